//! A study's plots against the pitch, log-log, as its approach describes
//! them (`LogLogPlot`): the convergence study's largest decided error and
//! the engine's time.
//!
//! Both are laid out from their text, measured: the value labels of the y
//! axis get the room the widest of them needs, the image is as wide as
//! its caption, and the legend lies in a strip under the plot (it hid the
//! data it named when drawn over the plot). Ticks are chosen here, not by
//! plotters: on the pitch axis at the study's pitches, on the value axis
//! at 1, 2 and 5 of each decade (every decade, or every few, over a wide
//! range); labels are written with at most three significant digits, so
//! no float noise reaches them (`9.999999999e-5` was a label).

use std::ops::Range;
use std::path::Path;

use plotters::prelude::*;

use super::WriteError;
use crate::harness::approach::LogLogPlot;

/// The font of every text here (registered by [`super::register_font`]).
const FONT: &str = "sans-serif";
/// The plots' smallest size (pixels); wider where the caption needs it,
/// taller by the legend's strip.
const WIDTH: u32 = 900;
const HEIGHT: u32 = 600;
/// Space around the chart (pixels).
const MARGIN: u32 = 16;
/// Text sizes (points): caption, labels and axis names, legend.
const CAPTION_PT: u32 = 22;
const LABEL_PT: u32 = 14;
/// The x axis's labels and its name, under the plot (pixels).
const X_LABEL_AREA: u32 = 45;
/// Beside the widest y label: the tick, the label's distance from it,
/// and the rotated axis name with a gap (pixels).
const Y_LABEL_EXTRA: u32 = 48;
/// One line of the legend (pixels), and the gap between its columns.
const LEGEND_LINE: u32 = 22;
const LEGEND_GAP: u32 = 28;
/// A legend entry's swatch: a stroke with a dot, then the words.
const SWATCH: u32 = 30;

/// The series' colours, in order (the k-th series the k-th, cycling).
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
];

/// The colour of series `k`.
fn colour(k: usize) -> RGBColor {
    COLOURS[k % COLOURS.len()]
}

/// Draws `plot` into `dir` (its file's name is the plot's), its series
/// coloured in order.
pub(crate) fn write_plot(dir: &Path, plot: &LogLogPlot) -> Result<(), WriteError> {
    super::register_font()?;
    draw_log_log(&dir.join(plot.file), plot)?;
    Ok(())
}

/// Where [`draw_log_log`] put its text (pixels).
#[derive(Debug, Clone, PartialEq)]
struct PlotLayout {
    /// The image.
    width: u32,
    height: u32,
    /// The y labels' area: the widest label, its tick and the axis name.
    y_label_area: u32,
    /// The y axis's labels, bottom up.
    y_labels: Vec<String>,
    /// The x axis's labels, left to right.
    x_labels: Vec<String>,
    /// Per legend entry: the left column and top row of its swatch, and
    /// the width of swatch and words.
    legend: Vec<[u32; 3]>,
}

/// The width and height (pixels) of `text` at `pt`.
fn text_size(text: &str, pt: u32) -> Result<(u32, u32), WriteError> {
    (FONT, pt)
        .into_font()
        .box_size(text)
        .map_err(|e| WriteError::Plot(format!("cannot measure {text:?}: {e:?}")))
}

