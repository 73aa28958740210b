//! A study fanned out over its starts: `verify --shard K/N` and
//! `converge --shard K/N` (either approach) compare only the starts `s`
//! (0-based, in the study's order, after sampling) with `s % N == K - 1`,
//! since the exact oracle of each start and angle is the expensive part
//! ([`super::study::study_shard`]); [`super::study::merge`] puts the N
//! shares back together into the study the unsharded command computes.
//!
//! A share ([`StudyPart`]) keeps every start-angle pair it compared as its
//! approach's [`super::pairs::Pair`] (push-and-slide's
//! [`super::compare::PairResult`], the direct approach's position-angle
//! [`super::direct::DirectPair`]): a comparison's statistics,
//! counts, area distances and worst starts are computed from those alone,
//! so a merge that puts the pairs back in the unsharded order computes them
//! exactly as the unsharded run does. The file format of a share is
//! [`crate::shard::study`]'s.
//!
//! **Invariant:** a merged comparison is assembled from the pairs in the
//! unsharded run's order (angle-major, then the study's start order), and
//! the unsharded run is itself the merge of its one share, shard 1/1;
//! only clock readings differ.

use std::any::Any;

use super::compare::StartSelection;
use super::metrics::TieBand;
use super::pairs::{Pair, PitchPart};
use crate::frame::Approach;
use crate::grid::GridSpec;
use crate::partition::Shard;

/// Which study: `verify` (one pitch) or `converge` (a ladder).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StudyKind {
    /// `verify`.
    Verify,
    /// `converge`.
    Converge,
}

/// A study's summary (`verify.json`, `converge.json`) as its approach
/// types it: what the one study path, the shards and the merge hold
/// without naming it.
pub(crate) trait KnownSummary: Any + std::fmt::Debug + Send + Sync + SummaryRecord {
    /// The study's angles (degrees) and pitches, coarsest first (mm), as
    /// the summary records them.
    fn angles_and_pitches(&self) -> (&[f64], Vec<f64>);
}

/// What every [`KnownSummary`] is as a record: written, read and copied
/// as its type says (one implementation for all).
pub(crate) trait SummaryRecord {
    /// The summary as its file holds it.
    fn to_json(&self) -> serde_json::Value;
    /// A copy.
    fn boxed_clone(&self) -> Box<dyn KnownSummary>;
}

impl<T: KnownSummary + serde::Serialize + Clone> SummaryRecord for T {
    fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or_default()
    }

    fn boxed_clone(&self) -> Box<dyn KnownSummary> {
        Box::new(self.clone())
    }
}

/// The summary `T` read from its JSON (a shard's).
pub(crate) fn read_summary<T: KnownSummary + serde::de::DeserializeOwned>(
    json: serde_json::Value,
) -> Result<Box<dyn KnownSummary>, String> {
    let summary: T = serde_json::from_value(json).map_err(|e| e.to_string())?;
    Ok(Box::new(summary))
}

/// A shard's summary: `verify.json` or `converge.json` as the shard knows
/// it: the part's identity, every setting and the shard's own timings,
/// with the statistics of no start (the merge computes them from every
/// shard's pairs; `shard.json` leaves them out). `shard.json` holds it as
/// `{"kind": ..., "summary": ...}`, the kind its approach's word for the
/// study (`verify`, `converge`, `verify-direct`, `converge-direct`).
#[derive(Debug)]
pub struct StudySummary {
    /// Whose study.
    pub(crate) approach: Approach,
    /// Which study.
    pub(crate) kind: StudyKind,
    /// The approach's word for the study in `shard.json`'s `kind`.
    pub(crate) word: &'static str,
    /// The summary, as the approach types it.
    pub(crate) known: Box<dyn KnownSummary>,
}

