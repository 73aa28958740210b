//! One study path for both studies and both approaches: `verify` (one
//! pitch) and `converge` (a ladder of pitches), push-and-slide or the
//! direct approach, whole or one shard's share of the starts.
//!
//! Every study runs as [`study_shard`]: it lays the coarsest grid and
//! chooses the study's starts on it, takes the exact side of the share's
//! starts, and compares every pitch's grid with it ([`Method`]); the
//! result is a [`StudyPart`]. The whole study ([`study`]) is the merge
//! ([`merge`]) of its one share, shard 1/1, so the unsharded command and a
//! merge of N shards compute every statistic in one place.
//!
//! What differs per approach is its [`Method`] (declared in the leaf
//! `method`, so that this module alone calls down into the approaches):
//! [`super::converge::Ladder`] for push-and-slide,
//! [`super::direct::DirectMethod`] for the direct approach. What differs
//! per study is its options ([`StudyOptions`]) and its summary; the four
//! summaries (`verify.json` and `converge.json` of each approach) are made
//! and set in [`summary_as_known`] and [`merge`].

use super::HarnessError;
use super::converge::{ConvergeOptions, ConvergeSummary, Convergence, PitchResult};
use super::direct::{
    DirectConvergeSummary, DirectConvergence, DirectMethod, DirectPitchResult, DirectVerification,
    DirectVerifySummary, assemble_direct,
};
use super::method::{Laid, MemoryLimit, Method, Pitch, Tracing, spec_at};
use super::pairs::{Pairs, PitchPart, share};
use super::sharded::{
    MergedClocks, StudyPart, StudySummary, merged_clocks, oracle_s, study_settings, unsharded_pairs,
};
use super::trace::Fault;
use super::verify::{Verification, VerifyOptions, VerifySummary};
use crate::analysis::Progress;
use crate::frame::Approach;
use crate::grid::GridSpec;
use crate::input::PartFile;
use crate::partition::Shard;
use crate::setup::Setup;

/// Which study, with its options.
#[derive(Debug, Clone, Copy)]
pub enum StudyOptions<'a> {
    /// `verify`: one pitch, the setup's.
    Verify(&'a VerifyOptions),
    /// `converge`: a ladder of pitches.
    Converge(&'a ConvergeOptions),
}

impl StudyOptions<'_> {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), HarnessError> {
        match self {
            StudyOptions::Verify(o) => o.validate(),
            StudyOptions::Converge(o) => o.validate(),
        }
    }

    /// The pitches, coarsest first (mm): verify's one (the setup's),
    /// converge's ladder.
    fn pitches(&self, setup: &Setup) -> Vec<f64> {
        match self {
            StudyOptions::Verify(_) => vec![setup.pitch],
            StudyOptions::Converge(o) => o.pitches.clone(),
        }
    }

    /// The longest the oracle may take (s): beyond it, refused.
    pub fn budget_s(&self) -> Option<f64> {
        match self {
            StudyOptions::Verify(o) => o.budget_s,
            StudyOptions::Converge(o) => o.budget_s,
        }
    }

    fn selection(&self) -> &super::StartSelection {
        match self {
            StudyOptions::Verify(o) => &o.selection,
            StudyOptions::Converge(o) => &o.selection,
        }
    }

    fn tie_band_per_mm(&self) -> f64 {
        match self {
            StudyOptions::Verify(o) => o.tie_band_per_mm,
            StudyOptions::Converge(o) => o.tie_band_per_mm,
        }
    }

    fn tolerance(&self) -> Option<f64> {
        match self {
            StudyOptions::Verify(o) => Some(o.tolerance),
            StudyOptions::Converge(o) => o.tolerance,
        }
    }
}

