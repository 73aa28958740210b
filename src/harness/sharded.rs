//! A study fanned out over its starts: `verify --shard K/N` and
//! `converge --shard K/N` compare only the starts `s` (0-based, in the
//! study's order, after sampling) with `s % N == K - 1`, since the exact
//! oracle of each start and angle is the expensive part; [`merge_verify`]
//! and [`merge_converge`] put the N shares back together into the study
//! the unsharded command computes. The direct approach's studies
//! (`--approach direct`, [`super::direct`]) fan out over their positions
//! alike ([`super::verify_direct_shard`], [`super::converge_direct_shard`];
//! [`merge_verify_direct`], [`merge_converge_direct`]).
//!
//! A share ([`StudyPart`]) keeps every start-angle pair it compared as a
//! [`PairResult`] (the direct approach's position-angle pairs as a
//! [`DirectPair`]): a comparison's statistics, counts, area distances and
//! worst starts are computed from those alone ([`assemble`],
//! [`assemble_direct`]), so a merge that puts the pairs back in the
//! unsharded order computes them exactly as the unsharded run does. The
//! file format of a share is [`crate::shard::study`]'s.
//!
//! **Invariant:** a merged comparison is assembled from the pairs in the
//! unsharded run's order (angle-major, then the study's start order),
//! and its summary is set by the same function as the unsharded run's
//! ([`VerifySummary::set_comparison`], [`ConvergeSummary::set_results`],
//! [`DirectVerifySummary::set_comparison`],
//! [`DirectConvergeSummary::set_results`]); only clock readings differ.

use std::time::Instant;

use super::HarnessError;
use super::compare::{GridSide, PairResult, StartSelection, assemble, pair_results};
use super::converge::{ConvergeOptions, ConvergeSummary, Convergence, Ladder, PitchResult};
use super::direct::{
    DirectConvergeSummary, DirectConvergence, DirectPitchPairs, DirectPitchResult,
    DirectVerification, DirectVerifySummary, assemble_direct, converge_pairs, verify_pairs,
};
use super::metrics::TieBand;
use super::pairs::{DirectPair, NO_BAND, Pairs, PitchPart};
use super::verify::{Traced, Verification, VerifyOptions, VerifySummary};
use crate::analysis::Progress;
use crate::grid::GridSpec;
use crate::input::PartFile;
use crate::partition::Shard;
use crate::setup::Setup;

/// A shard's summary: `verify.json` or `converge.json` as the shard knows
/// it: the part's identity, every setting and the shard's own timings,
/// with the statistics of no start (the merge computes them from every
/// shard's pairs; `shard.json` leaves them out).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", content = "summary", rename_all = "lowercase")]
pub enum StudySummary {
    /// A verification's.
    Verify(Box<VerifySummary>),
    /// A convergence study's.
    Converge(ConvergeSummary),
    /// A direct verification's (`verify --approach direct`).
    #[serde(rename = "verify-direct")]
    VerifyDirect(DirectVerifySummary),
    /// A direct convergence study's (`converge --approach direct`).
    #[serde(rename = "converge-direct")]
    ConvergeDirect(DirectConvergeSummary),
}

/// The options of a sharded study as given, beyond its summary: what
/// every shard of one study shares.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StudySettings {
    /// `--starts` as given: `all`, a sample size, `strip:Z0:Z1`.
    pub starts: String,
    /// `--seed` of a sample (0 otherwise).
    pub seed: u64,
    /// `--tie-band` (per mm).
    pub tie_band_per_mm: f64,
    /// `--tolerance` (mm).
    pub tolerance_mm: Option<f64>,
    /// The pitches, coarsest first (mm): verify's one, converge's ladder.
    pub pitches_mm: Vec<f64>,
}

/// One shard's share of a verification or a convergence study.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyPart {
    /// Which shard of how many.
    pub shard: Shard,
    /// The grid the starts are nodes of (the coarsest of a study).
    pub spec: GridSpec,
    /// Every start of the study (mm, analysis frame), in its order; the
    /// share's are those of [`Shard::indices`].
    pub starts: Vec<[f64; 2]>,
    /// The study's angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Per pitch, coarsest first.
    pub pitches: Vec<PitchPart>,
    /// The options.
    pub settings: StudySettings,
    /// The study's summary as the shard knows it (a `StudySummary`).
    pub summary: StudySummary,
    /// Seconds sampling the grid (0 for the direct approach, whose
    /// summaries do not report it).
    pub sample_s: f64,
    /// Seconds of the oracle on the share's starts.
    pub oracle_s: f64,
}