impl StudySummary {
    /// `known`, the summary of `approach`'s study `kind`, which
    /// `shard.json` names `word`.
    pub(crate) fn new(
        (approach, kind, word): (Approach, StudyKind, &'static str),
        known: impl KnownSummary,
    ) -> Self {
        StudySummary {
            approach,
            kind,
            word,
            known: Box::new(known),
        }
    }

    /// The summary, when it is a `T` (`None` for another's).
    pub(crate) fn take<T: KnownSummary>(self) -> Option<T> {
        (self.known as Box<dyn Any>)
            .downcast::<T>()
            .ok()
            .map(|t| *t)
    }
}

impl Clone for StudySummary {
    fn clone(&self) -> StudySummary {
        StudySummary {
            known: self.known.boxed_clone(),
            ..*self
        }
    }
}

impl PartialEq for StudySummary {
    fn eq(&self, other: &StudySummary) -> bool {
        (self.approach, self.kind) == (other.approach, other.kind)
            && self.known.to_json() == other.known.to_json()
    }
}

impl serde::Serialize for StudySummary {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut record = s.serialize_struct("StudySummary", 2)?;
        record.serialize_field("kind", self.word)?;
        record.serialize_field("summary", &self.known.to_json())?;
        record.end()
    }
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
/// `None` when a share's pairs are not `T`s (another approach's) or it is
/// short of pairs.
pub(crate) fn unsharded_pairs<T: Pair>(parts: &mut [StudyPart], k: usize) -> Option<Vec<T>> {
    let (n, total) = (parts.len(), parts.first()?.starts.len());
    let angles = parts[0].angles_deg.len();
    let mut shares = parts
        .iter_mut()
        .map(|p| Some(p.pitches.get_mut(k)?.pairs.take::<T>()?.into_iter()))
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
pub(crate) struct MergedClocks {
    pub pitch: f64,
    pub band: TieBand,
    pub nodes: usize,
    pub grid_s: f64,
    pub seconds: f64,
    /// Per angle, the union of the shards' covering nodes
    /// ([`super::pairs::PitchPart::covering`]), sorted.
    pub covering: Vec<Vec<[f64; 2]>>,
}

/// [`MergedClocks`] of pitch `k` of the shares `parts`.
pub(crate) fn merged_clocks(parts: &[StudyPart], k: usize) -> MergedClocks {
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
        covering: merged_covering(parts.iter().map(|p| &p.pitches[k].covering)),
    }
}

/// The union, per angle, of the shares' covering nodes, sorted: the same
/// points whatever the shards (the nearest node of each exact strike is
/// the same in every share).
fn merged_covering<'a>(shares: impl Iterator<Item = &'a Vec<Vec<[f64; 2]>>>) -> Vec<Vec<[f64; 2]>> {
    let mut merged: Vec<Vec<[f64; 2]>> = Vec::new();
    for share in shares {
        if merged.len() < share.len() {
            merged.resize(share.len(), Vec::new());
        }
        for (to, from) in merged.iter_mut().zip(share) {
            to.extend(from);
        }
    }
    for points in &mut merged {
        points.sort_by(|a, b| a[1].total_cmp(&b[1]).then(a[0].total_cmp(&b[0])));
        points
            .dedup_by(|a, b| a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits());
    }
    merged
}

/// The oracle's seconds summed over the shards.
pub(crate) fn oracle_s(parts: &[StudyPart]) -> f64 {
    parts.iter().map(|p| p.oracle_s).sum()
}

/// Every pitch of the shares `parts`, its pairs (`T`s: `None` for another
/// approach's, which makes the merge `None`) moved back in the unsharded
/// order and made a pitch's result by `result`.
pub(crate) fn merged_pitches<T: Pair, R>(
    parts: &mut [StudyPart],
    result: impl Fn(MergedClocks, Vec<T>) -> R,
) -> Option<Vec<R>> {
    (0..parts.first()?.pitches.len())
        .map(|k| {
            let clocks = merged_clocks(parts, k);
            Some(result(clocks, unsharded_pairs(parts, k)?))
        })
        .collect()
}

/// The one pitch of a verification (`None` for more or none).
pub(crate) fn only<T>(mut results: Vec<T>) -> Option<T> {
    results.pop().filter(|_| results.is_empty())
}
