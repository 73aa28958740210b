//! What a study compares, per start (or position) and angle and per
//! pitch, for either approach: the leaf the study modules (`verify`,
//! `converge`, `direct`) and the shards (`sharded`) share, so that none of
//! them depends on another for these.

use serde::{Deserialize, Serialize};

use super::HarnessError;
use super::compare::PairResult;
use super::metrics::TieBand;
use crate::partition::Shard;

/// The pairs of one pitch of a share, angle-major over the share's starts.
#[derive(Debug, Clone, PartialEq)]
pub enum Pairs {
    /// Push-and-slide's start-angle pairs.
    Slide(Vec<PairResult>),
    /// The direct approach's position-angle pairs.
    Direct(Vec<DirectPair>),
}

impl Pairs {
    /// How many pairs.
    pub fn len(&self) -> usize {
        match self {
            Pairs::Slide(p) => p.len(),
            Pairs::Direct(p) => p.len(),
        }
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Push-and-slide's pairs (`None` for the direct approach's).
    pub(super) fn slide_mut(&mut self) -> Option<&mut Vec<PairResult>> {
        match self {
            Pairs::Slide(p) => Some(p),
            Pairs::Direct(_) => None,
        }
    }

    /// The direct approach's pairs (`None` for push-and-slide's).
    pub(super) fn direct_mut(&mut self) -> Option<&mut Vec<DirectPair>> {
        match self {
            Pairs::Direct(p) => Some(p),
            Pairs::Slide(_) => None,
        }
    }
}

/// The tie band of a direct study's pitch, which has none (the knee does
/// not slide): zero.
pub(super) const NO_BAND: TieBand = TieBand {
    sigma: 0.0,
    m: 0.0,
    pitch: 0.0,
};

/// One pitch of a share: its start-angle pairs, angle-major over the
/// share's starts, and what was timed.
#[derive(Debug, Clone, PartialEq)]
pub struct PitchPart {
    /// The pitch (mm).
    pub pitch: f64,
    /// The pairs compared, angle-major over the share's starts.
    pub pairs: Pairs,
    /// The tie band at this pitch (zero for the direct approach).
    pub band: TieBand,
    /// Seconds on the grid side of the comparison.
    pub grid_s: f64,
    /// Seconds of the engine's full push and slide at this pitch (a
    /// convergence study times it; a verification does not: 0).
    pub seconds: f64,
    /// Grid nodes at this pitch.
    pub nodes: usize,
}

/// `shard`'s share of `all` ([`Shard::WHOLE`]: all of it); an error when
/// a shard would have no start.
pub(super) fn share(all: &[[f64; 2]], shard: Shard) -> Result<Vec<[f64; 2]>, HarnessError> {
    if shard.count > all.len() {
        return Err(HarnessError::TooManyShards {
            shards: shard.count,
            starts: all.len(),
        });
    }
    Ok(shard
        .indices(all.len())
        .into_iter()
        .map(|s| all[s])
        .collect())
}

/// One position at one angle: both sides' first contacts and the errors.
/// Positions and points in mm, in the placed part's frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DirectRow {
    /// The position's y (the centre of the knee-form's width).
    pub y: f64,
    /// The position's z (the reference point's height).
    pub z: f64,
    /// Angle (degrees).
    pub angle_deg: f64,
    /// `both`, `grid_only`, `exact_only`, `neither` or `oracle_failed`.
    pub status: String,
    /// The grid's `X* = -Y*` (the reference point's x at first contact).
    pub grid_level: Option<f64>,
    /// The exact `X*`.
    pub exact_level: Option<f64>,
    /// `|Y*_grid - Y*_exact|`.
    pub level_error: Option<f64>,
    /// The exact contact point's y and z.
    pub exact_y: Option<f64>,
    /// See `exact_y`.
    pub exact_z: Option<f64>,
    /// From the exact contact to the nearest grid-contacted node, in y-z.
    pub contact_distance: Option<f64>,
    /// Grid-contacted nodes (ties within `e0`).
    pub grid_contacted: usize,
    /// Exact contact points (ties within `e0` of travel).
    pub exact_ties: usize,
}

/// One position at one angle as a shard keeps it: its row, and whether
/// the engine's level there is not the transcription's (which the row
/// does not say). A comparison is [`assemble_direct`]d from these alone.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectPair {
    /// The row.
    pub row: DirectRow,
    /// The engine's level differs from the transcription's, to the bit.
    pub engine_mismatch: bool,
}
