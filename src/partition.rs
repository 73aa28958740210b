//! Which share of a run's work one shard does: `--shard K/N` takes the
//! `K`-th of every `N` items (a run's angles, a study's starts). The
//! pipeline and the harness select their work by it; the shard files are
//! [`crate::shard`]'s.

use serde::{Deserialize, Serialize};

/// One shard of a run's angles: the `index`-th (1-based) of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// K, from 1 to `count`.
    pub index: usize,
    /// N, at least 1.
    pub count: usize,
}

impl Shard {
    /// The whole run: shard 1 of 1, every item.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Whether this shard is the whole run ([`Shard::WHOLE`]).
    pub fn is_whole(&self) -> bool {
        self.count == 1
    }

    /// Parses `K/N` (1 <= K <= N <= [`crate::limits::MAX_ANGLES`]).
    pub fn parse(s: &str) -> Result<Shard, ShardSyntax> {
        let bad = || ShardSyntax(s.to_string());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count || count > crate::limits::MAX_ANGLES {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The indices, among `items` (a run's angles, a study's starts), of
    /// this shard's: `k` with `k % count == index - 1`, in increasing
    /// order.
    pub fn indices(&self, items: usize) -> Vec<usize> {
        (self.index - 1..items).step_by(self.count).collect()
    }

    /// Whether item `k` is this shard's: `k % count == index - 1`.
    pub fn has(&self, k: usize) -> bool {
        k % self.count == self.index - 1
    }

    /// Whether `indices` are this shard's among `items` ([`Shard::indices`]),
    /// checked without building them (a shard.json's numbers are not
    /// trusted to size anything): `1 <= index <= count <= max(items, 1)`
    /// and `indices[m] = index - 1 + m * count`.
    pub fn holds(&self, items: usize, indices: &[usize]) -> bool {
        let Shard { index, count } = *self;
        if index == 0 || index > count || count > items.max(1) {
            return false;
        }
        let expected = items.saturating_sub(index - 1).div_ceil(count);
        indices.len() == expected
            && indices.iter().enumerate().all(|(m, &k)| {
                m.checked_mul(count).and_then(|o| o.checked_add(index - 1)) == Some(k)
            })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Not `K/N` with `1 <= K <= N <= ` [`crate::limits::MAX_ANGLES`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("expected K/N with 1 <= K <= N (shard K of N), got {0:?}")]
pub struct ShardSyntax(pub String);
