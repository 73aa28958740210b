//! Images of the height grid and of the composite, with axes in mm.
//!
//! The plot shows the part as the knee sees it, named in the title: the
//! left side from -y (x to the right, the vehicle front, -x, on the left),
//! the right side from +y (x reversed, the front on the right); z up, one
//! square of pixels per node. It is cropped to the nodes that hit the part
//! (and any struck node) with a margin of [`CROP_MARGIN`], not the whole
//! grid with its knee-form margin. Small windows are enlarged by a whole
//! factor; windows too large for [`MAX_PLOT_W`] x [`MAX_PLOT_H`] pixels are
//! reduced by a whole factor, each pixel taking the largest count and the
//! smallest height of the nodes it covers, so a single colliding node is
//! never lost; when few pixels are struck, each is also circled
//! ([`RING_BELOW`]), so that a one-node result stays visible. Every colour
//! is in a key: the colour bar, and a line of swatches under the plot.
//!
//! The layout is measured from the text: the image is as wide as its
//! title, view line and widest key entry need, the key goes on to further
//! lines where one would pass the image's edge, and the plot area is at
//! least [`MIN_AXES`] pixels (and as long as its axis names) each way, the
//! part's pixels centred in it, so that a tiny, narrow or flat part keeps
//! its axis labels and a readable colour bar. The colour bar spans the
//! plot's rows, with the words of its ends outside it.
//!
//! Text uses DejaVu Sans, embedded by the `dejavu` crate and registered with
//! plotters once per process: no system font is needed.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::frame::Approach;
use crate::frame::Placement;
use crate::frame::Side;
use crate::grid::{GridSpec, HeightGrid};

/// Largest plot area width (pixels); the whole image stays under 1600
/// unless a title is wider.
const MAX_PLOT_W: usize = 1300;
/// Largest plot area height (pixels).
const MAX_PLOT_H: usize = 900;
/// Small grids are enlarged until the longer side reaches this (pixels).
const MIN_PLOT: usize = 480;

/// Space around the plot area (pixels): title above, axis labels left and
/// below, the colour bar on the right; and the empty border of the image.
const MARGIN: usize = 10;
/// Two lines (what is shown, and from where it is seen), then the colour
/// bar's label and, on the depth image, the word at its top end.
const TITLE_H: usize = 100;
/// One line of colour swatches under the x axis; a key wider than the
/// image takes more lines.
const KEY_H: usize = 26;
/// A key entry: the swatch and the gap before its words (pixels).
const SWATCH_W: usize = 20;
/// The gap between key entries on a line (pixels).
const KEY_GAP: usize = 24;
const Y_LABELS: usize = 80;
const X_LABELS: usize = 50;
/// The colour bar's strip, at least: the bar [`BAR_LEFT`] in, [`BAR_W`]
/// wide, its value labels in [`BAR_LABELS`] right of it and a margin.
const BAR_AREA_W: usize = 170;
const BAR_LEFT: usize = 20;
const BAR_W: usize = 70;
const BAR_LABELS: usize = 70;
/// The plot area is at least this wide and tall (pixels), the part's
/// pixels centred in it: room for a few axis labels and a readable colour
/// bar (it spans the plot's height) however narrow or flat the part.
const MIN_AXES: usize = 160;

/// Text sizes (points): title, view line, axis names, axis labels and key.
const TITLE_PT: u32 = 20;
const VIEW_PT: u32 = 15;
const DESC_PT: u32 = 14;
const LABEL_PT: u32 = 13;

/// The font family every text style here uses.
const FONT: &str = "sans-serif";

/// Colour of nodes whose line misses the part (`h = +inf`).
pub const NO_PART: RGBColor = RGBColor(250, 250, 250);

/// Nodes of margin kept around the part's nodes when cropping, at least;
/// or a twentieth of the window's size, whichever is more.
pub const CROP_MARGIN: usize = 3;

/// When fewer nodes than this are struck, each is circled in
/// [`RING_COLOUR`]: a single node of a 1300-node-wide grid is one pixel.
pub const RING_BELOW: usize = 32;

/// The circles around few struck pixels: a red that neither the count
/// ramp (viridis) nor the grey of the part takes.
pub const RING_COLOUR: RGBColor = RGBColor(228, 26, 28);

/// Radius of those circles (pixels).
const RING_RADIUS: i32 = 9;

/// The colour of the blind-spot marks (a cross on each cell the grid
/// cannot see into): magenta, apart from the counts' ramp, the greys and
/// the rings' red.
pub const BLIND_COLOUR: RGBColor = RGBColor(214, 0, 214);

/// Half the size of a blind-spot cross (pixels).
const BLIND_HALF: i32 = 4;

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