/// Draws `plot` into `path`.
fn draw_log_log(path: &Path, plot: &LogLogPlot) -> Result<PlotLayout, WriteError> {
    let mut pitches: Vec<f64> = plot
        .pitches
        .iter()
        .copied()
        .filter(|p| *p > 0.0 && p.is_finite())
        .collect();
    pitches.sort_by(f64::total_cmp);
    pitches.dedup();
    let (pmin, pmax) = match (pitches.first(), pitches.last()) {
        (Some(&lo), Some(&hi)) => (lo, hi),
        _ => (0.5, 2.0),
    };
    let x_range = pmin / 1.5..pmax * 1.5;
    let y_range = match &plot.values {
        r if r.start > 0.0 && r.start < r.end && r.end.is_finite() => r.clone(),
        // No value (no pitch ran): an empty decade.
        _ => 0.1..1.0,
    };
    let y_ticks = log_ticks(y_range.clone());
    let y_labels: Vec<String> = y_ticks.iter().map(|v| log_label(*v)).collect();
    let x_labels: Vec<String> = pitches.iter().map(|v| log_label(*v)).collect();
    let mut widest = 0;
    for label in &y_labels {
        widest = widest.max(text_size(label, LABEL_PT)?.0);
    }
    let y_label_area = widest + Y_LABEL_EXTRA;
    // The legend's entries, in as many columns as fit.
    let mut width = WIDTH.max(text_size(plot.caption, CAPTION_PT)?.0 + 2 * MARGIN + 8);
    let mut entries = Vec::new();
    for s in &plot.series {
        if let Some(label) = &s.label {
            entries.push(SWATCH + text_size(label, LABEL_PT)?.0);
        }
    }
    let column = entries.iter().copied().max().unwrap_or(0) + LEGEND_GAP;
    width = width.max(column + 2 * MARGIN);
    let columns = ((width - 2 * MARGIN + LEGEND_GAP) / column).max(1) as usize;
    let rows = entries.len().div_ceil(columns) as u32;
    let legend_h = if rows == 0 {
        0
    } else {
        rows * LEGEND_LINE + MARGIN
    };
    let height = HEIGHT + legend_h;
    // Under the chart, left to right then down: from the plot's left edge
    // where the columns fit so, else from the margin.
    let used = columns.min(entries.len()) as u32 * column;
    let x0 = if MARGIN + y_label_area + used + MARGIN <= width + LEGEND_GAP {
        MARGIN + y_label_area
    } else {
        MARGIN
    };
    let legend: Vec<[u32; 3]> = entries
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            let (col, row) = ((k % columns) as u32, (k / columns) as u32);
            [x0 + col * column, HEIGHT + row * LEGEND_LINE, w]
        })
        .collect();
    let layout = PlotLayout {
        width,
        height,
        y_label_area,
        y_labels,
        x_labels,
        legend,
    };
    draw(path, plot, &layout, &pitches, x_range, y_range, &y_ticks).map_err(draw_error)?;
    Ok(layout)
}

type DrawResult =
    Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>;

/// The drawing of [`draw_log_log`], at the places `layout` gives.
fn draw(
    path: &Path,
    plot: &LogLogPlot,
    layout: &PlotLayout,
    pitches: &[f64],
    x_range: Range<f64>,
    y_range: Range<f64>,
    y_ticks: &[f64],
) -> DrawResult {
    let root = BitMapBackend::new(path, (layout.width, layout.height)).into_drawing_area();
    root.fill(&WHITE)?;
    let chart_area = root.clone().shrink((0, 0), (layout.width, HEIGHT));
    // Light lines at 1 to 9 of each decade; at each decade only over more
    // than four (a line every few pixels is a grey band).
    let decades = |r: &Range<f64>| {
        let (lo, hi) = (r.start.log10(), r.end.log10());
        let every_m = hi - lo <= 4.0;
        (lo.floor() as i32..=hi.ceil() as i32)
            .flat_map(|e| (1..10).map(move |m: u32| (m, f64::from(m) * 10f64.powi(e))))
            .filter(|&(m, v)| r.contains(&v) && (m == 1 || every_m))
            .map(|(_, v)| v)
            .collect::<Vec<f64>>()
    };
    let x_light = decades(&x_range);
    let y_light = decades(&y_range);
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(plot.caption, (FONT, CAPTION_PT))
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(layout.y_label_area)
        .build_cartesian_2d(
            x_range
                .log_scale()
                .with_key_points(pitches.to_vec())
                .with_light_points(x_light),
            y_range
                .log_scale()
                .with_key_points(y_ticks.to_vec())
                .with_light_points(y_light),
        )?;
    let label = |v: &f64| log_label(*v);
    chart
        .configure_mesh()
        .x_desc(plot.x_desc)
        .y_desc(plot.y_desc)
        .x_label_formatter(&label)
        .y_label_formatter(&label)
        .label_style((FONT, LABEL_PT))
        .draw()?;
    for (k, s) in plot.series.iter().enumerate() {
        chart.draw_series(LineSeries::new(
            s.points.iter().copied(),
            colour(k).stroke_width(2),
        ))?;
        chart.draw_series(
            s.points
                .iter()
                .map(|&p| Circle::new(p, 4, colour(k).filled())),
        )?;
    }
    let style = (FONT, LABEL_PT).into_text_style(&root);
    let labelled = plot
        .series
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.label.as_ref().map(|l| (colour(k), l)));
    for ((colour, words), &[x, y, _]) in labelled.zip(&layout.legend) {
        let (x, y) = (x as i32, y as i32);
        root.draw(&PathElement::new(
            vec![(x, y + 8), (x + 22, y + 8)],
            colour.stroke_width(2),
        ))?;
        root.draw(&Circle::new((x + 11, y + 8), 4, colour.filled()))?;
        root.draw_text(words, &style, (x + SWATCH as i32, y))?;
    }
    root.present()
}