/// A study's [`StudySettings`]: `selection` as given, its tie band,
/// tolerance and pitches.
pub(super) fn study_settings(
    selection: &StartSelection,
    tie_band_per_mm: f64,
    tolerance_mm: Option<f64>,
    pitches_mm: Vec<f64>,
) -> StudySettings {
    let (starts, seed) = super::verify::selection_words(selection);
    StudySettings {
        starts,
        seed,
        tie_band_per_mm,
        tolerance_mm,
        pitches_mm,
    }
}

/// [`super::verify()`] of `shard`'s share of the starts only.
pub fn verify_shard(
    input: &PartFile,
    setup: &Setup,
    options: &VerifyOptions,
    shard: Shard,
    progress: &dyn Progress,
) -> Result<StudyPart, HarnessError> {
    let Traced {
        spec,
        grid,
        footprints,
        all,
        starts,
        traces,
        compare,
        sample_s,
        oracle_s,
    } = Traced::new(input, setup, options, Some(shard), progress)?;
    let t = Instant::now();
    let pairs = super::in_stage(progress, &super::comparing(traces.len()), None, || {
        pair_results(
            &input.part.triangles,
            &grid,
            &footprints,
            &starts,
            &traces,
            &compare,
            GridSide::default(),
        )
    })?;
    let grid_s = t.elapsed().as_secs_f64();
    let band = TieBand::new(setup.rule.sigma, spec.pitch, options.tie_band_per_mm);
    // The study's identity and settings; its statistics are the merge's
    // (a shard's own could be infinite, which JSON cannot say).
    let none = assemble(Vec::new(), &setup.angles, band, 0.0);
    let mut summary = VerifySummary::new(input, setup, options, &spec, &none, sample_s, oracle_s);
    summary.timings.grid_s = grid_s;
    Ok(StudyPart {
        shard,
        spec,
        starts: all,
        angles_deg: setup.angles.clone(),
        pitches: vec![PitchPart {
            pitch: spec.pitch,
            pairs: Pairs::Slide(pairs),
            band,
            grid_s,
            seconds: 0.0,
            nodes: spec.len(),
        }],
        settings: study_settings(
            &options.selection,
            options.tie_band_per_mm,
            Some(options.tolerance),
            vec![setup.pitch],
        ),
        summary: StudySummary::Verify(Box::new(summary)),
        sample_s,
        oracle_s,
    })
}

/// [`super::converge()`] of `shard`'s share of the starts only: the
/// oracle on the share, every pitch's grid sampled and its engine timed
/// as the unsharded study does, the share's pairs compared.
pub fn converge_shard(
    input: &PartFile,
    setup: &Setup,
    options: &ConvergeOptions,
    shard: Shard,
    progress: &dyn Progress,
) -> Result<StudyPart, HarnessError> {
    if setup.approach == crate::frame::Approach::Direct {
        return Err(HarnessError::DirectApproach);
    }
    options.validate()?;
    let pitches = &options.pitches;
    let t = Instant::now();
    let ladder = Ladder::new(
        input,
        &Setup {
            pitch: pitches[0],
            ..setup.clone()
        },
        pitches[pitches.len() - 1],
        &options.selection,
        options.tie_band_per_mm,
        super::converge::Share {
            shard: Some(shard),
            oracle_budget_s: None,
            refuse_beyond_s: options.budget_s,
        },
        progress,
    )?;
    let sample_s = (t.elapsed().as_secs_f64() - ladder.oracle_s).max(0.0);
    for &p in pitches {
        setup.check_memory(&ladder.spec_at(p), input.part.triangles.len())?;
    }
    let mut parts = Vec::new();
    for &p in pitches {
        parts.push(ladder.measure_pairs(p, progress)?);
    }
    // The study's identity and settings; its fits are the merge's.
    let summary = ConvergeSummary::new(input, setup, options, ladder.all_starts.len(), &[]);
    Ok(StudyPart {
        shard,
        spec: ladder.coarse(),
        starts: ladder.all_starts.clone(),
        angles_deg: setup.angles.clone(),
        pitches: parts,
        settings: study_settings(
            &options.selection,
            options.tie_band_per_mm,
            options.tolerance,
            pitches.clone(),
        ),
        summary: StudySummary::Converge(summary),
        sample_s,
        oracle_s: ladder.oracle_s,
    })
}