/// A study's result: what its files hold, for either study and approach.
#[derive(Debug, Clone)]
pub enum Study {
    /// `verify`'s.
    Verify(Box<Verification>),
    /// `converge`'s.
    Converge(Box<Convergence>),
    /// `verify --approach direct`'s.
    VerifyDirect(Box<DirectVerification>),
    /// `converge --approach direct`'s.
    ConvergeDirect(Box<DirectConvergence>),
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
    let selection = options.selection();
    let mut method: Box<dyn Method + '_> = match setup.approach {
        Approach::Slide => Box::new(super::converge::Ladder::lay(
            input,
            &coarse_setup,
            selection,
            options.tie_band_per_mm(),
            fault,
        )?),
        Approach::Direct => Box::new(DirectMethod::lay(input, &coarse_setup, selection)?),
    };
    let coarse = method.laid().coarse;
    let converging = matches!(options, StudyOptions::Converge(_));
    if converging {
        for &p in &pitches {
            setup.check_memory(&spec_at(&coarse, p), input.part.triangles.len())?;
        }
    }
    let tracing = Tracing {
        share: share(&method.laid().starts, shard)?,
        finest: pitches[pitches.len() - 1],
        refuse_beyond_s: options.budget_s(),
        within_s: None,
        memory: Some(MemoryLimit {
            bytes: setup.max_memory_bytes,
            pitches: pitches.len(),
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
    let summary = summary_as_known(
        input,
        setup,
        options,
        &coarse,
        all_starts.len(),
        &parts,
        sample_s,
        oracle_s,
    );
    Ok(StudyPart {
        shard,
        spec: coarse,
        starts: all_starts,
        angles_deg: setup.angles.clone(),
        pitches: parts,
        settings: study_settings(
            selection,
            options.tie_band_per_mm(),
            options.tolerance(),
            pitches,
        ),
        summary,
        sample_s,
        oracle_s,
    })
}

/// The study's summary as a share knows it: the part's identity, every
/// setting and the share's own seconds, with the statistics of no start
/// ([`merge`] sets them from every share's pairs; a share's own could be
/// infinite, which JSON cannot say).
#[allow(clippy::too_many_arguments)]
fn summary_as_known(
    input: &PartFile,
    setup: &Setup,
    options: StudyOptions,
    coarse: &GridSpec,
    starts: usize,
    parts: &[PitchPart],
    sample_s: f64,
    oracle_s: f64,
) -> StudySummary {
    let grid_s = parts.first().map_or(0.0, |p| p.grid_s);
    match (options, setup.approach) {
        (StudyOptions::Verify(o), Approach::Slide) => {
            let band = parts[0].band;
            let none = super::compare::assemble(Vec::new(), &setup.angles, band, 0.0);
            let mut s = VerifySummary::new(input, setup, o, coarse, &none, sample_s, oracle_s);
            s.timings.grid_s = grid_s;
            StudySummary::Verify(Box::new(s))
        }
        (StudyOptions::Converge(o), Approach::Slide) => {
            StudySummary::Converge(ConvergeSummary::new(input, setup, o, starts, &[]))
        }
        (StudyOptions::Verify(o), Approach::Direct) => {
            let mut s = DirectVerifySummary::new(input, setup, o);
            s.grid_s = grid_s;
            s.oracle_s = oracle_s;
            StudySummary::VerifyDirect(s)
        }
        (StudyOptions::Converge(o), Approach::Direct) => StudySummary::ConvergeDirect(
            DirectConvergeSummary::new(input, setup, o, starts, oracle_s),
        ),
    }
}

/// The study of the shares `parts`: every shard of one study exactly
/// once, in shard order (as [`crate::shard::study`] checks), each holding
/// every pair of its starts. Its pairs are put back in the unsharded order
/// and assembled, and its summary set, as for the whole study; `None` when
/// the shares are not of one study.
pub(crate) fn merge(mut parts: Vec<StudyPart>) -> Option<Study> {
    let first = parts.first()?;
    let summary = first.summary.clone();
    let (angles, spec) = (first.angles_deg.clone(), first.spec);
    let oracle_s = oracle_s(&parts);
    let sample_s = parts.iter().map(|p| p.sample_s).fold(0.0, f64::max);
    let slide = |parts: &mut [StudyPart]| {
        merged_pitches(parts, Pairs::slide_mut, |clocks, pairs| PitchResult {
            pitch: clocks.pitch,
            comparison: super::compare::assemble(pairs, &angles, clocks.band, clocks.grid_s),
            seconds: clocks.seconds,
            nodes: clocks.nodes,
        })
    };
    let direct = |parts: &mut [StudyPart]| {
        merged_pitches(parts, Pairs::direct_mut, |clocks, pairs| {
            DirectPitchResult {
                pitch: clocks.pitch,
                comparison: assemble_direct(pairs, clocks.grid_s),
                nodes: clocks.nodes,
            }
        })
    };
    Some(match summary {
        StudySummary::Verify(mut summary) => {
            let result = only(slide(&mut parts)?)?;
            summary.set_comparison(&result.comparison, &spec);
            summary.timings.sample_s = sample_s;
            summary.timings.oracle_s = oracle_s;
            Study::Verify(Box::new(Verification {
                comparison: result.comparison,
                summary: *summary,
            }))
        }
        StudySummary::Converge(mut summary) => {
            let results = slide(&mut parts)?;
            summary.set_results(&results);
            Study::Converge(Box::new(Convergence {
                fits: super::converge::fits(&results),
                results,
                summary,
                oracle_s,
            }))
        }
        StudySummary::VerifyDirect(mut summary) => {
            let result = only(direct(&mut parts)?)?;
            summary.set_comparison(&result.comparison, oracle_s);
            Study::VerifyDirect(Box::new(DirectVerification {
                comparison: result.comparison,
                summary,
            }))
        }
        StudySummary::ConvergeDirect(mut summary) => {
            let results = direct(&mut parts)?;
            summary.oracle_s = oracle_s;
            summary.set_results(&results);
            Study::ConvergeDirect(Box::new(DirectConvergence { results, summary }))
        }
    })
}

/// Every pitch of the shares `parts`, its pairs (those `pick` takes:
/// `None` for the other approach's, which makes the merge `None`) moved
/// back in the unsharded order and made a pitch's result by `result`.
fn merged_pitches<T, R>(
    parts: &mut [StudyPart],
    pick: fn(&mut Pairs) -> Option<&mut Vec<T>>,
    result: impl Fn(MergedClocks, Vec<T>) -> R,
) -> Option<Vec<R>> {
    (0..parts.first()?.pitches.len())
        .map(|k| {
            let clocks = merged_clocks(parts, k);
            Some(result(clocks, unsharded_pairs(parts, k, pick)?))
        })
        .collect()
}

/// The one pitch of a verification (`None` for more or none).
fn only<T>(mut results: Vec<T>) -> Option<T> {
    results.pop().filter(|_| results.is_empty())
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
    if setup.approach == Approach::Direct {
        return Err(HarnessError::DirectApproach);
    }
    match whole(input, setup, StudyOptions::Verify(options), fault, progress)? {
        Study::Verify(v) => Ok(*v),
        _ => unreachable!("a slide verification is a Study::Verify"),
    }
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
    if setup.approach == Approach::Direct {
        return Err(HarnessError::DirectApproach);
    }
    match study(input, setup, StudyOptions::Converge(options), progress)? {
        Study::Converge(c) => Ok(*c),
        _ => unreachable!("a slide convergence study is a Study::Converge"),
    }
}