/// Writes the height grid as a PNG: colour by closeness to the knee
/// (bright = small `h`, the first to meet the knee; the bar's ends say
/// which is closer), in the part's own y (mm), nodes that miss the part in
/// a pale neutral (in the key), mm axes, the side and viewing direction in
/// the title, cropped to the part (see the module docs). Returns where it
/// put things.
pub fn write_depth_png(
    path: &Path,
    grid: &HeightGrid,
    placement: &Placement,
) -> Result<Layout, PngError> {
    let side = placement.side;
    let frame = placement.frame.record().map(|r| r.given);
    let direct = placement.approach == Approach::Direct;
    let (h_lo, h_hi) = finite_range(&grid.h);
    let window = crop_window(grid, None);
    let shown = window.crop(grid);
    let title = format!(
        "Height grid (depth buffer seen from the knee): {} x {} nodes at {} mm pitch",
        grid.spec.nx,
        grid.spec.nz,
        tick(&grid.spec.pitch)
    );
    let raster = Raster::plan(shown.spec.nx, shown.spec.nz)?;
    let heights = raster.reduce(shown.spec.nx, &shown.h, f64::INFINITY, f64::min);
    let colour = |h: f64| {
        if h.is_finite() {
            viridis((h_hi - h) / (h_hi - h_lo))
        } else {
            NO_PART
        }
    };
    let pixels: Vec<RGBColor> = heights.into_iter().map(colour).collect();
    // The bar is in the part's y: on the right side, -h; for the direct
    // approach in its x, -h.
    let flipped = direct || side == Side::Right;
    let (y_lo, y_hi) = if flipped {
        (-h_hi, -h_lo)
    } else {
        (h_lo, h_hi)
    };
    // With a frame the picture is in vehicle coordinates, and so is y.
    let bar_label = match (direct, frame.is_some()) {
        (false, true) => "y (mm, vehicle frame)",
        (false, false) => "y (mm, part frame)",
        (true, true) => "x (mm, vehicle frame)",
        (true, false) => "x (mm, part frame)",
    };
    let plot = Plot {
        grid: &shown,
        raster: &raster,
        pixels: &pixels,
        title: &title,
        side,
        frame: frame.as_deref(),
        approach: placement.approach,
        key: &[(NO_PART, "no part (the node's line misses it)")],
        rings: &[],
        marks: &[],
        bar_label,
        bar_ends: Some(depth_bar_ends(if flipped {
            Side::Right
        } else {
            Side::Left
        })),
    };
    draw_plot(path, &plot, |area, rows| {
        let mut bar = colour_bar(area, rows.clone(), y_lo..y_hi)?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(((rows.end - rows.start) / 24).clamp(2, 10) as usize)
            .y_label_formatter(&tick)
            .label_style((FONT, LABEL_PT))
            .draw()?;
        // A smooth bar: enough bands that neighbours differ by under one
        // colour step.
        const BANDS: usize = 256;
        let dy = (y_hi - y_lo) / BANDS as f64;
        bar.draw_series((0..BANDS).map(|k| {
            let lo = y_lo + k as f64 * dy;
            let h = if flipped {
                -(lo + 0.5 * dy)
            } else {
                lo + 0.5 * dy
            };
            Rectangle::new([(0.0, lo), (1.0, lo + dy)], colour(h).filled())
        }))?;
        Ok(())
    })
}

/// The words at the top and bottom ends of the depth bar: the bright end
/// (small `h`) is the one closer to the knee, at the bottom of the bar for
/// the left side (part y = h) and at its top for the right (part y = -h).
pub fn depth_bar_ends(side: Side) -> [&'static str; 2] {
    const CLOSER: &str = "closer to the knee";
    const FARTHER: &str = "farther from the knee";
    match side {
        Side::Left => [FARTHER, CLOSER],
        Side::Right => [CLOSER, FARTHER],
    }
}

/// The key of the composite image, beside its colour bar of counts: the
/// grey of the part not struck, the pale of no part, and the circles when
/// there are any.
pub fn composite_key(ringed: bool, blind: bool) -> Vec<(RGBColor, &'static str)> {
    let mut key = vec![
        (grey(0.5), "part, not struck (lighter = closer to the knee)"),
        (NO_PART, "no part"),
    ];
    if ringed {
        key.push((RING_COLOUR, "circled: struck (few nodes)"));
    }
    if blind {
        key.push((BLIND_COLOUR, "crossed: blind spot (unseen between nodes)"));
    }
    key
}

