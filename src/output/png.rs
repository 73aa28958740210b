//! Images of the height grid and of the composite, with axes in mm.
//!
//! The plot shows the grid as seen by the knee (from -y): x to the right
//! with the vehicle front (-x) on the left, z up, one square of pixels per
//! node. Small grids are enlarged by a whole factor; grids too large for
//! [`MAX_PLOT_W`] x [`MAX_PLOT_H`] pixels are reduced by a whole factor,
//! each pixel taking the largest count and the smallest height of the nodes
//! it covers, so a single colliding node is never lost.
//!
//! Text uses DejaVu Sans, embedded by the `dejavu` crate and registered with
//! plotters once per process: no system font is needed.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::grid::HeightGrid;

/// Largest plot area width (pixels); the whole image stays under 1600.
const MAX_PLOT_W: usize = 1300;
/// Largest plot area height (pixels).
const MAX_PLOT_H: usize = 900;
/// Small grids are enlarged until the longer side reaches this (pixels).
const MIN_PLOT: usize = 480;

/// Space around the plot area (pixels): title above, axis labels left and
/// below, the colour bar on the right.
const MARGIN: usize = 10;
const TITLE_H: usize = 40;
const Y_LABELS: usize = 80;
const X_LABELS: usize = 50;
const BAR_AREA_W: usize = 170;
/// Images are at least this tall so the colour bar stays readable.
const MIN_IMAGE_H: usize = 320;

/// The font family every text style here uses.
const FONT: &str = "sans-serif";

/// Colour of nodes whose line misses the part (`h = +inf`).
const NO_PART: RGBColor = RGBColor(250, 250, 250);

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PngError {
    /// The embedded font could not be parsed (a broken build).
    #[error("the embedded DejaVu Sans font could not be loaded")]
    Font,
    /// The grid has no node.
    #[error("cannot draw an empty grid ({nx} x {nz} nodes)")]
    EmptyGrid {
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
    },
    /// The composite does not have one count per node.
    #[error("the composite has {got} entries but the grid has {expected} nodes")]
    Length {
        /// Nodes in the grid.
        expected: usize,
        /// Entries in the composite.
        got: usize,
    },
    /// Plotters or the PNG encoder failed (e.g. the directory is missing).
    #[error("cannot draw {path}: {reason}")]
    Draw {
        /// The image file.
        path: PathBuf,
        /// What plotters said.
        reason: String,
    },
}

/// Writes the height grid as a PNG: colour by height `h` (mm, analysis
/// frame y: small = near the knee, drawn bright), nodes that miss the part
/// in a pale neutral, a colour bar in mm, mm axes and a title with the grid
/// size and pitch.
pub fn write_depth_png(path: &Path, grid: &HeightGrid) -> Result<(), PngError> {
    let (h_lo, h_hi) = finite_range(&grid.h);
    let title = format!(
        "Height grid (y in the analysis frame): {} x {} nodes at {} mm pitch",
        grid.spec.nx, grid.spec.nz, grid.spec.pitch
    );
    let raster = Raster::plan(grid.spec.nx, grid.spec.nz)?;
    let heights = raster.reduce(grid.spec.nx, &grid.h, f64::INFINITY, f64::min);
    let colour = |h: f64| {
        if h.is_finite() {
            viridis((h_hi - h) / (h_hi - h_lo))
        } else {
            NO_PART
        }
    };
    let pixels: Vec<RGBColor> = heights.into_iter().map(colour).collect();
    draw_plot(path, grid, &raster, &pixels, &title, |area| {
        let mut bar = colour_bar(area, "y (mm)", h_lo..h_hi)?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_label_formatter(&tick)
            .label_style((FONT, 13))
            .draw()?;
        // A smooth bar: enough bands that neighbours differ by under one
        // colour step.
        const BANDS: usize = 256;
        let dh = (h_hi - h_lo) / BANDS as f64;
        bar.draw_series((0..BANDS).map(|k| {
            let lo = h_lo + k as f64 * dh;
            Rectangle::new([(0.0, lo), (1.0, lo + dh)], colour(lo + 0.5 * dh).filled())
        }))?;
        Ok(())
    })
}

