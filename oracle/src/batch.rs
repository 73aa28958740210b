//! Many starts at many angles, in parallel.

use rayon::prelude::*;

use crate::knee_form::KneeForm;
use crate::trace::trace_validated;
use crate::{OracleError, OracleOptions, Part, StartTrace};

/// Pushes and slides every start at every angle, in parallel on rayon's
/// current thread pool.
///
/// `starts` are reference-point positions `(x, z)` in mm, analysis frame;
/// `angles_deg` are knee-form angles in degrees. The output is in a fixed
/// order whatever the threads: angle-major, `angles_deg.len() *
/// starts.len()` traces, the trace of `starts[s]` at `angles_deg[a]` at
/// index `a * starts.len() + s`.
pub fn evaluate(
    part: &Part,
    starts: &[[f64; 2]],
    angles_deg: &[f64],
    options: &OracleOptions,
) -> Result<Vec<StartTrace>, OracleError> {
    evaluate_reporting(part, starts, angles_deg, options, &|| {})
}

/// [`evaluate`], calling `traced` once as each start-angle pair's trace
/// is done (from whichever thread traced it): a caller's progress.
pub fn evaluate_reporting(
    part: &Part,
    starts: &[[f64; 2]],
    angles_deg: &[f64],
    options: &OracleOptions,
    traced: &(dyn Fn() + Sync),
) -> Result<Vec<StartTrace>, OracleError> {
    let n = starts.len();
    let pairs: Vec<(usize, usize)> = (0..angles_deg.len() * n).map(|k| (k % n, k / n)).collect();
    evaluate_pairs(part, starts, angles_deg, &pairs, options, traced)
}

/// The traces of the start-angle `pairs` (`(start, angle)`, indices into
/// `starts` and `angles_deg`), in their order, in parallel on rayon's
/// current thread pool, calling `traced` as each is done: any subset of
/// [`evaluate`]'s pairs, each trace the same.
pub fn evaluate_pairs(
    part: &Part,
    starts: &[[f64; 2]],
    angles_deg: &[f64],
    pairs: &[(usize, usize)],
    options: &OracleOptions,
    traced: &(dyn Fn() + Sync),
) -> Result<Vec<StartTrace>, OracleError> {
    options.validate()?;
    if let Some(bad) = angles_deg.iter().find(|a| !a.is_finite()) {
        return Err(OracleError::InvalidOptions(format!(
            "angle {bad} is not finite"
        )));
    }
    if let Some(bad) = starts
        .iter()
        .find(|s| !(s[0].is_finite() && s[1].is_finite()))
    {
        return Err(OracleError::InvalidOptions(format!(
            "start {bad:?} is not finite"
        )));
    }
    if let Some(&(s, a)) = pairs
        .iter()
        .find(|&&(s, a)| s >= starts.len() || a >= angles_deg.len())
    {
        return Err(OracleError::InvalidOptions(format!(
            "pair ({s}, {a}) is not a start and angle given"
        )));
    }
    let knees: Vec<KneeForm> = angles_deg
        .iter()
        .map(|&angle| KneeForm::new(options.knee_form, angle))
        .collect();
    Ok(pairs
        .par_iter()
        .map(|&(s, a)| {
            let trace = trace_validated(part, &knees[a], starts[s], options);
            traced();
            trace
        })
        .collect())
}
