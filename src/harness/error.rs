//! Why a study could not run ([`HarnessError`]): the error of every part
//! of the harness, in a leaf of its own.

use crate::grid::GridError;
use crate::setup::SetupError;

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
    /// push-and-slide: [`super::study()`] compares either approach; `--pitch
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
    /// A study would not fit in memory.
    #[error(
        "the study would hold about {need_gib:.1} GiB ({held_gib:.1} GiB whatever its starts: the part and the oracle's copy of it, the grids and the finer grids that refine a miss; the rest the exact traces and their comparison for {pairs} start-angle pairs, predicted from a sample), beyond the {limit_gib:.1} GiB allowed (--max-memory, or this machine's memory): {}",
        fan_out_words(*shards)
    )]
    StudyMemory {
        /// The predicted memory (GiB).
        need_gib: f64,
        /// Of it, what every shard holds whatever its starts (GiB).
        held_gib: f64,
        /// The memory allowed (GiB).
        limit_gib: f64,
        /// Start-angle pairs to trace.
        pairs: usize,
        /// Shards that would each fit; 0 where none would (what every
        /// shard holds is beyond the limit).
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
        "no pitch down to {finest} mm meets a tolerance of {tolerance} mm: decided area miss distance to the exact knee-form {studied} (results/README.md says what does not converge)"
    )]
    PitchNotFound {
        /// The tolerance (mm).
        tolerance: f64,
        /// The finest pitch studied (mm).
        finest: f64,
        /// The study, in words.
        studied: String,
    },
    /// A pitch study's evidence cannot support a claim at some pitch.
    #[error(
        "the pitch study is INCONCLUSIVE at {pitch} mm for a tolerance of {tolerance} mm: {why}; no pitch is chosen (give one with --pitch, and `kneeform verify` it)"
    )]
    Inconclusive {
        /// The tolerance (mm).
        tolerance: f64,
        /// The pitch at which it was inconclusive (mm).
        pitch: f64,
        /// Why, in words.
        why: String,
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

/// What to do about a study beyond its memory that `shards` shards would
/// each fit (0: none would).
fn fan_out_words(shards: usize) -> String {
    if shards == 0 {
        "sharding does not help, since every shard holds the grids: use a coarser --pitch or a smaller --grid-size, or allow more with --max-memory".into()
    } else {
        format!(
            "fan it out with --shard K/{shards} (K = 1..{shards}, then `kneeform merge`), or compare fewer angles or starts"
        )
    }
}