/// Writes the composite as a PNG: nodes counted by at least one angle in a
/// colour per count (a viridis-like ramp, 1 dark to `n_angles` bright, with
/// a discrete legend) over the height grid in grey (pale neutral where the
/// part is missed), both in the key, mm axes, `title` with the side and
/// viewing direction under it, cropped to the part and what was struck;
/// few struck pixels are circled, and the cells `blind` (each by its first
/// corner node `(i, j)`: [`crate::blind`]) crossed. Returns where it put
/// things.
pub fn write_composite_png(
    path: &Path,
    grid: &HeightGrid,
    composite: &[u16],
    n_angles: usize,
    title: &str,
    placement: &Placement,
    blind: &[(usize, usize)],
) -> Result<Layout, PngError> {
    let side = placement.side;
    let frame = placement.frame.record().map(|r| r.given);
    let approach = placement.approach;
    if composite.len() != grid.spec.len() {
        return Err(PngError::Length {
            expected: grid.spec.len(),
            got: composite.len(),
        });
    }
    let max_count = composite.iter().copied().max().unwrap_or(0);
    let n = n_angles.max(usize::from(max_count)).max(1);
    let (h_lo, h_hi) = finite_range(&grid.h);
    let window = crop_window(grid, Some(composite));
    let shown = window.crop(grid);
    let shown_counts = window.crop_values(grid.spec.nx, composite);
    let raster = Raster::plan(shown.spec.nx, shown.spec.nz)?;
    let counts = raster.reduce(shown.spec.nx, &shown_counts, 0u16, u16::max);
    let heights = raster.reduce(shown.spec.nx, &shown.h, f64::INFINITY, f64::min);
    let struck: Vec<usize> = (0..shown_counts.len())
        .filter(|&k| shown_counts[k] > 0)
        .collect();
    let mut rings: Vec<usize> = if struck.len() < RING_BELOW {
        struck
            .iter()
            .map(|&k| raster.pixel_of(k % shown.spec.nx, k / shown.spec.nx))
            .collect()
    } else {
        Vec::new()
    };
    rings.dedup();
    let mut marks: Vec<usize> = blind
        .iter()
        .filter(|&&(i, j)| window.i.contains(&i) && window.j.contains(&j))
        .map(|&(i, j)| raster.pixel_of(i - window.i.start, j - window.j.start))
        .collect();
    marks.sort_unstable();
    marks.dedup();
    let pixels: Vec<RGBColor> = counts
        .into_iter()
        .zip(heights)
        .map(|(c, h)| match (c, h.is_finite()) {
            (1.., _) => count_colour(usize::from(c), n),
            (0, true) => grey((h_hi - h) / (h_hi - h_lo)),
            (0, false) => NO_PART,
        })
        .collect();
    let key = composite_key(!rings.is_empty(), !marks.is_empty());
    let plot = Plot {
        grid: &shown,
        raster: &raster,
        pixels: &pixels,
        title,
        side,
        frame: frame.as_deref(),
        approach,
        key: &key,
        rings: &rings,
        marks: &marks,
        bar_label: "struck at N angles",
        bar_ends: None,
    };
    draw_plot(path, &plot, |area, rows| {
        let top = n as f64 + 0.5;
        let mut bar = colour_bar(area, rows.clone(), 0.5..top)?;
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
            .y_labels(n.min(12).min((rows.end - rows.start) as usize / 20).max(1))
            .y_label_formatter(&whole)
            .label_style((FONT, LABEL_PT))
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

/// The nodes an image shows: columns `i` and rows `j` of the grid.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Window {
    /// Node columns.
    pub i: Range<usize>,
    /// Node rows.
    pub j: Range<usize>,
}

impl Window {
    /// The grid inside the window.
    fn crop(&self, grid: &HeightGrid) -> HeightGrid {
        let spec = GridSpec {
            pitch: grid.spec.pitch,
            i_origin: grid.spec.i_origin + self.i.start as i64,
            j_origin: grid.spec.j_origin + self.j.start as i64,
            nx: self.i.len(),
            nz: self.j.len(),
        };
        HeightGrid {
            spec,
            h: self.crop_values(grid.spec.nx, &grid.h),
        }
    }

    /// The values of a row-major grid `nx` wide inside the window.
    fn crop_values<T: Copy>(&self, nx: usize, values: &[T]) -> Vec<T> {
        self.j
            .clone()
            .flat_map(|j| {
                values[j * nx + self.i.start..j * nx + self.i.end]
                    .iter()
                    .copied()
            })
            .collect()
    }
}

/// The part plus what was struck: the smallest window holding every node
/// whose line meets the part and every node with a count in `composite`,
/// grown by [`CROP_MARGIN`] nodes (or a twentieth of its size) on every
/// side within the grid. The whole grid when no node meets the part.
pub fn crop_window(grid: &HeightGrid, composite: Option<&[u16]>) -> Window {
    let (nx, nz) = (grid.spec.nx, grid.spec.nz);
    let (mut i0, mut i1, mut j0, mut j1) = (usize::MAX, 0, usize::MAX, 0);
    for j in 0..nz {
        for i in 0..nx {
            let k = j * nx + i;
            let shown = grid.h[k].is_finite()
                || composite.is_some_and(|c| c.get(k).is_some_and(|&v| v > 0));
            if shown {
                i0 = i0.min(i);
                i1 = i1.max(i);
                j0 = j0.min(j);
                j1 = j1.max(j);
            }
        }
    }
    if i0 > i1 {
        return Window { i: 0..nx, j: 0..nz };
    }
    let grow = |lo: usize, hi: usize, n: usize| {
        let m = CROP_MARGIN.max((hi - lo + 1) / 20);
        lo.saturating_sub(m)..(hi + 1 + m).min(n)
    };
    Window {
        i: grow(i0, i1, nx),
        j: grow(j0, j1, nz),
    }
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

    /// The pixel (row-major from the top row) at the centre of node
    /// `(i, j)`.
    fn pixel_of(&self, i: usize, j: usize) -> usize {
        let along = |k: usize| k * self.up + self.up / 2;
        let (c, r) = if self.block > 1 {
            (i / self.block, j / self.block)
        } else {
            (along(i), along(j))
        };
        (self.h - 1 - r) * self.w + c
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

/// What [`draw_plot`] draws.
struct Plot<'a> {
    /// The nodes shown (already cropped).
    grid: &'a HeightGrid,
    raster: &'a Raster,
    /// Row-major from the top, x increasing to the right.
    pixels: &'a [RGBColor],
    title: &'a str,
    /// Which way the knee looks: the right side is drawn with x reversed.
    side: Side,
    /// The `--frame` given, if any: the axes are then the vehicle's, not
    /// the part file's, and the view line says so.
    frame: Option<&'a str>,
    /// For the direct approach the grid's columns are the part's y (the
    /// direct frame, [`crate::direct`]), seen from +x.
    approach: Approach,
    /// Swatches under the plot: colour and meaning.
    key: &'a [(RGBColor, &'a str)],
    /// Pixels (indices into `pixels`) to circle.
    rings: &'a [usize],
    /// Pixels to cross (blind spots).
    marks: &'a [usize],
    /// The words above the colour bar.
    bar_label: &'a str,
    /// The words at the bar's top and bottom ends, if any.
    bar_ends: Option<[&'a str; 2]>,
}

impl Plot<'_> {
    /// The second line of the title: where the part is seen from, and in
    /// which axes.
    fn view_text(&self) -> String {
        let line = match self.approach {
            Approach::Slide => view_line(self.side),
            Approach::Direct => "Direct approach, seen from the knee (looking -x): y across, z up",
        };
        match self.frame {
            None => line.to_string(),
            Some(given) => format!("{line}; vehicle axes (part placed by --frame {given})"),
        }
    }

    /// The names of the x and z axes.
    fn axis_names(&self) -> (String, String) {
        let direct = self.approach == Approach::Direct;
        let x_desc = match (direct, self.side == Side::Right) {
            (true, _) => "y (mm)",
            (false, true) => "x (mm), vehicle front \u{2192}",
            (false, false) => "x (mm), vehicle front \u{2190}",
        };
        // With a frame the axes are the vehicle's, not the part file's.
        match self.frame {
            None => (x_desc.to_string(), "z (mm), up".to_string()),
            Some(_) => (
                format!("vehicle {x_desc}"),
                "vehicle z (mm), up".to_string(),
            ),
        }
    }
}

/// The second line of every title: the side and where it is seen from.
pub fn view_line(side: Side) -> &'static str {
    match side {
        Side::Left => {
            "Left side, seen from the knee (looking +y): vehicle front (-x) on the left, z up"
        }
        Side::Right => {
            "Right side, seen from the knee (looking -y): vehicle front (-x) on the right, z up"
        }
    }
}

