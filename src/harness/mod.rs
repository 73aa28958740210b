//! The verification harness: the grid engine against the exact oracle on
//! the same starts (SPEC, "What the harness measures"), and convergence
//! over the pitch.
//!
//! * [`verify()`]: one pitch, a part's starts compared with the oracle
//!   ([`Verification`]: the per-start rows, the metrics, `verify.json`'s
//!   summary);
//! * [`check_analysis`]: the sample check every analysis carries (the
//!   oracle on a few of its own starts);
//! * [`converge()`]: the same starts at several pitches, the fitted order
//!   of convergence and the pitch to choose ([`Convergence`]);
//! * `compare`: start selection, the oracle's traces, one grid's
//!   comparison;
//! * `trace`: the grid's push and slide of one start, with the travel of
//!   each colliding node;
//! * `causes`: why a figure fails (blind spots touched, the grid's
//!   level error, undecided contacts, oracle failures);
//! * `metrics`: push, first-contact, miss and false-alarm errors, the
//!   tie band, the area distance;
//! * `nearest`: a 2-d tree for the area distance's nearest points;
//! * `pairs`: what a study compares per start and angle, and per pitch,
//!   for either approach, and a shard's share of the starts;
//! * `approach`: what a study does its own way per approach (the
//!   `StudyApproach` trait: its steps, a `method::Method`, its summaries,
//!   its pairs in a shard's file, its merge, its files and words), which
//!   `slide` (push-and-slide) and `direct` implement;
//! * `codec`: the bits of a shard's `shard.bin`;
//! * `study`: the one path every study takes, verify or converge, either
//!   approach, whole or one shard's share ([`study()`], [`study_shard`]),
//!   and the merge of shares;
//! * `sharded`: what a shard keeps of its share (`verify --shard K/N`,
//!   either approach) and how the shares' pairs go back in order.
//!
//! **Invariant:** the harness reads the engine's grid and the oracle's
//! traces and computes neither side's geometry, with one exception stated
//! here: `trace` re-runs SPEC's push and slide of one start on the
//! engine's grid, because the engine's fast path keeps no per-start
//! travel (it keeps each node's reach). It is a direct transcription of
//! SPEC, tested equal to the engine's masks on every start.

pub(crate) mod approach;
pub(crate) mod auto;
pub(crate) mod causes;
pub(crate) mod check;
pub(crate) mod codec;
pub(crate) mod compare;
pub(crate) mod converge;
pub(crate) mod direct;
pub(crate) mod error;
pub(crate) mod identity;
pub(crate) mod method;
pub(crate) mod metrics;
pub(crate) mod nearest;
pub(crate) mod pairs;
pub(crate) mod sharded;
pub(crate) mod slide;
pub(crate) mod stage;
pub(crate) mod study;
pub(crate) mod trace;
pub(crate) mod verify;

#[cfg(test)]
mod fault_tests;

pub use approach::{Said, Study, StudyOptions};
pub use auto::{AutoPitch, choose_pitch};
pub use causes::Mechanism;
pub use check::check_analysis;
pub use compare::{Comparison, StartSelection};
pub use converge::{ConvergeOptions, Convergence, ROUNDING_MM, fit_power_law};
pub use direct::{DIRECT_METRICS, DirectConvergence, DirectVerification};
pub use error::HarnessError;
pub use identity::RunIdentity;
pub use metrics::{DECIDED_METRICS, METRICS, TieBand};
use sharded::StudyKind;
pub use sharded::StudyPart;
pub use study::{converge, study, study_shard, verify};

pub use verify::{Verification, VerifyOptions, oracle_options, sampling_tolerance};

/// Each approach's studies ([`approach::StudyApproach`]): the one place
/// that names them. A new approach is its variant of
/// [`crate::Approach`], its own module, and its line here.
pub(crate) fn studies_of(approach: crate::Approach) -> &'static dyn approach::StudyApproach {
    match approach {
        crate::Approach::Slide => &slide::Slide,
        crate::Approach::Direct => &direct::Direct,
    }
}

/// The approach and study whose shards `shard.json` names `word`.
pub(crate) fn study_named(word: &str) -> Option<(crate::Approach, StudyKind)> {
    crate::Approach::ALL.into_iter().find_map(|a| {
        [StudyKind::Verify, StudyKind::Converge]
            .into_iter()
            .find(|&k| studies_of(a).kind_word(k) == word)
            .map(|k| (a, k))
    })
}
