//! The convergence study's plots: the largest decided error against the
//! pitch, and the engine's time against the pitch, both log-log.

use std::path::Path;

use plotters::prelude::*;

use super::WriteError;
use crate::harness::DECIDED_METRICS;
use crate::harness::converge::{Fit, PitchResult};

/// Draws the log-log error plot (one series per decided metric, fitted
/// order in the legend: the guarantee a user reads) and the time plot into
/// `dir`.
pub fn write_plots(
    dir: &Path,
    results: &[PitchResult],
    fits: &[(String, Option<Fit>)],
) -> Result<(), WriteError> {
    super::register_font()?;
    let pitches: Vec<f64> = results.iter().map(|r| r.pitch).collect();
    let (pmin, pmax) = (
        pitches.iter().copied().fold(f64::INFINITY, f64::min),
        pitches.iter().copied().fold(0.0, f64::max),
    );
    let positive: Vec<f64> = results
        .iter()
        .flat_map(|r| r.comparison.stats.iter().map(|s| s.1.max))
        .filter(|v| *v > 0.0 && v.is_finite())
        .collect();
    let (emin, emax) = (
        positive
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
            .min(1e-3),
        positive.iter().copied().fold(0.0, f64::max).max(1e-2),
    );
    let colours = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
        RGBColor(140, 86, 75),
    ];
    {
        let path = dir.join("error_vs_pitch.png");
        let root = BitMapBackend::new(&path, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_error)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "Grid vs exact, decided strikes: largest error against pitch (log-log)",
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (pmin / 1.5..pmax * 1.5).log_scale(),
                (emin / 2.0..emax * 2.0).log_scale(),
            )
            .map_err(draw_error)?;
        chart
            .configure_mesh()
            .x_desc("pitch (mm)")
            .y_desc("max error (mm)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(draw_error)?;
        let plotted = fits
            .iter()
            .enumerate()
            .filter(|(_, (m, _))| DECIDED_METRICS.contains(&m.as_str()));
        for (series, (k, (metric, fit))) in plotted.enumerate() {
            let colour = colours[series % colours.len()];
            let points: Vec<(f64, f64)> = results
                .iter()
                .map(|r| (r.pitch, r.comparison.stats[k].1.max))
                .filter(|(_, e)| *e > 0.0 && e.is_finite())
                .collect();
            let label = match fit {
                Some(f) => format!("{metric}: alpha = {:.2}", f.alpha),
                None => format!("{metric}: no fit"),
            };
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(draw_error)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(draw_error)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(draw_error)?;
        root.present().map_err(draw_error)?;
    }
    {
        let path = dir.join("time_vs_pitch.png");
        let root = BitMapBackend::new(&path, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_error)?;
        let times: Vec<(f64, f64)> = results
            .iter()
            .map(|r| (r.pitch, r.seconds.max(1e-4)))
            .collect();
        let (tmin, tmax) = (
            times.iter().map(|t| t.1).fold(f64::INFINITY, f64::min),
            times.iter().map(|t| t.1).fold(0.0, f64::max),
        );
        let mut chart = ChartBuilder::on(&root)
            .caption("Engine time against pitch (log-log)", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (pmin / 1.5..pmax * 1.5).log_scale(),
                (tmin / 2.0..tmax * 2.0).log_scale(),
            )
            .map_err(draw_error)?;
        chart
            .configure_mesh()
            .x_desc("pitch (mm)")
            .y_desc("push + slide, study angles (s)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(draw_error)?;
        chart
            .draw_series(LineSeries::new(times.clone(), colours[0].stroke_width(2)))
            .map_err(draw_error)?;
        chart
            .draw_series(
                times
                    .iter()
                    .map(|&p| Circle::new(p, 4, colours[0].filled())),
            )
            .map_err(draw_error)?;
        root.present().map_err(draw_error)?;
    }
    Ok(())
}

fn draw_error<E: std::fmt::Display>(e: E) -> WriteError {
    WriteError::Plot(e.to_string())
}