/// The width and height (pixels) of `text` in the plots' font at `pt`.
fn text_size(text: &str, pt: u32) -> Result<(usize, usize), PngError> {
    let (w, h) = (FONT, pt)
        .into_font()
        .box_size(text)
        .map_err(|_| PngError::Font)?;
    Ok((w as usize, h as usize))
}

/// Where [`draw_plot`] puts things (pixels from the image's top left):
/// sized from the part's raster and from every text, measured, so that
/// nothing is cut at the image's edge however small, narrow or flat the
/// part and however long the words.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Image width.
    width: usize,
    /// Image height.
    height: usize,
    /// The left strip: the plot, its axis labels and margins; the colour
    /// bar's strip follows it.
    chart_w: usize,
    /// The colour bar's strip.
    bar_w: usize,
    /// The plot area: left column, top row, width, height; at least the
    /// raster's size and [`MIN_AXES`].
    plot: [usize; 4],
    /// The raster's offset in the plot area (columns, rows): it is centred.
    pad: [usize; 2],
    /// Per key entry: the left column and top row of its swatch, and the
    /// width of swatch and words.
    key: Vec<[usize; 3]>,
}

impl Layout {
    fn plan(plot: &Plot, view: &str, x_desc: &str, z_desc: &str) -> Result<Layout, PngError> {
        let raster = plot.raster;
        // Each axis's name is centred on its side of the plot: the plot
        // is at least as long.
        let pw = raster
            .w
            .max(MIN_AXES)
            .max(text_size(x_desc, DESC_PT)?.0 + 2 * MARGIN);
        let ph = raster
            .h
            .max(MIN_AXES)
            .max(text_size(z_desc, DESC_PT)?.0 + 2 * MARGIN);
        let chart_w = MARGIN + Y_LABELS + pw + MARGIN;
        let mut bar_w = BAR_AREA_W.max(BAR_LEFT + text_size(plot.bar_label, DESC_PT)?.0 + MARGIN);
        for end in plot.bar_ends.iter().flatten() {
            bar_w = bar_w.max(BAR_LEFT + text_size(end, LABEL_PT)?.0 + MARGIN);
        }
        let key_x = MARGIN + Y_LABELS;
        let entries = plot
            .key
            .iter()
            .map(|(_, words)| Ok(SWATCH_W + text_size(words, LABEL_PT)?.0))
            .collect::<Result<Vec<usize>, PngError>>()?;
        let width = (chart_w + bar_w)
            .max(MARGIN + text_size(plot.title, TITLE_PT)?.0 + MARGIN)
            .max(MARGIN + text_size(view, VIEW_PT)?.0 + MARGIN)
            .max(key_x + entries.iter().copied().max().unwrap_or(0) + MARGIN);
        // The key's entries left to right, a new line where one would
        // pass the image's right margin.
        let key_top = TITLE_H + ph + X_LABELS + 6;
        let (mut x, mut line) = (key_x, 0);
        let mut key = Vec::with_capacity(entries.len());
        for w in entries {
            if x > key_x && x + w + MARGIN > width {
                (x, line) = (key_x, line + 1);
            }
            key.push([x, key_top + line * KEY_H, w]);
            x += w + KEY_GAP;
        }
        let lines = if key.is_empty() { 0 } else { line + 1 };
        Ok(Layout {
            width,
            height: TITLE_H + ph + X_LABELS + lines * KEY_H + MARGIN,
            chart_w,
            bar_w,
            plot: [MARGIN + Y_LABELS, TITLE_H, pw, ph],
            pad: [(pw - raster.w) / 2, (ph - raster.h) / 2],
            key,
        })
    }
}