/// Writes the composite as a PNG: nodes counted by at least one angle in a
/// colour per count (a viridis-like ramp, 1 dark to `n_angles` bright, with
/// a discrete legend) over the height grid in grey (pale neutral where the
/// part is missed), mm axes and `title`.
pub fn write_composite_png(
    path: &Path,
    grid: &HeightGrid,
    composite: &[u16],
    n_angles: usize,
    title: &str,
) -> Result<(), PngError> {
    if composite.len() != grid.spec.len() {
        return Err(PngError::Length {
            expected: grid.spec.len(),
            got: composite.len(),
        });
    }
    let max_count = composite.iter().copied().max().unwrap_or(0);
    let n = n_angles.max(usize::from(max_count)).max(1);
    let (h_lo, h_hi) = finite_range(&grid.h);
    let raster = Raster::plan(grid.spec.nx, grid.spec.nz)?;
    let counts = raster.reduce(grid.spec.nx, composite, 0u16, u16::max);
    let heights = raster.reduce(grid.spec.nx, &grid.h, f64::INFINITY, f64::min);
    let pixels: Vec<RGBColor> = counts
        .into_iter()
        .zip(heights)
        .map(|(c, h)| match (c, h.is_finite()) {
            (1.., _) => count_colour(usize::from(c), n),
            (0, true) => grey((h_hi - h) / (h_hi - h_lo)),
            (0, false) => NO_PART,
        })
        .collect();
    draw_plot(path, grid, &raster, &pixels, title, |area| {
        let top = n as f64 + 0.5;
        let mut bar = colour_bar(area, "angles", 0.5..top)?;
        let whole = |v: &f64| {
            if (v - v.round()).abs() < 1e-9 {
                format!("{}", v.round())
            } else {
                String::new()
            }
        };
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(n.min(12))
            .y_label_formatter(&whole)
            .label_style((FONT, 13))
            .draw()?;
        bar.draw_series((1..=n).map(|c| {
            let y = c as f64;
            Rectangle::new(
                [(0.0, y - 0.5), (1.0, y + 0.5)],
                count_colour(c, n).filled(),
            )
        }))?;
        Ok(())
    })
}

/// The smallest and largest finite value, widened to a non-empty range
/// (a flat grid still gets a colour bar); `(0, 1)` when none is finite.
fn finite_range(h: &[f64]) -> (f64, f64) {
    let (lo, hi) = h
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        (0.0, 1.0)
    } else if lo == hi {
        (lo - 0.5, hi + 0.5)
    } else {
        (lo, hi)
    }
}

/// How nodes map to plot pixels: each node is `up` x `up` pixels, or each
/// pixel covers `block` x `block` nodes (one of the two is 1). Pixel columns
/// count from x's low end, pixel rows from z's low end (drawn bottom up).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Raster {
    w: usize,
    h: usize,
    up: usize,
    block: usize,
}

impl Raster {
    fn plan(nx: usize, nz: usize) -> Result<Raster, PngError> {
        if nx == 0 || nz == 0 {
            return Err(PngError::EmptyGrid { nx, nz });
        }
        if nx <= MAX_PLOT_W && nz <= MAX_PLOT_H {
            let up = MIN_PLOT
                .div_ceil(nx.max(nz))
                .min(MAX_PLOT_W / nx)
                .min(MAX_PLOT_H / nz)
                .max(1);
            return Ok(Raster {
                w: nx * up,
                h: nz * up,
                up,
                block: 1,
            });
        }
        let block = nx.div_ceil(MAX_PLOT_W).max(nz.div_ceil(MAX_PLOT_H));
        Ok(Raster {
            w: nx.div_ceil(block),
            h: nz.div_ceil(block),
            up: 1,
            block,
        })
    }

