//! A study fanned out over its starts: `verify --shard K/N` and
//! `converge --shard K/N` (either approach) compare only the starts `s`
//! (0-based, in the study's order, after sampling) with `s % N == K - 1`,
//! since the exact oracle of each start and angle is the expensive part
//! ([`super::study::study_shard`]); [`super::study::merge`] puts the N
//! shares back together into the study the unsharded command computes.
//!
//! A share ([`StudyPart`]) keeps every start-angle pair it compared as a
//! [`super::compare::PairResult`] (the direct approach's position-angle
//! pairs as a [`super::pairs::DirectPair`]): a comparison's statistics,
//! counts, area distances and worst starts are computed from those alone,
//! so a merge that puts the pairs back in the unsharded order computes them
//! exactly as the unsharded run does. The file format of a share is
//! [`crate::shard::study`]'s.
//!
//! **Invariant:** a merged comparison is assembled from the pairs in the
//! unsharded run's order (angle-major, then the study's start order), and
//! the unsharded run is itself the merge of its one share, shard 1/1;
//! only clock readings differ.

use super::compare::StartSelection;
use super::converge::ConvergeSummary;
use super::direct::{DirectConvergeSummary, DirectVerifySummary};
use super::metrics::TieBand;
use super::pairs::{Pairs, PitchPart};
use super::verify::VerifySummary;
use crate::grid::GridSpec;
use crate::partition::Shard;

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

/// The pairs of pitch `k` of `parts` (every shard of one study exactly
/// once, in shard order: `parts[K - 1]` is shard K's), moved out of them
/// in the unsharded order: angle-major, then the study's start order.
/// `pick` gives a share's pairs of the study's kind (`None` for another
/// kind, which makes the merge `None`; so does a share short of pairs).
pub(super) fn unsharded_pairs<T>(
    parts: &mut [StudyPart],
    k: usize,
    pick: impl Fn(&mut Pairs) -> Option<&mut Vec<T>>,
) -> Option<Vec<T>> {
    let (n, total) = (parts.len(), parts.first()?.starts.len());
    let angles = parts[0].angles_deg.len();
    let mut shares = parts
        .iter_mut()
        .map(|p| Some(std::mem::take(pick(&mut p.pitches.get_mut(k)?.pairs)?).into_iter()))
        .collect::<Option<Vec<_>>>()?;
    let whole = |p: &StudyPart, share: &std::vec::IntoIter<T>| {
        share.len() == p.shard.indices(total).len() * angles
    };
    if !parts.iter().zip(&shares).all(|(p, s)| whole(p, s)) {
        return None;
    }
    // Each share holds its starts in the study's order, angle-major: start
    // s of the study is the next pair of share s % N.
    let mut out = Vec::with_capacity(total * angles);
    for _ in 0..angles {
        for s in 0..total {
            out.push(shares[s % n].next()?);
        }
    }
    Some(out)
}

/// What a merged pitch `k` says besides its pairs: the first share's
/// pitch, tie band and node count, the grid seconds summed over the
/// shards, the engine's seconds (which every shard measures alike) their
/// longest.
pub(super) struct MergedClocks {
    pub pitch: f64,
    pub band: TieBand,
    pub nodes: usize,
    pub grid_s: f64,
    pub seconds: f64,
}

/// [`MergedClocks`] of pitch `k` of the shares `parts`.
pub(super) fn merged_clocks(parts: &[StudyPart], k: usize) -> MergedClocks {
    let first = &parts[0].pitches[k];
    MergedClocks {
        pitch: first.pitch,
        band: first.band,
        nodes: first.nodes,
        grid_s: parts.iter().map(|p| p.pitches[k].grid_s).sum(),
        seconds: parts
            .iter()
            .map(|p| p.pitches[k].seconds)
            .fold(0.0, f64::max),
    }
}

/// The oracle's seconds summed over the shards.
pub(super) fn oracle_s(parts: &[StudyPart]) -> f64 {
    parts.iter().map(|p| p.oracle_s).sum()
}