/// Draws the title and view line, the pixels in a plot with mm axes (x
/// reversed for the right side), the rings, the key, the colour bar's
/// words and, through `legend` (given the bar's strip and its pixel rows,
/// the plot's), the colour bar; then encodes.
fn draw_plot(
    path: &Path,
    plot: &Plot,
    legend: impl FnOnce(&Area, Range<i32>) -> DrawResult,
) -> Result<Layout, PngError> {
    register_font()?;
    let failed = |e: &dyn std::fmt::Display| PngError::Draw {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let raster = plot.raster;
    let view = plot.view_text();
    let (x_desc, z_desc) = plot.axis_names();
    let layout = Layout::plan(plot, &view, &x_desc, &z_desc)?;
    let [left, top, pw, ph] = layout.plot;
    let [pad_l, pad_t] = layout.pad;
    let size = (layout.width as u32, layout.height as u32);
    let root = BitMapBackend::new(path, size).into_drawing_area();
    let reversed = plot.side == Side::Right;
    let draw = || -> DrawResult {
        root.fill(&WHITE)?;
        root.draw_text(
            plot.title,
            &(FONT, TITLE_PT).into_text_style(&root),
            (MARGIN as i32, 10),
        )?;
        root.draw_text(
            &view,
            &(FONT, VIEW_PT).into_text_style(&root),
            (MARGIN as i32, 36),
        )?;
        let chart_area = root.clone().shrink((0, 0), (layout.chart_w as u32, size.1));
        let bar_area = root
            .clone()
            .shrink((layout.chart_w as u32, 0), (layout.bar_w as u32, size.1));
        let spec = plot.grid.spec;
        let p = spec.pitch;
        // The axes in mm: the raster's span, and the plot area's columns
        // and rows around it.
        let mm = |pixels: usize| raster.span(pixels) * p;
        let x0 = spec.x(0) - 0.5 * p;
        let x1 = x0 + mm(raster.w);
        let z0 = spec.z(0) - 0.5 * p;
        let z1 = z0 + mm(raster.h);
        let (pad_r, pad_b) = (pw - raster.w - pad_l, ph - raster.h - pad_t);
        // The right side's axis runs over -x, labelled with x.
        let (a, b) = if reversed { (-x1, -x0) } else { (x0, x1) };
        let x_axis = a - mm(pad_l)..b + mm(pad_r);
        let z_axis = z0 - mm(pad_b)..z1 + mm(pad_t);
        let mut chart = ChartBuilder::on(&chart_area)
            .margin_top(top as u32)
            .margin_left((left - Y_LABELS) as u32)
            .margin_right((layout.chart_w - left - pw) as u32)
            .margin_bottom((layout.height - top - ph - X_LABELS) as u32)
            .x_label_area_size(X_LABELS as u32)
            .y_label_area_size(Y_LABELS as u32)
            .build_cartesian_2d(x_axis, z_axis)?;
        let (px, py) = chart.plotting_area().get_pixel_range();
        debug_assert_eq!(
            [px.start, py.start, px.end - px.start, py.end - py.start].map(|v| v as usize),
            layout.plot
        );
        let at = |k: usize| -> (i32, i32) {
            let (c, r) = (k % raster.w, k / raster.w);
            let c = if reversed { raster.w - 1 - c } else { c };
            ((left + pad_l + c) as i32, (top + pad_t + r) as i32)
        };
        for (k, colour) in plot.pixels.iter().enumerate() {
            root.draw_pixel(at(k), colour)?;
        }
        for &k in plot.rings {
            root.draw(&Circle::new(
                at(k),
                RING_RADIUS,
                RING_COLOUR.stroke_width(2),
            ))?;
        }
        for &k in plot.marks {
            let (x, y) = at(k);
            let h = BLIND_HALF;
            let stroke = BLIND_COLOUR.stroke_width(2);
            root.draw(&PathElement::new(
                vec![(x - h, y - h), (x + h, y + h)],
                stroke,
            ))?;
            root.draw(&PathElement::new(
                vec![(x - h, y + h), (x + h, y - h)],
                stroke,
            ))?;
        }
        // The direct approach's columns are the analysed y (mirrored for
        // the right side): the reversed axis is the part's y itself.
        let direct = plot.approach == Approach::Direct;
        let x_label = |v: &f64| tick(&if reversed && !direct { -v } else { *v });
        chart
            .configure_mesh()
            .disable_mesh()
            // At most one label per 60 pixels across, 30 up: they never
            // overlap, however narrow the plot.
            .x_labels((pw / 60).clamp(3, 10))
            .y_labels((ph / 30).clamp(3, 10))
            .x_label_formatter(&x_label)
            .y_label_formatter(&tick)
            .x_desc(x_desc)
            .y_desc(z_desc)
            .label_style((FONT, LABEL_PT))
            .axis_desc_style((FONT, DESC_PT))
            .draw()?;
        // The key: a swatch (framed, so the pale one shows) and its words.
        let style = (FONT, LABEL_PT).into_text_style(&root);
        for ((colour, words), &[x, y, _]) in plot.key.iter().zip(&layout.key) {
            let (x, y) = (x as i32, y as i32);
            root.draw(&Rectangle::new([(x, y), (x + 14, y + 14)], colour.filled()))?;
            root.draw(&Rectangle::new([(x, y), (x + 14, y + 14)], BLACK))?;
            root.draw_text(words, &style, (x + SWATCH_W as i32, y))?;
        }
        let left = BAR_LEFT as i32;
        bar_area.draw_text(
            plot.bar_label,
            &(FONT, DESC_PT).into_text_style(&bar_area),
            (left, TITLE_H as i32 - 40),
        )?;
        if let Some([high, low]) = plot.bar_ends {
            let style = (FONT, LABEL_PT).into_text_style(&bar_area);
            bar_area.draw_text(high, &style, (left, top as i32 - 22))?;
            bar_area.draw_text(low, &style, (left, (top + ph) as i32 + 8))?;
        }
        legend(&bar_area, top as i32..(top + ph) as i32)?;
        root.present()
    };
    draw().map_err(|e| failed(&e))?;
    Ok(layout)
}

/// The colour bar's frame in `area` (the image's strip right of the plot):
/// a bar [`BAR_W`] wide with value labels on its right, spanning the pixel
/// `rows` (the plot's).
fn colour_bar<'a, 'b>(
    area: &'a Area<'b>,
    rows: Range<i32>,
    values: Range<f64>,
) -> Result<
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    DrawError,
> {
    let (w, h) = area.dim_in_pixel();
    ChartBuilder::on(area)
        .margin_top(rows.start as u32)
        .margin_bottom(h - rows.end as u32)
        .margin_left(BAR_LEFT as u32)
        .margin_right(w - (BAR_LEFT + BAR_W + BAR_LABELS) as u32)
        .set_label_area_size(LabelAreaPosition::Right, BAR_LABELS as u32)
        .build_cartesian_2d(0.0..1.0, values)
}

/// An axis tick in mm: rounded to 1e-6 to hide the float noise of tick
/// arithmetic, with no trailing zeros (`300`, `12.5`).
pub(crate) fn tick(v: &f64) -> String {
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
    use crate::output::{decode_png, temp_dir};

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
        let depth = write_depth_png(&dir.join("depth.png"), &g, &Side::Left.into()).unwrap();
        let comp = write_composite_png(
            &dir.join("composite.png"),
            &g,
            &composite,
            61,
            "Composite, 61 angles",
            &Side::Left.into(),
            &[(40, 20)],
        )
        .unwrap();
        // The blind spot's cross is drawn.
        let (_, _, pixels) = decode_png(&dir.join("composite.png"));
        assert!(count_of(&pixels, BLIND_COLOUR) > 4);
        // The part meets columns 5..120: grown by a twentieth of that
        // (5 nodes), the window is the whole grid, 120 x 60 nodes, enlarged
        // 4 times to reach MIN_PLOT.
        assert_eq!(
            crop_window(&g, None),
            Window {
                i: 0..120,
                j: 0..60
            }
        );
        let plot = Raster::plan(120, 60).unwrap();
        assert_eq!((plot.w, plot.h, plot.up), (480, 240, 4));
        let want = (
            (MARGIN + Y_LABELS + 480 + MARGIN + BAR_AREA_W) as u32,
            (TITLE_H + 240 + X_LABELS + KEY_H + MARGIN) as u32,
        );
        assert_eq!(depth.plot, [MARGIN + Y_LABELS, TITLE_H, 480, 240]);
        assert_eq!(png_size(&dir.join("depth.png")), want);
        // The composite's key (four entries: the rings and the cross) takes
        // two lines.
        assert_eq!(comp.plot, depth.plot);
        assert_eq!(
            png_size(&dir.join("composite.png")),
            (want.0, want.1 + KEY_H as u32)
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn paper_sized_grid_fits_the_width_bound() {
        let dir = temp_dir("png-big");
        let g = grid(1538, 801, |i, j| (i + j) as f64 * 0.01);
        let r = Raster::plan(1538, 801).unwrap();
        assert_eq!((r.w, r.h, r.block), (769, 401, 2));
        write_composite_png(
            &dir.join("c.png"),
            &g,
            &vec![1; g.spec.len()],
            1,
            "all",
            &Side::Left.into(),
            &[],
        )
        .unwrap();
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

    fn count_of(pixels: &[[u8; 3]], colour: RGBColor) -> usize {
        pixels
            .iter()
            .filter(|p| **p == [colour.0, colour.1, colour.2])
            .count()
    }

    #[test]
    fn the_image_is_cropped_to_the_part_and_what_was_struck() {
        // A 20 x 10-node part in the middle of a 400 x 300-node grid (the
        // knee-form margin), and a struck node outside it.
        let g = grid(400, 300, |i, j| {
            if (190..210).contains(&i) && (145..155).contains(&j) {
                1.0
            } else {
                f64::INFINITY
            }
        });
        assert_eq!(
            crop_window(&g, None),
            Window {
                i: 187..213,
                j: 142..158
            }
        );
        let mut composite = vec![0u16; g.spec.len()];
        composite[150 * 400 + 230] = 1;
        let w = crop_window(&g, Some(&composite));
        assert_eq!(
            w,
            Window {
                i: 187..234,
                j: 142..158
            }
        );
        // Nothing meets the part: the whole grid.
        let empty = grid(40, 30, |_, _| f64::INFINITY);
        assert_eq!(crop_window(&empty, None), Window { i: 0..40, j: 0..30 });
        // The cropped grid keeps its nodes' coordinates.
        let c = w.crop(&g);
        assert_eq!((c.spec.x(0), c.spec.z(0)), (g.spec.x(187), g.spec.z(142)));
        assert_eq!(c.at(3, 3), g.at(190, 145));
    }

    #[test]
    fn a_single_struck_node_of_a_large_grid_is_circled_and_in_the_key() {
        let dir = temp_dir("png-one");
        // Wider than the plot: 2 nodes per pixel, so the node is under one
        // pixel of its own.
        let (nx, nz) = (2400, 600);
        let g = grid(nx, nz, |i, _| i as f64 * 0.01);
        let mut composite = vec![0u16; nx * nz];
        composite[300 * nx + 1000] = 5;
        let path = dir.join("one.png");
        write_composite_png(
            &path,
            &g,
            &composite,
            61,
            "one node",
            &Side::Left.into(),
            &[],
        )
        .unwrap();
        let (_, _, pixels) = decode_png(&path);
        // The ring: 2 px wide, radius 9: well over 50 pixels.
        assert!(count_of(&pixels, RING_COLOUR) > 50, "no ring");
        assert!(count_of(&pixels, count_colour(5, 61)) >= 1, "no node");
        // The grey of the part is in the key: its swatch's colour is drawn.
        let swatch = composite_key(true, false)[0].0;
        assert!(count_of(&pixels, swatch) >= 14 * 14 - 4 * 14);
        // Many struck nodes: no rings.
        let many = vec![1u16; nx * nz];
        write_composite_png(&path, &g, &many, 61, "all", &Side::Left.into(), &[]).unwrap();
        let (_, _, pixels) = decode_png(&path);
        assert_eq!(count_of(&pixels, RING_COLOUR), 0);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn the_right_side_is_drawn_as_its_knee_sees_it_with_x_reversed() {
        let dir = temp_dir("png-side");
        let g = grid(100, 50, |_, _| 0.0);
        // Struck: the node column of lowest x (the vehicle front).
        let composite: Vec<u16> = (0..100 * 50).map(|k| u16::from(k % 100 == 0)).collect();
        let struck = count_colour(1, 1);
        let mut first_column = Vec::new();
        for side in [Side::Left, Side::Right] {
            let path = dir.join("side.png");
            write_composite_png(&path, &g, &composite, 1, "side", &side.into(), &[]).unwrap();
            let (w, _, pixels) = decode_png(&path);
            let cols: Vec<usize> = (0..pixels.len())
                .filter(|&k| pixels[k] == [struck.0, struck.1, struck.2])
                .map(|k| k % w)
                .collect();
            first_column.push((*cols.iter().min().unwrap(), *cols.iter().max().unwrap()));
        }
        // Left: the front column is at the plot's left edge; right: at its
        // right edge (the bar, in the same colour, is further right still).
        let plot_left = MARGIN + Y_LABELS;
        assert!(first_column[0].0 <= plot_left + 10, "{first_column:?}");
        assert!(first_column[1].0 > plot_left + 300, "{first_column:?}");
        assert!(view_line(Side::Left).contains("looking +y"));
        assert!(view_line(Side::Right).contains("looking -y"));
        assert!(view_line(Side::Right).contains("front (-x) on the right"));
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn the_depth_bar_says_which_end_is_closer_to_the_knee() {
        // The bright end of the bar is small h: the bottom for the left
        // side (part y = h), the top for the right (part y = -h).
        assert_eq!(depth_bar_ends(Side::Left)[1], "closer to the knee");
        assert_eq!(depth_bar_ends(Side::Right)[0], "closer to the knee");
        let dir = temp_dir("png-depth");
        let g = grid(60, 60, |i, _| i as f64);
        for side in [Side::Left, Side::Right] {
            let path = dir.join("depth.png");
            let layout = write_depth_png(&path, &g, &side.into()).unwrap();
            let (w, h, pixels) = decode_png(&path);
            let bar = layout.chart_w..layout.chart_w + layout.bar_w;
            // The bar: the image's right strip; its brightest (closest)
            // colour nearest the end the words say.
            // viridis(1) is (253, 231, 37); the bar's end band is within a
            // step of it.
            let bright = |p: [u8; 3]| p[0] > 240 && p[1] > 220 && p[2] < 60;
            let rows: Vec<usize> = (0..pixels.len())
                .filter(|&k| bar.contains(&(k % w)) && bright(pixels[k]))
                .map(|k| k / w)
                .collect();
            assert!(!rows.is_empty(), "{side:?}");
            let mean = rows.iter().sum::<usize>() as f64 / rows.len() as f64;
            let closer_at_top = depth_bar_ends(side)[0] == "closer to the knee";
            assert_eq!(mean < h as f64 / 2.0, closer_at_top, "{side:?}: {mean}");
        }
        std::fs::remove_dir_all(dir).unwrap();
    }

    /// Asserts that nothing of `path`'s image (drawn with `layout`) is cut
    /// at its edges, and that every key entry, swatch and words, lies
    /// inside it and is drawn whole.
    fn assert_inside(path: &Path, layout: &Layout, what: &str) {
        let (w, h, pixels) = decode_png(path);
        assert_eq!((w, h), (layout.width, layout.height), "{what}");
        let at = |c: usize, r: usize| pixels[r * w + c];
        // The image's border (half its margin) is blank: no text, axis or
        // swatch runs off any side.
        let border = MARGIN / 2;
        for r in 0..h {
            for c in 0..w {
                if r < border || r >= h - border || c < border || c >= w - border {
                    assert_eq!(
                        at(c, r),
                        [255; 3],
                        "{what}: drawn at the edge, {c},{r} of {w}x{h}"
                    );
                }
            }
        }
        let dark = |p: [u8; 3]| p.iter().all(|&v| v < 140);
        for (k, &[x, y, ew]) in layout.key.iter().enumerate() {
            // The entry's box: the swatch, and the words to its right.
            assert!(
                x >= MARGIN && x + ew + MARGIN <= w && y + 18 + MARGIN <= h,
                "{what}: key entry {k} at {x},{y} ({ew} wide) outside {w}x{h}"
            );
            // The swatch's frame is drawn, and so are the words, to
            // within a few pixels of their measured end.
            assert!(
                dark(at(x, y + 7)) && dark(at(x + 14, y + 7)),
                "{what}: swatch {k}"
            );
            let last = (x + SWATCH_W..x + ew + 3)
                .filter(|&c| (y..y + 18).any(|r| dark(at(c, r))))
                .max()
                .unwrap_or(0);
            assert!(
                last + 6 >= x + ew,
                "{what}: key words {k} end at {last}, not {}",
                x + ew
            );
        }
    }

    #[test]
    fn every_key_entry_and_label_lies_inside_the_image_whatever_the_part() {
        let dir = temp_dir("png-inside");
        let framed = Placement {
            side: Side::Right,
            frame: crate::frame::Frame::parse("-y,x,z").unwrap(),
            approach: Approach::Direct,
        };
        let placements = [Side::Left.into(), Side::Right.into(), framed];
        // Tiny, tall and narrow, wide and flat, a scenario seen edge-on
        // (tilted-wave under --frame=-y,x,z: 7 x 80 nodes), ordinary, and
        // larger than the plot.
        for (nx, nz) in [
            (2, 2),
            (3, 400),
            (1500, 2),
            (7, 80),
            (120, 60),
            (3000, 1900),
        ] {
            let g = grid(nx, nz, |i, j| (i + 2 * j) as f64 * 0.37);
            // Few struck nodes (circled) and a blind spot (crossed): the
            // longest key, four entries.
            let mut composite = vec![0u16; nx * nz];
            composite[nx * nz / 2] = 2;
            for (n, placement) in placements.iter().enumerate() {
                let what = format!("{nx} x {nz}, placement {n}");
                let path = dir.join("depth.png");
                let layout = write_depth_png(&path, &g, placement).unwrap();
                assert_inside(&path, &layout, &format!("depth {what}"));
                let path = dir.join("composite.png");
                let layout = write_composite_png(
                    &path,
                    &g,
                    &composite,
                    61,
                    "Composite colliding area, 61 angles (L = 200 mm)",
                    placement,
                    &[(0, 0)],
                )
                .unwrap();
                assert_eq!(layout.key.len(), 4);
                assert_inside(&path, &layout, &format!("composite {what}"));
            }
        }
        std::fs::remove_dir_all(dir).unwrap();
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