    /// The nodes (of `n` along the axis) that pixel `k` covers.
    fn nodes(&self, k: usize, n: usize) -> Range<usize> {
        let lo = k * self.block / self.up;
        let hi = ((k + 1) * self.block / self.up).max(lo + 1);
        lo.min(n)..hi.min(n)
    }

    /// Nodes spanned by `pixels` pixels (mm = this times the pitch).
    fn span(&self, pixels: usize) -> f64 {
        (pixels * self.block) as f64 / self.up as f64
    }

    /// Folds the values of the nodes under each pixel, starting from
    /// `empty`; pixels row-major from the top (highest z) row.
    fn reduce<V: Copy, T: Copy>(
        &self,
        nx: usize,
        values: &[V],
        empty: T,
        fold: impl Fn(T, V) -> T,
    ) -> Vec<T> {
        let nz = values.len() / nx;
        let mut out = Vec::with_capacity(self.w * self.h);
        for r in 0..self.h {
            let rows = self.nodes(self.h - 1 - r, nz);
            for c in 0..self.w {
                let cols = self.nodes(c, nx);
                let mut acc = empty;
                for j in rows.clone() {
                    for &v in &values[j * nx + cols.start..j * nx + cols.end] {
                        acc = fold(acc, v);
                    }
                }
                out.push(acc);
            }
        }
        out
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type DrawError = DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>;
type DrawResult = Result<(), DrawError>;

/// Draws the title, the pixels (row-major from the top) in a plot with mm
/// axes, and, through `legend`, the colour bar on the right; then encodes.
fn draw_plot(
    path: &Path,
    grid: &HeightGrid,
    raster: &Raster,
    pixels: &[RGBColor],
    title: &str,
    legend: impl FnOnce(&Area) -> DrawResult,
) -> Result<(), PngError> {
    register_font()?;
    let failed = |e: &dyn std::fmt::Display| PngError::Draw {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let chart_w = MARGIN + Y_LABELS + raster.w + MARGIN;
    let height = (TITLE_H + raster.h + X_LABELS + MARGIN).max(MIN_IMAGE_H);
    let size = ((chart_w + BAR_AREA_W) as u32, height as u32);
    let root = BitMapBackend::new(path, size).into_drawing_area();
    let draw = || -> DrawResult {
        root.fill(&WHITE)?;
        root.draw_text(
            title,
            &(FONT, 20).into_text_style(&root),
            (MARGIN as i32, 10),
        )?;
        let (chart_area, bar_area) = root.split_horizontally(chart_w as u32);
        let p = grid.spec.pitch;
        let x0 = grid.spec.x(0) - 0.5 * p;
        let z0 = grid.spec.z(0) - 0.5 * p;
        let mut chart = ChartBuilder::on(&chart_area)
            .margin_top(TITLE_H as u32)
            .margin_left(MARGIN as u32)
            .margin_right(MARGIN as u32)
            .margin_bottom((height - TITLE_H - raster.h - X_LABELS) as u32)
            .x_label_area_size(X_LABELS as u32)
            .y_label_area_size(Y_LABELS as u32)
            .build_cartesian_2d(
                x0..x0 + raster.span(raster.w) * p,
                z0..z0 + raster.span(raster.h) * p,
            )?;
        let (px, py) = chart.plotting_area().get_pixel_range();
        debug_assert_eq!(
            ((px.end - px.start) as usize, (py.end - py.start) as usize),
            (raster.w, raster.h)
        );
        for (k, colour) in pixels.iter().enumerate() {
            let (c, r) = ((k % raster.w) as i32, (k / raster.w) as i32);
            root.draw_pixel((px.start + c, py.start + r), colour)?;
        }
        chart
            .configure_mesh()
            .disable_mesh()
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .x_desc("x (mm), vehicle front \u{2190}")
            .y_desc("z (mm), up")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()?;
        legend(&bar_area)?;
        root.present()
    };
    draw().map_err(|e| failed(&e))
}

/// The colour bar's frame in `area` (the image's right strip): a bar with
/// value labels on its right, `label` above it, spanning the plot's height.
fn colour_bar<'a, 'b>(
    area: &'a Area<'b>,
    label: &str,
    values: Range<f64>,
) -> Result<
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    DrawError,
> {
    area.draw_text(
        label,
        &(FONT, 14).into_text_style(area),
        (20, TITLE_H as i32 - 20),
    )?;
    ChartBuilder::on(area)
        .margin_top(TITLE_H as u32)
        .margin_bottom((MARGIN + X_LABELS) as u32)
        .margin_left(20)
        .margin_right(MARGIN as u32)
        .set_label_area_size(LabelAreaPosition::Right, 70)
        .build_cartesian_2d(0.0..1.0, values)
}

/// An axis tick in mm: rounded to 1e-6 to hide the float noise of tick
/// arithmetic, with no trailing zeros (`300`, `12.5`).
fn tick(v: &f64) -> String {
    let r = (v * 1e6).round() / 1e6;
    format!("{}", if r == 0.0 { 0.0 } else { r })
}

/// Registers DejaVu Sans as plotters' `sans-serif` once per process.
pub(crate) fn register_font() -> Result<(), PngError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok()
    });
    if ok { Ok(()) } else { Err(PngError::Font) }
}