/// The pairs of pitch `k` of `parts` (every shard of one study exactly
/// once, in shard order: `parts[K - 1]` is shard K's) in the unsharded
/// order: angle-major, then the study's start order. `pick` gives a
/// share's pairs of the study's kind (`None` for another kind, which
/// makes the merge `None`).
fn unsharded_pairs<T: Clone>(
    parts: &[StudyPart],
    k: usize,
    pick: impl Fn(&Pairs) -> Option<&[T]>,
) -> Option<Vec<T>> {
    let first = &parts[0];
    let (n, total) = (parts.len(), first.starts.len());
    let shares = parts
        .iter()
        .map(|p| pick(&p.pitches.get(k)?.pairs))
        .collect::<Option<Vec<&[T]>>>()?;
    let sizes: Vec<usize> = parts.iter().map(|p| p.shard.indices(total).len()).collect();
    let mut out = Vec::with_capacity(total * first.angles_deg.len());
    for a in 0..first.angles_deg.len() {
        for s in 0..total {
            out.push(shares[s % n].get(a * sizes[s % n] + s / n)?.clone());
        }
    }
    Some(out)
}

fn slide(pairs: &Pairs) -> Option<&[PairResult]> {
    match pairs {
        Pairs::Slide(p) => Some(p),
        Pairs::Direct(_) => None,
    }
}

fn direct(pairs: &Pairs) -> Option<&[DirectPair]> {
    match pairs {
        Pairs::Direct(p) => Some(p),
        Pairs::Slide(_) => None,
    }
}

/// Grid seconds of pitch `k` summed over the shards, the engine's seconds
/// (which every shard measures alike) their longest.
fn merged_clocks(parts: &[StudyPart], k: usize) -> PitchPart {
    let first = &parts[0].pitches[k];
    PitchPart {
        grid_s: parts.iter().map(|p| p.pitches[k].grid_s).sum(),
        seconds: parts
            .iter()
            .map(|p| p.pitches[k].seconds)
            .fold(0.0, f64::max),
        ..first.clone()
    }
}

/// Pitch `k` of the study `parts` merged: its pairs in the unsharded
/// order, assembled, with [`merged_clocks`].
fn merged_pitch(parts: &[StudyPart], k: usize) -> Option<PitchResult> {
    let merged = merged_clocks(parts, k);
    let pairs = unsharded_pairs(parts, k, slide)?;
    Some(PitchResult {
        pitch: merged.pitch,
        comparison: assemble(pairs, &parts[0].angles_deg, merged.band, merged.grid_s),
        seconds: merged.seconds,
        nodes: merged.nodes,
    })
}

/// Pitch `k` of the direct study `parts` merged (as [`merged_pitch`]).
fn merged_direct_pitch(parts: &[StudyPart], k: usize) -> Option<DirectPitchResult> {
    let merged = merged_clocks(parts, k);
    let pairs = unsharded_pairs(parts, k, direct)?;
    Some(DirectPitchResult {
        pitch: merged.pitch,
        comparison: assemble_direct(pairs, merged.grid_s),
        nodes: merged.nodes,
    })
}

/// A convergence study's summary as its first shard holds it (`None`
/// when it is another kind), and every pitch of the shares `parts`
/// merged by `pitch` (either approach's).
fn merged_pitches<S, R>(
    parts: &[StudyPart],
    summary: impl Fn(&StudySummary) -> Option<S>,
    pitch: impl Fn(&[StudyPart], usize) -> Option<R>,
) -> Option<(S, Vec<R>)> {
    let first = parts.first()?;
    let summary = summary(&first.summary)?;
    let results = (0..first.pitches.len())
        .map(|k| pitch(parts, k))
        .collect::<Option<Vec<R>>>()?;
    Some((summary, results))
}

/// The oracle's seconds summed over the shards.
fn oracle_s(parts: &[StudyPart]) -> f64 {
    parts.iter().map(|p| p.oracle_s).sum()
}

/// The verification of the shares `parts`: every shard of one study
/// exactly once, in shard order (as [`crate::shard::study`] checks), each
/// holding every pair of its starts.
pub(crate) fn merge_verify(parts: &[StudyPart]) -> Option<Verification> {
    let first = parts.first()?;
    let StudySummary::Verify(summary) = &first.summary else {
        return None;
    };
    let result = merged_pitch(parts, 0)?;
    let mut summary = VerifySummary::clone(summary);
    summary.set_comparison(&result.comparison, &first.spec);
    let t = &mut summary.timings;
    t.sample_s = parts.iter().map(|p| p.sample_s).fold(0.0, f64::max);
    t.oracle_s = oracle_s(parts);
    Some(Verification {
        comparison: result.comparison,
        summary,
    })
}

