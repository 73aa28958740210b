//! How to run the engine ([`EngineOptions`], [`Algorithm`]): a leaf the
//! driver (`mod.rs`) and its rooms (`band.rs`) both read.

use crate::engine::probe::Probe;
use crate::strike::StrikeRule;

/// Which implementation of push and slide to run. Both give identical masks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Algorithm {
    /// The paper's sections 3 and 4, literally: the reference and baseline.
    Paper,
    /// Sliding-window-minimum push and the one-layer streaming slide.
    Fast,
}

impl Algorithm {
    /// Every implementation, as `--algorithm` offers them.
    pub const ALL: [Algorithm; 2] = [Algorithm::Paper, Algorithm::Fast];

    /// The name, as `--algorithm` takes it and `summary.json` records it.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Paper => "paper",
            Algorithm::Fast => "fast",
        }
    }
}

/// How to run the engine.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineOptions {
    /// SPEC's strike rule: rounding tolerance `e0` and deflection
    /// threshold `sigma`.
    pub rule: StrikeRule,
    /// The implementation.
    pub algorithm: Algorithm,
    /// Start rows to run (`None`: all). The benchmark runs the paper
    /// algorithm on a sample of rows.
    pub start_rows: Option<Vec<usize>>,
    /// Cells to probe (fast path only): whether the knee-form's face meets
    /// each at a level its `y` sticks out past ([`super::AngleMask::probes_met`]).
    pub probes: Vec<Probe>,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions {
            rule: StrikeRule::default(),
            algorithm: Algorithm::Fast,
            start_rows: None,
            probes: Vec::new(),
        }
    }
}
