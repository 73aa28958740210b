//! What a study compares, per start (or position) and angle and per
//! pitch, whatever its approach: the leaf the approaches (`slide`,
//! `direct`) and the shares (`sharded`) share, so that none of them
//! depends on another for these.

use std::any::Any;

use super::error::HarnessError;
use super::metrics::TieBand;
use crate::partition::Shard;

/// One pair of a study (a start or a position at one angle) as a shard
/// keeps it: all its comparison is assembled from. Each approach has its
/// own ([`super::compare::PairResult`] for push-and-slide,
/// [`super::direct::DirectPair`] for the direct approach), and encodes it
/// in a shard's `shard.bin` itself.
pub(crate) trait Pair: std::fmt::Debug + Clone + PartialEq + Send + Sync + 'static {
    /// Appends the pair's bits to `bin`; its approach's `read_pairs` reads
    /// them back (`super::approach::StudyApproach`).
    fn put(&self, bin: &mut Vec<u8>);
}

/// The pairs of one pitch of a share as [`Pairs`] holds them, whatever
/// their approach.
trait PairSet: Any + std::fmt::Debug + Send + Sync {
    fn len(&self) -> usize;
    fn put(&self, bin: &mut Vec<u8>);
    fn boxed_clone(&self) -> Box<dyn PairSet>;
    fn same(&self, other: &dyn PairSet) -> bool;
}

impl<T: Pair> PairSet for Vec<T> {
    fn len(&self) -> usize {
        Vec::len(self)
    }

    fn put(&self, bin: &mut Vec<u8>) {
        self.iter().for_each(|pair| pair.put(bin));
    }

    fn boxed_clone(&self) -> Box<dyn PairSet> {
        Box::new(self.clone())
    }

    fn same(&self, other: &dyn PairSet) -> bool {
        (other as &dyn Any).downcast_ref::<Vec<T>>() == Some(self)
    }
}

/// The pairs of one pitch of a share, angle-major over the share's
/// starts, of whichever approach compared them.
#[derive(Debug)]
pub struct Pairs(Box<dyn PairSet>);

impl Pairs {
    /// `pairs`, as a share holds them.
    pub(crate) fn of<T: Pair>(pairs: Vec<T>) -> Pairs {
        Pairs(Box::new(pairs))
    }

    /// How many pairs.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends every pair's bits to `bin`, in order.
    pub(crate) fn put(&self, bin: &mut Vec<u8>) {
        self.0.put(bin);
    }

    /// The pairs moved out, when they are `T`s (`None` for another
    /// approach's, which are left).
    pub(crate) fn take<T: Pair>(&mut self) -> Option<Vec<T>> {
        (self.0.as_mut() as &mut dyn Any)
            .downcast_mut::<Vec<T>>()
            .map(std::mem::take)
    }
}

/// `count` pairs read one by one (pair `k` by `read(k)`), as [`Pairs`]: an
/// approach's [`super::approach::StudyApproach::read_pairs`].
pub(crate) fn read_each<T: Pair>(
    count: usize,
    mut read: impl FnMut(usize) -> Result<T, String>,
) -> Result<Pairs, String> {
    let mut pairs = Vec::with_capacity(count);
    for k in 0..count {
        pairs.push(read(k)?);
    }
    Ok(Pairs::of(pairs))
}

impl Clone for Pairs {
    fn clone(&self) -> Pairs {
        Pairs(self.0.boxed_clone())
    }
}

impl PartialEq for Pairs {
    fn eq(&self, other: &Pairs) -> bool {
        self.0.same(other.0.as_ref())
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
    /// Per angle, the analysis's struck nodes nearest to the share's exact
    /// strikes (mm, xz; [`super::compare::covering_nodes`]): what the
    /// area's misses are measured to, beside the compared starts' own
    /// strikes. None for the direct approach.
    pub covering: Vec<Vec<[f64; 2]>>,
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