/// The convergence study of the shares `parts` (as [`merge_verify`]).
pub(crate) fn merge_converge(parts: &[StudyPart]) -> Option<Convergence> {
    let converge = |s: &StudySummary| match s {
        StudySummary::Converge(c) => Some(c.clone()),
        _ => None,
    };
    let (mut summary, results) = merged_pitches(parts, converge, merged_pitch)?;
    summary.set_results(&results);
    Some(Convergence {
        fits: super::converge::fits(&results),
        results,
        summary,
        oracle_s: oracle_s(parts),
    })
}

/// The direct verification of the shares `parts` (as [`merge_verify`]).
pub(crate) fn merge_verify_direct(parts: &[StudyPart]) -> Option<DirectVerification> {
    let first = parts.first()?;
    let StudySummary::VerifyDirect(summary) = &first.summary else {
        return None;
    };
    let comparison = merged_direct_pitch(parts, 0)?.comparison;
    let mut summary = summary.clone();
    summary.set_comparison(&comparison, oracle_s(parts));
    Some(DirectVerification {
        comparison,
        summary,
    })
}

/// The direct convergence study of the shares `parts` (as
/// [`merge_verify`]).
pub(crate) fn merge_converge_direct(parts: &[StudyPart]) -> Option<DirectConvergence> {
    let converge_direct = |s: &StudySummary| match s {
        StudySummary::ConvergeDirect(c) => Some(c.clone()),
        _ => None,
    };
    let (mut summary, results) = merged_pitches(parts, converge_direct, merged_direct_pitch)?;
    summary.oracle_s = oracle_s(parts);
    summary.set_results(&results);
    Some(DirectConvergence { results, summary })
}

/// [`verify_direct`](crate::harness::verify_direct) of `shard`'s share
/// of the positions only: the positions `s` (0-based, in the study's
/// order, after sampling) with `s % N == K - 1`, the oracle run on those
/// alone.
pub fn verify_direct_shard(
    input: &PartFile,
    setup: &Setup,
    options: &VerifyOptions,
    shard: Shard,
    progress: &dyn Progress,
) -> Result<StudyPart, HarnessError> {
    let (study, pairs, grid_s, oracle_s) =
        verify_pairs(input, setup, options, Some(shard), progress)?;
    // The study's identity and settings, the shard's own seconds; its
    // statistics are the merge's.
    let mut summary = DirectVerifySummary::new(input, setup, options);
    summary.grid_s = grid_s;
    summary.oracle_s = oracle_s;
    Ok(StudyPart {
        shard,
        spec: study.spec,
        pitches: vec![PitchPart {
            pitch: setup.pitch,
            pairs: Pairs::Direct(pairs),
            band: NO_BAND,
            grid_s,
            seconds: 0.0,
            nodes: study.spec.len(),
        }],
        starts: study.positions,
        angles_deg: setup.angles.clone(),
        settings: study_settings(
            &options.selection,
            options.tie_band_per_mm,
            Some(options.tolerance),
            vec![setup.pitch],
        ),
        summary: StudySummary::VerifyDirect(summary),
        sample_s: 0.0,
        oracle_s,
    })
}

/// [`converge_direct`](crate::harness::converge_direct) of `shard`'s
/// share of the positions only (as [`verify_direct_shard`]), every pitch
/// compared on the share.
pub fn converge_direct_shard(
    input: &PartFile,
    setup: &Setup,
    options: &ConvergeOptions,
    shard: Shard,
    progress: &dyn Progress,
) -> Result<StudyPart, HarnessError> {
    let (study, pitches, oracle_s) = converge_pairs(input, setup, options, Some(shard), progress)?;
    // The study's identity and settings, the shard's own oracle seconds;
    // its fits are the merge's.
    let summary =
        DirectConvergeSummary::new(input, setup, options, study.positions.len(), oracle_s);
    Ok(StudyPart {
        shard,
        spec: study.spec,
        starts: study.positions,
        angles_deg: setup.angles.clone(),
        pitches: pitches.into_iter().map(direct_part).collect(),
        settings: study_settings(
            &options.selection,
            options.tie_band_per_mm,
            options.tolerance,
            options.pitches.clone(),
        ),
        summary: StudySummary::ConvergeDirect(summary),
        sample_s: 0.0,
        oracle_s,
    })
}

/// A direct pitch's pairs as a shard keeps them.
fn direct_part(p: DirectPitchPairs) -> PitchPart {
    PitchPart {
        pitch: p.pitch,
        pairs: Pairs::Direct(p.pairs),
        band: NO_BAND,
        grid_s: p.grid_s,
        seconds: 0.0,
        nodes: p.nodes,
    }
}
