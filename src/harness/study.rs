//! One study path for both studies and both approaches: `verify` (one
//! pitch) and `converge` (a ladder of pitches), push-and-slide or the
//! direct approach, whole or one shard's share of the starts.
//!
//! Every study runs as [`study_shard`]: it lays the coarsest grid and
//! chooses the study's starts on it, takes the exact side of the share's
//! starts, and compares every pitch's grid with it; the
//! result is a [`StudyPart`]. The whole study ([`study`]) is the merge
//! ([`merge`]) of its one share, shard 1/1, so the unsharded command and a
//! merge of N shards compute every statistic in one place.
//!
//! What differs per approach is its
//! [`super::approach::StudyApproach`] ([`super::studies_of`] names
//! them): the [`super::method::Method`] it lays (its grids, its exact
//! side, its pairs), its summaries, its pairs in a shard's file and its
//! merge. What differs per study is its options ([`StudyOptions`]); this
//! module names no approach.

use super::approach::{ShareKnown, Study, StudyOptions};
use super::converge::{ConvergeOptions, Convergence};
use super::error::HarnessError;
use super::method::{Laid, MemoryLimit, Pitch, Tracing, spec_at};
use super::pairs::share;
use super::sharded::{StudyKind, StudyPart, study_settings};
use super::trace::Fault;
use super::verify::{Verification, VerifyOptions};
use crate::analysis::Progress;
use crate::frame::Approach;
use crate::input::PartFile;
use crate::partition::Shard;
use crate::setup::Setup;

/// What a study of a part of `triangles` triangles holds besides its
/// traces and comparisons (bytes): the program, the part and the oracle's
/// copy of it, the grid of each of `pitches` (laid from `coarse`), and the
/// finer bands that refine the finest pitch's misses.
fn held_bytes(
    approach: &dyn super::approach::StudyApproach,
    setup: &Setup,
    triangles: usize,
    coarse: &crate::grid::GridSpec,
    pitches: &[f64],
) -> f64 {
    use crate::memory::{
        BASE_BYTES, BYTES_PER_TRIANGLE, ORACLE_BYTES_PER_TRIANGLE, STUDY_GRID_BYTES_PER_NODE,
    };
    let grids: f64 = pitches
        .iter()
        .map(|&p| {
            let s = spec_at(coarse, p);
            STUDY_GRID_BYTES_PER_NODE * s.nx as f64 * s.nz as f64
        })
        .sum();
    let finest = spec_at(coarse, pitches[pitches.len() - 1]);
    BASE_BYTES
        + (BYTES_PER_TRIANGLE + ORACLE_BYTES_PER_TRIANGLE) * triangles as f64
        + grids
        + approach.refinement_bytes(setup, &finest, rayon::current_num_threads())
}

/// The study `options` of `shard`'s share of the starts (the starts `s`,
/// 0-based in the study's order, with `s % N == K - 1`) on `setup`'s
/// approach: the oracle on the share alone, every pitch compared on it.
pub fn study_shard(
    input: &PartFile,
    setup: &Setup,
    options: StudyOptions,
    shard: Shard,
    progress: &dyn Progress,
) -> Result<StudyPart, HarnessError> {
    run(input, setup, options, shard, None, progress)
}

/// The whole study `options` on `setup`'s approach: the merge of its one
/// share.
pub fn study(
    input: &PartFile,
    setup: &Setup,
    options: StudyOptions,
    progress: &dyn Progress,
) -> Result<Study, HarnessError> {
    whole(input, setup, options, None, progress)
}

/// [`study`] with an optional deliberate mistake on the grid side.
pub(super) fn whole(
    input: &PartFile,
    setup: &Setup,
    options: StudyOptions,
    fault: Option<Fault>,
    progress: &dyn Progress,
) -> Result<Study, HarnessError> {
    let all = Shard { index: 1, count: 1 };
    let part = run(input, setup, options, all, fault, progress)?;
    Ok(merge(vec![part]).expect("a study's one share merges into it"))
}

