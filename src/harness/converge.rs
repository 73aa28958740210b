//! Convergence over the pitch: the same starts (the coarsest grid's; grids
//! on multiples of the pitch nest) compared at `p, p/2, p/4, ...`, a
//! power law `error ~ C p^alpha` fitted in log-log per metric, and the
//! coarsest pitch that meets a tolerance.

use std::path::Path;

use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use super::metrics::{DECIDED_METRICS, METRICS};
use super::verify::Comparison;

/// One pitch of a convergence study.
#[derive(Debug, Clone)]
pub struct PitchResult {
    /// The pitch (mm).
    pub pitch: f64,
    /// The comparison with the exact traces.
    pub comparison: Comparison,
    /// Wall-clock time of the engine's full push and slide at this pitch,
    /// for the study's angles (s).
    pub seconds: f64,
    /// Grid nodes.
    pub nodes: usize,
}

/// `error ~ c * pitch^alpha`, fitted by least squares on logarithms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// The order of convergence.
    pub alpha: f64,
    /// The constant (mm per mm^alpha).
    pub c: f64,
    /// Pitches with a positive error that entered the fit.
    pub points: usize,
}

/// Fits `y ~ c x^alpha` through the points with `x, y > 0`; `None` with
/// fewer than two such points (an error that is zero at every pitch has no
/// order).
pub fn fit_power_law(points: &[(f64, f64)]) -> Option<Fit> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = (
        logs.iter().map(|p| p.0).sum::<f64>() / n,
        logs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let alpha = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    Some(Fit {
        alpha,
        c: (my - alpha * mx).exp(),
        points: logs.len(),
    })
}

/// The fits of every metric's max error over `results`.
pub fn fits(results: &[PitchResult]) -> Vec<(String, Option<Fit>)> {
    METRICS
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let points: Vec<(f64, f64)> = results
                .iter()
                .map(|r| (r.pitch, r.comparison.stats[k].1.max))
                .collect();
            (m.to_string(), fit_power_law(&points))
        })
        .collect()
}

/// The coarsest pitch whose comparison passes `tolerance` (measured, not
/// extrapolated).
pub fn recommended_pitch(results: &[PitchResult], tolerance: f64) -> Option<&PitchResult> {
    results
        .iter()
        .filter(|r| r.comparison.passes(tolerance))
        .max_by(|a, b| a.pitch.total_cmp(&b.pitch))
}

/// `converge.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergeSummary {
    /// Version of kneeform.
    pub kneeform_version: String,
    /// The part as given.
    pub input_file: String,
    /// SHA-256 of the part file's bytes (hex), as `summary.json`'s
    /// `sha256`: what `kneeform report` matches a study to its run by.
    #[serde(default)]
    pub input_sha256: String,
    /// Factor from the file's units to mm.
    #[serde(default = "super::unit_scale")]
    pub scale: f64,
    /// `left` or `right`.
    #[serde(default = "super::left_side")]
    pub side: crate::Side,
    /// Knee-form L, R, W (mm).
    #[serde(default)]
    pub knee_form_mm: [f64; 3],
    /// The strike rule of every pitch, as in `summary.json`: sigma =
    /// tan(deflection) and how the grid's rate is estimated.
    pub sigma: f64,
    /// `capped` or `x-slope` (`summary.json`'s `rate`).
    pub rate: String,
    /// The pitches, coarsest first (mm).
    pub pitches_mm: Vec<f64>,
    /// Per metric, the fit of its max error, where it has one.
    pub fits: std::collections::BTreeMap<String, Fit>,
    /// The tolerance asked for (mm).
    pub tolerance_mm: Option<f64>,
    /// The coarsest pitch meeting it (mm).
    pub recommended_pitch_mm: Option<f64>,
    /// Predicted time of a full 61-angle analysis at that pitch (s): the
    /// measured time for the study's angles, scaled to 61.
    pub predicted_full_time_s: Option<f64>,
    /// Angles of the study (degrees).
    pub angles_deg: Vec<f64>,
    /// Deflection threshold delta (degrees).
    pub deflection_deg: f64,
    /// Rounding tolerance e0 (mm).
    pub e0_mm: f64,
    /// The tie band's rule, in words.
    pub tie_band_rule: String,
    /// Starts compared per angle.
    pub starts: usize,
    /// Per pitch: engine seconds for the study's angles.
    pub seconds: Vec<f64>,
}

/// Draws the log-log error plot (one series per decided metric, fitted
/// order in the legend: the guarantee a user reads) and the time plot into
/// `dir`.
pub fn write_plots(
    dir: &Path,
    results: &[PitchResult],
    fits: &[(String, Option<Fit>)],
) -> anyhow::Result<()> {
    crate::output::register_font()?;
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

fn draw_error<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("cannot draw the convergence plot: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_power_law() {
        let points: Vec<(f64, f64)> = [8.0, 4.0, 2.0, 1.0]
            .iter()
            .map(|&p: &f64| (p, 0.3 * p.powf(1.7)))
            .collect();
        let fit = fit_power_law(&points).unwrap();
        assert!(
            (fit.alpha - 1.7).abs() < 1e-12 && (fit.c - 0.3).abs() < 1e-12,
            "{fit:?}"
        );
        assert_eq!(fit.points, 4);
        // Zero errors carry no order.
        assert!(fit_power_law(&[(8.0, 0.0), (4.0, 0.0), (2.0, 1.0)]).is_none());
    }
}
