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
pub(crate) mod method;
pub(crate) mod metrics;
pub(crate) mod nearest;
pub(crate) mod pairs;
pub(crate) mod sharded;
pub(crate) mod slide;
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
pub use metrics::{DECIDED_METRICS, METRICS, TieBand};
pub use sharded::{StudyKind, StudyPart};
pub use study::{converge, study, study_shard, verify};

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
pub use verify::{Verification, VerifyOptions, oracle_options, sampling_tolerance};

use serde::{Deserialize, Serialize};

use crate::grid::GridError;
use crate::input::PartFile;
use crate::setup::SetupError;

/// Which part, read how, by which kneeform: the record that opens every
/// study's JSON (`verify.json`, `converge.json`, both approaches'),
/// flattened into it, so the files read as they always did. `kneeform
/// report` matches a study to its run by it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunIdentity {
    /// Version of kneeform.
    pub kneeform_version: String,
    /// The part (STL or scenario file) as given.
    pub input_file: String,
    /// SHA-256 of the part file's bytes (hex), as `summary.json`'s
    /// `sha256`.
    #[serde(default)]
    pub input_sha256: String,
    /// Factor from the file's units to mm.
    #[serde(default = "verify::unit_scale")]
    pub scale: f64,
    /// `left` or `right`.
    #[serde(default = "verify::left_side")]
    pub side: crate::Side,
    /// `--frame`: the map from the part's coordinates into vehicle
    /// coordinates; absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<crate::frame::FrameRecord>,
}

impl RunIdentity {
    /// The identity of a study of `input` by this build.
    pub fn of(input: &PartFile) -> RunIdentity {
        RunIdentity {
            kneeform_version: env!("CARGO_PKG_VERSION").into(),
            input_file: input.path.display().to_string(),
            input_sha256: input.sha256.clone(),
            scale: input.scale,
            side: input.side,
            frame: input.frame.record(),
        }
    }
}