/// Matplotlib's viridis sampled at t = 0, 1/8, ..., 1: perceptually
/// uniform, readable in grey and by most colour-blind readers.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 45, 123),
    (59, 82, 139),
    (44, 114, 142),
    (33, 145, 140),
    (40, 174, 128),
    (94, 201, 98),
    (173, 220, 48),
    (253, 231, 37),
];

/// The viridis colour at `t` in [0, 1] (clamped), linear between samples.
fn viridis(t: f64) -> RGBColor {
    let s = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let k = (s.floor() as usize).min(VIRIDIS.len() - 2);
    let f = s - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    let mix = |u: u8, v: u8| (f64::from(u) + f * (f64::from(v) - f64::from(u))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The colour of count `c` of `n`: 1 darkest, `n` brightest.
pub(crate) fn count_colour(c: usize, n: usize) -> RGBColor {
    if n <= 1 {
        viridis(1.0)
    } else {
        viridis((c.min(n) - 1) as f64 / (n - 1) as f64)
    }
}

/// The part behind the composite: grey, lighter nearer the knee (`t` = 1),
/// kept mid-range so every count colour stands out.
fn grey(t: f64) -> RGBColor {
    let g = (110.0 + 100.0 * t.clamp(0.0, 1.0)).round() as u8;
    RGBColor(g, g, g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::output::temp_dir;

    fn grid(nx: usize, nz: usize, h: impl Fn(usize, usize) -> f64) -> HeightGrid {
        let spec = GridSpec {
            pitch: 1.24,
            i_origin: -40,
            j_origin: 3,
            nx,
            nz,
        };
        let h = (0..nx * nz).map(|k| h(k % nx, k / nx)).collect();
        HeightGrid { spec, h }
    }

    /// Checks the PNG signature and reads the size from the IHDR chunk.
    fn png_size(path: &Path) -> (u32, u32) {
        let bytes = std::fs::read(path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&bytes[12..16], b"IHDR");
        // A plot with axes and text compresses to well over a few kB.
        assert!(bytes.len() > 4000, "{} bytes", bytes.len());
        let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
        (be(16), be(20))
    }

    #[test]
    fn depth_and_composite_images_are_valid_pngs_of_the_planned_size() {
        let dir = temp_dir("png");
        let g = grid(120, 60, |i, j| {
            if i < 5 {
                f64::INFINITY
            } else {
                (i as f64 * 0.1).sin() * 5.0 + j as f64 * 0.01
            }
        });
        let mut composite = vec![0u16; g.spec.len()];
        composite[30 * 120 + 60] = 3;
        composite[10 * 120 + 20] = 61;
        write_depth_png(&dir.join("depth.png"), &g).unwrap();
        write_composite_png(
            &dir.join("composite.png"),
            &g,
            &composite,
            61,
            "Composite, 61 angles",
        )
        .unwrap();
        // 120 x 60 nodes, enlarged 4 times to reach MIN_PLOT.
        let plot = Raster::plan(120, 60).unwrap();
        assert_eq!((plot.w, plot.h, plot.up), (480, 240, 4));
        let want = (
            (MARGIN + Y_LABELS + 480 + MARGIN + BAR_AREA_W) as u32,
            MIN_IMAGE_H.max(TITLE_H + 240 + X_LABELS + MARGIN) as u32,
        );
        assert_eq!(png_size(&dir.join("depth.png")), want);
        assert_eq!(png_size(&dir.join("composite.png")), want);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn paper_sized_grid_fits_the_width_bound() {
        let dir = temp_dir("png-big");
        let g = grid(1538, 801, |i, j| (i + j) as f64 * 0.01);
        let r = Raster::plan(1538, 801).unwrap();
        assert_eq!((r.w, r.h, r.block), (769, 401, 2));
        write_composite_png(&dir.join("c.png"), &g, &vec![1; g.spec.len()], 1, "all").unwrap();
        assert!(png_size(&dir.join("c.png")).0 <= 1600);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn downsampling_keeps_an_isolated_colliding_node_and_the_lowest_height() {
        let (nx, nz) = (3001, 1900);
        let r = Raster::plan(nx, nz).unwrap();
        assert_eq!(r.block, 3);
        let mut composite = vec![0u16; nx * nz];
        let mut h = vec![1.0; nx * nz];
        // The last node of the grid: a pixel whose block is cut short.
        composite[nx * nz - 1] = 2;
        h[1234 * nx + 2999] = -7.0;
        let counts = r.reduce(nx, &composite, 0, u16::max);
        let lit: Vec<usize> = (0..counts.len()).filter(|&k| counts[k] > 0).collect();
        // Top row (highest z), last column.
        assert_eq!(lit, [r.w - 1]);
        assert_eq!(counts[r.w - 1], 2);
        let heights = r.reduce(nx, &h, f64::INFINITY, f64::min);
        let low: Vec<usize> = (0..heights.len()).filter(|&k| heights[k] < 0.0).collect();
        // Node row 1234 is pixel row 411 from the bottom.
        assert_eq!(low, [(r.h - 1 - 1234 / 3) * r.w + 2999 / 3]);
    }

    #[test]
    fn every_node_is_covered_exactly_once() {
        for (nx, nz) in [(7, 3), (1301, 5), (2000, 2000), (1538, 801)] {
            let r = Raster::plan(nx, nz).unwrap();
            let ones = vec![1u32; nx * nz];
            let covered = r.reduce(nx, &ones, 0, |a, b| a + b);
            assert_eq!(
                covered.iter().sum::<u32>() as usize,
                nx * nz * r.up * r.up,
                "{nx} x {nz}"
            );
            assert!(r.w <= MAX_PLOT_W && r.h <= MAX_PLOT_H);
        }
        assert!(matches!(
            Raster::plan(0, 4),
            Err(PngError::EmptyGrid { .. })
        ));
    }

    #[test]
    fn count_colours_run_dark_to_bright() {
        let luma =
            |c: RGBColor| 0.3 * f64::from(c.0) + 0.59 * f64::from(c.1) + 0.11 * f64::from(c.2);
        let l: Vec<f64> = (1..=61).map(|c| luma(count_colour(c, 61))).collect();
        assert!(l.windows(2).all(|w| w[0] <= w[1]), "{l:?}");
        assert_eq!(count_colour(1, 61), RGBColor(68, 1, 84));
        assert_eq!(count_colour(61, 61), RGBColor(253, 231, 37));
        assert_eq!(finite_range(&[f64::INFINITY, 2.0, 2.0]), (1.5, 2.5));
        assert_eq!(tick(&300.0), "300");
        assert_eq!(tick(&(0.1 + 0.2)), "0.3");
        assert_eq!(tick(&-1e-12), "0");
    }
}