/// Ticks of a log axis over `range` (positive): 1, 2 and 5 of each decade
/// when the range spans at most three decades, every decade up to eight,
/// and every few decades beyond, so that there are at most about eight
/// labels; at least the range's ends' decades when none falls inside.
fn log_ticks(range: Range<f64>) -> Vec<f64> {
    let (lo, hi) = (range.start.log10(), range.end.log10());
    let (first, last) = (lo.floor() as i32, hi.ceil() as i32);
    let span = (hi - lo).max(0.0);
    let inside = |v: &f64| range.start <= *v && *v <= range.end;
    let mantissas: &[f64] = if span <= 3.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let every = (span / 8.0).ceil().max(1.0) as i32;
    let ticks: Vec<f64> = (first..=last)
        .filter(|e| e.rem_euclid(every) == 0)
        .flat_map(|e| mantissas.iter().map(move |m| m * 10f64.powi(e)))
        .filter(inside)
        .collect();
    if ticks.is_empty() {
        // Within one decade, narrower than 1-2-5: its ends.
        vec![range.start, range.end]
    } else {
        ticks
    }
}

/// A positive axis value with at most three significant digits and no
/// float noise: `0.001`, `0.3`, `12.5`, `40000`; `1e-5`, `2.5e-8` and
/// `1e5` outside [0.001, 100000).
fn log_label(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return format!("{v}");
    }
    let mut e = v.log10().floor() as i32;
    let mut m = (v / 10f64.powi(e) * 100.0).round() / 100.0;
    if m >= 10.0 {
        m /= 10.0;
        e += 1;
    }
    if (-3..5).contains(&e) {
        let digits = (2 - e).max(0) as usize;
        let text = format!("{:.*}", digits, m * 10f64.powi(e));
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        let mantissa = format!("{m:.2}");
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{e}")
    }
}