fn run(
    input: &PartFile,
    setup: &Setup,
    options: StudyOptions,
    shard: Shard,
    fault: Option<Fault>,
    progress: &dyn Progress,
) -> Result<StudyPart, HarnessError> {
    options.validate()?;
    let pitches = options.pitches(setup);
    let coarse_setup = Setup {
        pitch: pitches[0],
        ..setup.clone()
    };
    coarse_setup.validate()?;
    let approach = super::studies_of(setup.approach);
    let mut method = approach.lay(input, &coarse_setup, options, fault)?;
    let coarse = method.laid().coarse;
    let converging = options.kind() == StudyKind::Converge;
    if converging {
        for &p in &pitches {
            setup.check_memory(&spec_at(&coarse, p), input.part.triangles.len())?;
        }
    }
    let held_bytes = held_bytes(
        approach,
        setup,
        input.part.triangles.len(),
        &coarse,
        &pitches,
    );
    // What every share holds is checked before the oracle is built (its
    // BVH aborted the run where it did not fit); the traces are checked
    // once a sample of them is measured.
    let held = crate::memory::MemoryEstimate {
        items: vec![("study", held_bytes)],
    };
    crate::setup::check_estimate(&held, setup.max_memory_bytes).map_err(|limit| {
        let limit = match limit {
            crate::setup::Limit::Allowed(b) | crate::setup::Limit::Machine(b, _) => b,
        };
        HarnessError::StudyMemory {
            need_gib: held_bytes / crate::setup::GIB,
            held_gib: held_bytes / crate::setup::GIB,
            limit_gib: limit / crate::setup::GIB,
            pairs: method.laid().starts.len() * setup.angles.len(),
            shards: 0,
        }
    })?;
    let tracing = Tracing {
        share: share(&method.laid().starts, shard)?,
        finest: pitches[pitches.len() - 1],
        refuse_beyond_s: options.budget_s(),
        within_s: None,
        memory: Some(MemoryLimit {
            bytes: setup.max_memory_bytes,
            pitches: pitches.len(),
            held_bytes,
        }),
    };
    let oracle_s = method.trace(tracing, progress)?;
    let mut parts = Vec::with_capacity(pitches.len());
    for &p in &pitches {
        parts.push(method.pitch(Pitch { p, converging }, progress)?);
    }
    let Laid {
        starts: all_starts,
        sample_s,
        ..
    } = method.laid().clone();
    let summary = approach.summary_as_known(ShareKnown {
        input,
        setup,
        options,
        coarse: &coarse,
        starts: all_starts.len(),
        parts: &parts,
        sample_s,
        oracle_s,
    });
    Ok(StudyPart {
        shard,
        spec: coarse,
        starts: all_starts,
        angles_deg: setup.angles.clone(),
        pitches: parts,
        settings: study_settings(
            options.selection(),
            options.tie_band_per_mm(),
            options.tolerance(),
            pitches,
        ),
        summary,
        sample_s,
        oracle_s,
    })
}

/// The study of the shares `parts`: every shard of one study exactly
/// once, in shard order (as [`crate::shard::study`] checks), each holding
/// every pair of its starts. Its pairs are put back in the unsharded order
/// and assembled, and its summary set, as for the whole study; `None` when
/// the shares are not of one study.
pub(crate) fn merge(mut parts: Vec<StudyPart>) -> Option<Study> {
    let summary = parts.first()?.summary.clone();
    super::studies_of(summary.approach).merge(summary, &mut parts)
}

/// `verify`'s study of push-and-slide: refused for the direct approach,
/// which [`study`] compares with [`StudyOptions::Verify`].
pub fn verify(
    input: &PartFile,
    setup: &Setup,
    options: &VerifyOptions,
    progress: &dyn Progress,
) -> Result<Verification, HarnessError> {
    verify_with(input, setup, options, progress, None)
}

/// [`verify`] with an optional deliberate mistake on the grid side.
pub(crate) fn verify_with(
    input: &PartFile,
    setup: &Setup,
    options: &VerifyOptions,
    progress: &dyn Progress,
    fault: Option<Fault>,
) -> Result<Verification, HarnessError> {
    if setup.approach != Approach::Slide {
        return Err(HarnessError::DirectApproach);
    }
    let study = whole(input, setup, StudyOptions::Verify(options), fault, progress)?;
    Ok(study
        .downcast::<Verification>()
        .expect("a slide verification is a Verification"))
}

/// `converge`'s study: every pitch of `options` compared on the same
/// starts (the coarsest grid's), the oracle run once at the finest pitch's
/// resolution, each grid timed over the engine's full run. Refused for the
/// direct approach, which [`study`] compares with
/// [`StudyOptions::Converge`].
pub fn converge(
    input: &PartFile,
    setup: &Setup,
    options: &ConvergeOptions,
    progress: &dyn Progress,
) -> Result<Convergence, HarnessError> {
    if setup.approach != Approach::Slide {
        return Err(HarnessError::DirectApproach);
    }
    let study = study(input, setup, StudyOptions::Converge(options), progress)?;
    Ok(study
        .downcast::<Convergence>()
        .expect("a slide convergence study is a Convergence"))
}
