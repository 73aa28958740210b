//! Many starts at many angles, in parallel.

use rayon::prelude::*;

use crate::knee_form::KneeForm;
use crate::trace::{Chain, trace_joining, trace_validated};
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
    let Some(chain) = options.chain else {
        return Ok(pairs
            .par_iter()
            .map(|&(s, a)| {
                let trace = trace_validated(part, &knees[a], starts[s], options);
                traced();
                trace
            })
            .collect());
    };
    // Each chain traced from its block's first column to the last column
    // asked for, its links in order; the chains in parallel.
    let groups = chain_groups(starts, pairs, &chain);
    let traced_groups: Vec<Vec<(usize, StartTrace)>> = groups
        .par_iter()
        .map(|group| {
            let (s, a) = pairs[group[0]];
            let z = starts[s][1];
            // Each pair's column, in column order.
            let mut columns: Vec<(i64, usize)> = group
                .iter()
                .filter_map(|&k| Some((chain.column(starts[pairs[k].0][0])?, k)))
                .collect();
            columns.sort_unstable();
            let Some(&(last, _)) = columns.last() else {
                // Off the lattice: one start, traced on its own.
                let trace = trace_validated(part, &knees[a], starts[s], options);
                traced();
                return vec![(group[0], trace)];
            };
            let mut out = Vec::with_capacity(group.len());
            let mut asked = columns.iter().peekable();
            let mut left: Option<StartTrace> = None;
            for c in chain.head(last)..=last {
                let start = [chain.x(c), z];
                let trace = trace_joining(part, &knees[a], start, options, left.as_ref());
                while let Some(&(_, k)) = asked.next_if(|&&(col, _)| col == c) {
                    out.push((k, trace.clone()));
                    traced();
                }
                left = Some(trace);
            }
            out
        })
        .collect();
    let mut traces: Vec<Option<StartTrace>> = vec![None; pairs.len()];
    for (k, trace) in traced_groups.into_iter().flatten() {
        traces[k] = Some(trace);
    }
    Ok(traces
        .into_iter()
        .map(|t| t.expect("every pair lies in one chain"))
        .collect())
}

/// The pairs of `pairs` (indices into it) that [`evaluate_pairs`] traces
/// together under `chain`: one group per angle, row (`z`) and block of
/// the lattice, in the order of their first pair; a start off the lattice
/// alone. Tracing whole groups, any subset of them costs no more than its
/// own chains.
pub fn chain_groups(
    starts: &[[f64; 2]],
    pairs: &[(usize, usize)],
    chain: &Chain,
) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut index: std::collections::HashMap<(usize, u64, i64), usize> = Default::default();
    for (k, &(s, a)) in pairs.iter().enumerate() {
        let [x, z] = starts[s];
        match chain.column(x) {
            Some(c) => {
                let key = (a, z.to_bits(), chain.head(c));
                let g = *index.entry(key).or_insert_with(|| {
                    groups.push(Vec::new());
                    groups.len() - 1
                });
                groups[g].push(k);
            }
            None => groups.push(vec![k]),
        }
    }
    groups
}