fn draw_error<E: std::fmt::Display>(e: E) -> WriteError {
    WriteError::Plot(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::harness::approach::PlotLine;
    use crate::output::{decode_png, temp_dir};

    #[test]
    fn labels_have_three_significant_digits_and_no_float_noise() {
        assert_eq!(log_label(9.999999999e-5), "1e-4");
        assert_eq!(log_label(0.30000000000000004), "0.3");
        assert_eq!(log_label(14.879999999999999), "14.9");
        assert_eq!(log_label(0.001), "0.001");
        assert_eq!(log_label(4.0), "4");
        assert_eq!(log_label(0.62), "0.62");
        assert_eq!(log_label(1.24), "1.24");
        assert_eq!(log_label(40000.0), "40000");
        assert_eq!(log_label(2.5e-8), "2.5e-8");
        assert_eq!(log_label(1e-8), "1e-8");
        assert_eq!(log_label(1e5), "1e5");
        assert_eq!(log_ticks(0.005..0.2), [0.005, 0.01, 0.02, 0.05, 0.1, 0.2]);
        assert_eq!(log_ticks(0.003..0.4), [0.005, 0.01, 0.02, 0.05, 0.1, 0.2]);
        assert_eq!(log_ticks(3e-9..40.0).len(), 5);
        assert_eq!(log_ticks(2.1..2.9), [2.1, 2.9]);
    }

    #[test]
    fn convergence_plots_keep_every_label_inside_the_canvas() {
        let dir = temp_dir("plot-inside");
        // An error exact to rounding at every pitch beside errors of mm, a
        // time at the 1e-4 s floor: the labels the plots had trouble with
        // (`9.999999999e-5`, two `0.1` one over the other).
        let pitches = [0.5, 1.0, 2.0, 4.0, 8.0];
        let cases = [
            (
                1e-8 / 2.0..40.0,
                vec![1e-8, 1.1e-8, 0.3, 2.5, 14.879999999999999],
            ),
            (5e-5..2e-3, vec![1e-4, 1e-4, 2e-4, 4e-4, 1e-3]),
            (0.0025..0.2, vec![0.1, 0.022, 0.005, 0.005, 0.005]),
            (1.0..9000.0, vec![4000.0, 700.0, 90.0, 12.0, 2.0]),
        ];
        for (n, (values, ys)) in cases.into_iter().enumerate() {
            let series = (0..2)
                .map(|s| PlotLine {
                    label: (n % 2 == 0)
                        .then(|| format!("first_contact_error_decided, number {s}: alpha = 1.31")),
                    points: pitches
                        .iter()
                        .zip(&ys)
                        .map(|(&p, &y)| (p, y * (1.0 + s as f64)))
                        .collect(),
                })
                .collect();
            let path = dir.join("plot.png");
            crate::output::register_font().unwrap();
            let layout = draw_log_log(
                &path,
                &LogLogPlot {
                    file: "plot.png",
                    caption: "Engine time against pitch (log-log)",
                    x_desc: "pitch (mm)",
                    y_desc: "push + slide, study angles (s)",
                    pitches: pitches.to_vec(),
                    values,
                    series,
                },
            )
            .unwrap();
            let (w, h, pixels) = decode_png(&path);
            assert_eq!((w as u32, h as u32), (layout.width, layout.height));
            // Nothing is drawn in the canvas's outer margin: no label
            // runs off an edge.
            let border = (MARGIN / 2) as usize;
            for r in 0..h {
                for c in 0..w {
                    if r < border || r >= h - border || c < border || c >= w - border {
                        assert_eq!(pixels[r * w + c], [255; 3], "case {n}: drawn at {c},{r}");
                    }
                }
            }
            // Every y label fits its area beside the axis name; each
            // label is short (no float noise).
            for label in layout.y_labels.iter().chain(&layout.x_labels) {
                assert!(label.len() <= 6, "case {n}: {label}");
                let (lw, _) = text_size(label, LABEL_PT).unwrap();
                assert!(
                    lw + Y_LABEL_EXTRA <= layout.y_label_area,
                    "case {n}: {label}"
                );
            }
            assert_eq!(layout.x_labels, ["0.5", "1", "2", "4", "8"]);
            // The legend lies under the plot, inside the canvas.
            for &[x, y, ew] in &layout.legend {
                assert!(y >= HEIGHT && y + LEGEND_LINE <= layout.height, "case {n}");
                assert!(x >= MARGIN && x + ew + MARGIN <= layout.width, "case {n}");
            }
            assert_eq!(layout.legend.len(), if n % 2 == 0 { 2 } else { 0 });
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
}
