//! The verification harness: the grid engine against the exact oracle on
//! the same starts (SPEC, "What the harness measures"), and convergence
//! over the pitch.
//!
//! * [`trace`]: the grid's push and slide of one start, with the travel of
//!   each colliding node (and test-only [`Fault`]s);
//! * [`metrics`]: push, first-contact, miss and false-alarm errors, area
//!   IoU;
//! * [`verify`]: start selection, the oracle's traces, one grid's
//!   comparison;
//! * [`converge`]: the same starts at several pitches, the fitted order of
//!   convergence and the pitch to choose.
//!
//! **Invariant:** the harness reads the oracle's answers and the engine's,
//! and computes neither's geometry itself.

pub mod converge;
pub mod metrics;
pub mod nearest;
pub mod trace;
pub mod verify;

pub use metrics::{DECIDED_METRICS, METRICS, Stats, TieBand};
pub use trace::{Fault, GridTrace, grid_trace};
pub use verify::{
    AreaDistance, CompareOptions, Comparison, Counts, StartSelection, VerifyRow, compare_grid,
    exact_traces, select_starts,
};

use serde::{Deserialize, Serialize};

/// `verify.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VerifySummary {
    /// Version of kneeform.
    pub kneeform_version: String,
    /// The part (STL or scenario file) as given.
    pub input_file: String,
    /// SHA-256 of the part file's bytes (hex), as `summary.json`'s
    /// `sha256`: what `kneeform report` matches a verification to its run by.
    #[serde(default)]
    pub input_sha256: String,
    /// Factor from the file's units to mm.
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// `left` or `right`.
    #[serde(default = "left_side")]
    pub side: crate::Side,
    /// Grid pitch (mm).
    pub pitch_mm: f64,
    /// The tolerance every metric's max is held to (mm).
    pub tolerance_mm: f64,
    /// Whether every decided metric is within tolerance, with nothing
    /// contradictory or failed (undecided strikes never fail).
    pub pass: bool,
    /// Angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Knee-form L, R, W (mm).
    pub knee_form_mm: [f64; 3],
    /// Deflection threshold delta (degrees).
    pub deflection_deg: f64,
    /// The same threshold as a rate, `sigma = tan(delta)`.
    pub sigma: f64,
    /// Rounding tolerance e0 (mm).
    pub e0_mm: f64,
    /// How the grid's deflection rate is estimated (`capped` or `x-slope`).
    pub rate: String,
    /// The tie band at this pitch: `sigma`, `m`, and its bounds as rates.
    pub tie_band: TieBand,
    /// The tie band's rule, in words.
    pub tie_band_rule: String,
    /// The headline: the area distance, decided (mm; `null` if infinite).
    pub area_distance_decided_mm: Option<f64>,
    /// The area distance over all strikes (mm; `null` if infinite).
    pub area_distance_mm: Option<f64>,
    /// The area distance per angle.
    pub area_distance: Vec<AreaDistance>,
    /// `all`, or the sample size.
    pub starts: String,
    /// The sample's seed.
    pub seed: u64,
    /// Per metric: max, p95, mean over the values (mm).
    pub metrics: std::collections::BTreeMap<String, Stats>,
    /// Grid mask against exact contacts snapped to nodes.
    pub area_iou: f64,
    /// Counts.
    pub counts: Counts,
    /// The worst start-angle pairs.
    pub worst_starts: Vec<WorstStart>,
    /// Seconds on each side.
    pub timings: VerifyTimings,
}

/// `scale` of files written before it was recorded.
pub(crate) fn unit_scale() -> f64 {
    1.0
}

/// `side` of files written before it was recorded.
pub(crate) fn left_side() -> crate::Side {
    crate::Side::Left
}

/// One of the worst start-angle pairs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorstStart {
    /// Grid column.
    pub i: usize,
    /// Grid row.
    pub j: usize,
    /// Start position x (mm, analysis frame).
    pub x: f64,
    /// Start position z (mm).
    pub z: f64,
    /// Angle (degrees).
    pub angle_deg: f64,
    /// The metric that is worst there.
    pub metric: String,
    /// Its value (mm).
    pub value: f64,
    /// Where the disagreement lies, `[x, z]` (mm, analysis frame): the
    /// missed exact strike or the false-alarm grid strike.
    pub at: Option<[f64; 2]>,
}

/// Seconds spent by each side.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct VerifyTimings {
    /// Sampling the grid.
    pub sample_s: f64,
    /// Grid push and slide of the compared starts.
    pub grid_s: f64,
    /// The oracle's traces.
    pub oracle_s: f64,
}