/// Why a verification or convergence study could not run. (A failed
/// oracle query on one start is no error: it is counted and fails the
/// comparison.)
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    /// The setup is invalid.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The grid cannot be laid.
    #[error(transparent)]
    Grid(#[from] GridError),
    /// The oracle refused the part or its options.
    #[error(transparent)]
    Oracle(#[from] kneeform_oracle::OracleError),
    /// The setup asks for the direct approach of a call that compares
    /// push-and-slide: [`study()`] compares either approach; `--pitch
    /// auto` has none for the direct approach.
    #[error(
        "this compares push-and-slide with the exact oracle: the direct approach is compared by harness::study (kneeform verify/converge --approach direct), and --pitch auto does not choose its pitch yet"
    )]
    DirectApproach,
    /// No start is placed on the part.
    #[error("no start is placed on this part: nothing to compare")]
    NoStarts,
    /// The strip or the runs asked for hold no start.
    #[error("{0}: nothing to compare")]
    NoneChosen(String),
    /// A start given is not a node of the grid compared.
    #[error("start ({}, {}) mm is not a node of the {} mm grid: the pitches must nest", crate::limits::short(*x), crate::limits::short(*z), crate::limits::short(*pitch))]
    StartNotANode {
        /// The start's x (mm).
        x: f64,
        /// The start's z (mm).
        z: f64,
        /// The grid's pitch (mm).
        pitch: f64,
    },
    /// The traces are not one per start and angle.
    #[error("{traces} exact traces for {expected} start-angle pairs")]
    TraceCount {
        /// Traces given.
        traces: usize,
        /// Starts times angles.
        expected: usize,
    },
    /// The tolerance is not a finite positive length.
    #[error("the tolerance must be a finite number of mm > 0, got {0}")]
    Tolerance(f64),
    /// The tie band's growth is not a finite number >= 0.
    #[error("the tie band's growth must be a finite number >= 0 (per mm), got {0}")]
    TieBand(f64),
    /// The pitch ladder of a convergence study is unusable.
    #[error("{0}")]
    Pitches(String),
    /// A start sample of no start.
    #[error("a start sample must hold at least one start")]
    EmptySample,
    /// Runs of starts longer than a chain block, or empty.
    #[error("a run of starts must hold 1 to {max} starts (one chain block), got {length}")]
    RunLength {
        /// The run's length asked for.
        length: usize,
        /// The longest run.
        max: usize,
    },
    /// The time budget is not a finite positive number of seconds.
    #[error("the time budget must be a finite number of seconds > 0, got {0}")]
    Budget(f64),
    /// The pitch a tolerance needs exceeds the time budget or memory.
    #[error(
        "a tolerance of {tolerance} mm needs a pitch of {pitch} mm or finer: about {predicted_s:.0} s and {memory_gib:.1} GiB for the analysis, beyond the budget of {budget_s} s or the {max_memory_gib:.1} GiB allowed (raise --budget-s or --max-memory, or accept a larger --tolerance); decided area distance to the exact knee-form at the pitches studied: {studied}"
    )]
    PitchBudget {
        /// The tolerance (mm).
        tolerance: f64,
        /// The pitch it would need next (mm).
        pitch: f64,
        /// The predicted analysis time there (s).
        predicted_s: f64,
        /// The memory estimate there (GiB).
        memory_gib: f64,
        /// The budget (s).
        budget_s: f64,
        /// The memory limit (GiB).
        max_memory_gib: f64,
        /// The study so far, in words.
        studied: String,
    },
    /// The pitch study itself ran past the time budget.
    #[error(
        "the pitch study for a tolerance of {tolerance} mm took {spent_s:.1} s{next}, beyond --budget-s {budget_s} (raise it, or accept a larger --tolerance); decided area distance to the exact knee-form at the pitches studied: {studied}"
    )]
    StudyBudget {
        /// The tolerance (mm).
        tolerance: f64,
        /// Seconds spent.
        spent_s: f64,
        /// What the next step would add, in words (or nothing).
        next: String,
        /// The budget (s).
        budget_s: f64,
        /// The study so far, in words.
        studied: String,
    },
    /// A verification's exact traces would take longer than its budget.
    #[error(
        "the exact oracle would take about {predicted_s:.0} s for {pairs} start-angle pairs (predicted from a sample), beyond --budget-s {budget_s}: fan it out with --shard K/{shards} (K = 1..{shards}, then `kneeform merge`), or trace fewer starts (--starts)"
    )]
    VerifyBudget {
        /// The predicted oracle time (s).
        predicted_s: f64,
        /// Start-angle pairs to trace.
        pairs: usize,
        /// The budget (s).
        budget_s: f64,
        /// Shards that would each fit the budget.
        shards: usize,
    },
    /// A study's exact traces and comparisons would not fit in memory.
    #[error(
        "the exact traces and their comparison would hold about {need_gib:.1} GiB for {pairs} start-angle pairs (predicted from a sample), beyond the {limit_gib:.1} GiB allowed (--max-memory, or this machine's memory): fan it out with --shard K/{shards} (K = 1..{shards}, then `kneeform merge`), or compare fewer angles or starts"
    )]
    StudyMemory {
        /// The predicted memory (GiB).
        need_gib: f64,
        /// The memory allowed (GiB).
        limit_gib: f64,
        /// Start-angle pairs to trace.
        pairs: usize,
        /// Shards that would each fit.
        shards: usize,
    },
    /// The exact traces of a pitch study would take longer than its
    /// budget.
    #[error(
        "the pitch study's exact traces ({pairs} start-angle pairs) would take about {predicted_s:.0} s at the rate they ran, beyond --budget-s {budget_s} (raise it, or accept a larger --tolerance: a coarser finest pitch makes the oracle's casts cheaper)"
    )]
    OracleBudget {
        /// The predicted oracle time (s).
        predicted_s: f64,
        /// Start-angle pairs to trace.
        pairs: usize,
        /// The budget (s).
        budget_s: f64,
    },
    /// A tolerance finer than the study's finest pitch can show.
    #[error(
        "a tolerance of {tolerance} mm is beyond what --pitch auto can show: its finest pitch is {finest} mm, and the grid's error is of the order of the pitch (accept a tolerance of {finest} mm or more)"
    )]
    ToleranceTooFine {
        /// The tolerance (mm).
        tolerance: f64,
        /// The finest pitch the study would try (mm).
        finest: f64,
    },
    /// No pitch of the study meets the tolerance.
    #[error(
        "no pitch down to {finest} mm meets a tolerance of {tolerance} mm: decided area distance to the exact knee-form {studied} (results/README.md says what does not converge)"
    )]
    PitchNotFound {
        /// The tolerance (mm).
        tolerance: f64,
        /// The finest pitch studied (mm).
        finest: f64,
        /// The study, in words.
        studied: String,
    },
    /// More shards than starts: some shard would have nothing to compare.
    #[error("{shards} shards of {starts} starts: at most one shard per start")]
    TooManyShards {
        /// N.
        shards: usize,
        /// The study's starts.
        starts: usize,
    },
    /// A strip of start rows whose bounds are not finite and ordered.
    #[error("a strip of starts needs finite z bounds Z0 <= Z1 (mm), got {0:?}")]
    Strip([f64; 2]),
}

/// `work` reported to `progress` as one stage, `what` with `total` steps
/// (a spinner when `None`): the stage ends however `work` returns.
pub(crate) fn in_stage<T>(
    progress: &dyn crate::Progress,
    what: &str,
    total: Option<u64>,
    work: impl FnOnce() -> T,
) -> T {
    progress.begin(what, total);
    let done = work();
    progress.end();
    done
}

/// The stage in which a study's grid slides are compared with the exact
/// traces of `pairs` start-angle pairs: minutes on a large part.
pub(crate) fn comparing(pairs: usize) -> String {
    format!("grid against exact: {pairs} start-angle pairs")
}
