//! Step 2a of SPEC, the push: for every start, the face level `yr` at which
//! the knee-form pushed in +y first touches a grid point, `min h` over the
//! nodes inside the footprint.
//!
//! The footprint is a union of row intervals, so `yr` is a minimum of row
//! window minima. [`WindowMin`] is a sparse table per grid row (levels of
//! `2^l`-wide minima, built once for all angles): any window is the minimum
//! of two overlapping power-of-two windows, so each (start, footprint row)
//! costs two loads and two comparisons. [`push_block`] does a block of
//! consecutive starts at once, their levels held in vector registers.
//!
//! Heights are taken as their ranks ([`crate::ranked`]): minima of ranks
//! are the ranks of minima, exactly.

use crate::kneeform::GridFootprint;
use crate::padded::{PaddedGrid, fmin};
use crate::ranked::{OFF, Rank};

/// Row window minima of a padded height grid's real rows, for every
/// power-of-two width.
///
/// Level 0 is the grid's own height ranks (borrowed, not copied), and the
/// padding rows above and below the grid are left out: they hold only
/// `+inf`, which never lowers a minimum, so the push skips the
/// footprint rows that fall on them. That keeps the table at `levels - 1`
/// copies of the real rows, the largest item of an analysis's memory.
#[derive(Debug)]
pub struct WindowMin<'a> {
    /// The padded grid's real rows' ranks: level 0.
    heights: &'a [Rank],
    /// `levels[l - 1][row * stride + x]` = min of the ranks over
    /// `x .. x + 2^l` in the real row `row` ([`OFF`] past its end).
    levels: Vec<Vec<Rank>>,
    /// Padded index of the first real row's first node.
    first: usize,
}

impl<'a> WindowMin<'a> {
    /// The widest push window of `footprints` (nodes, at least 1): the
    /// width the table must cover.
    pub fn max_width(footprints: &[GridFootprint]) -> usize {
        footprints
            .iter()
            .flat_map(|fp| fp.rows.iter().map(|r| (r.khi - r.klo + 1).max(1) as usize))
            .max()
            .unwrap_or(1)
    }

    /// The levels a table for windows up to `max_width` nodes holds: widths
    /// 1, 2, 4, ... up to `max_width`. All but the first are a copy of the
    /// grid's real rows.
    pub fn levels(max_width: usize) -> usize {
        max_width.max(1).ilog2() as usize + 1
    }

    /// Builds the table for windows up to `max_width` nodes over `ranks`,
    /// the ranks of `grid`'s heights ([`crate::ranked::RankedGrid`]).
    pub fn new(grid: &PaddedGrid, ranks: &'a [Rank], max_width: usize) -> WindowMin<'a> {
        let stride = grid.stride;
        let first = grid.pad_rows * stride;
        let heights = &ranks[first..first + grid.spec.nz * stride];
        let mut levels: Vec<Vec<Rank>> = Vec::new();
        let mut width = 1;
        for _ in 1..WindowMin::levels(max_width) {
            let prev = levels.last().map_or(heights, Vec::as_slice);
            let mut next = vec![OFF; prev.len()];
            for (dst, src) in next.chunks_exact_mut(stride).zip(prev.chunks_exact(stride)) {
                let n = stride - width;
                for x in 0..n {
                    dst[x] = src[x].min(src[x + width]);
                }
                dst[n..].copy_from_slice(&src[n..]);
            }
            levels.push(next);
            width *= 2;
        }
        WindowMin {
            heights,
            levels,
            first,
        }
    }

    /// Level `l`: minima over `2^l` nodes, indexed from the first real row.
    #[inline(always)]
    fn level(&self, l: usize) -> &[Rank] {
        if l == 0 {
            self.heights
        } else {
            &self.levels[l - 1]
        }
    }

    /// The minima over `width` consecutive nodes of the real rows, for a
    /// power-of-two `width` the table holds, as [`WindowOf`].
    pub fn windows_of(&self, width: usize) -> Option<WindowOf<'_>> {
        let l = width.checked_ilog2()? as usize;
        (width.is_power_of_two() && l <= self.levels.len()).then(|| WindowOf {
            minima: self.level(l),
            first: self.first,
        })
    }

    /// Memory held (bytes), level 0 aside (it is the grid's).
    pub fn bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.len() * size_of::<Rank>())
            .sum()
    }
}

/// A level of [`WindowMin`]: the minimum over a fixed number of
/// consecutive nodes of a real row, from any node.
#[derive(Debug, Clone, Copy)]
pub struct WindowOf<'a> {
    minima: &'a [Rank],
    first: usize,
}

impl WindowOf<'_> {
    /// The minimum over the window beginning at the padded node `node`, on
    /// a real row.
    #[inline(always)]
    pub fn at(&self, node: usize) -> Rank {
        self.minima[node - self.first]
    }
}

/// One footprint row of a push: the offset from a start to its first
/// inside node, the table level and the second window's shift covering
/// its width.
type PushRow = (isize, u32, u32);

/// The push rows of one footprint, ready for [`push_block`]: each row
/// with nodes inside, in `dj` order.
#[derive(Debug, Clone)]
pub struct PushRows {
    rows: Vec<PushRow>,
    /// Each row's `dj`, ascending.
    dj: Vec<i32>,
}

impl PushRows {
    /// Lays out `fp`'s rows on `grid`.
    pub fn new(grid: &PaddedGrid, fp: &GridFootprint) -> PushRows {
        let inside: Vec<_> = fp.rows.iter().filter(|r| r.khi >= r.klo).collect();
        debug_assert!(inside.is_sorted_by_key(|r| r.dj));
        let rows = inside
            .iter()
            .map(|r| {
                let width = (r.khi - r.klo + 1) as u32;
                let level = width.ilog2();
                (grid.offset(r.dj, r.klo), level, width - (1 << level))
            })
            .collect();
        PushRows {
            rows,
            dj: inside.iter().map(|r| r.dj).collect(),
        }
    }

    /// The indices of the rows that fall on the grid's real rows for a
    /// start in row `j0` of a grid of `nz` rows (the others lie on `+inf`
    /// padding).
    fn within(&self, j0: usize, nz: usize) -> std::ops::Range<usize> {
        let j0 = j0 as i64;
        let lo = self.dj.partition_point(|&dj| j0 + i64::from(dj) < 0);
        let hi = self
            .dj
            .partition_point(|&dj| j0 + i64::from(dj) < nz as i64);
        lo..hi.max(lo)
    }
}

/// [`push_block`] for the starts of `T` consecutive start rows from `j0`
/// at once, in a grid of `nz` rows whose rows are `stride` nodes apart:
/// `base` is the node index of the first row's first start. The rows are
/// taken footprint row by footprint row, each for the `T` start rows in
/// turn, so the grid rows they read are read again by the next footprint
/// row (one grid row up for one start row down), while still in the
/// first-level cache.
#[inline(always)]
pub fn push_tile<const W: usize, const T: usize>(
    table: &WindowMin,
    rows: &PushRows,
    j0: usize,
    nz: usize,
    stride: usize,
    base: usize,
) -> [[Rank; W]; T] {
    let mut yr = [[OFF; W]; T];
    let base = base - table.first;
    let ranges: [std::ops::Range<usize>; T] = std::array::from_fn(|t| rows.within(j0 + t, nz));
    let lo = ranges.iter().map(|r| r.start).min().unwrap_or(0);
    let hi = ranges.iter().map(|r| r.end).max().unwrap_or(0);
    for e in lo..hi {
        let (offset, level, second) = rows.rows[e];
        let t_level = table.level(level as usize);
        for (t, yr) in yr.iter_mut().enumerate() {
            if !ranges[t].contains(&e) {
                continue;
            }
            let a = (base + t * stride).wrapping_add_signed(offset);
            let first: &[Rank; W] = t_level[a..a + W].try_into().expect("W values");
            let b = a + second as usize;
            let last: &[Rank; W] = t_level[b..b + W].try_into().expect("W values");
            for w in 0..W {
                yr[w] = yr[w].min(first[w].min(last[w]));
            }
        }
    }
    yr
}

/// Face levels (ranks) of `W` consecutive starts of start row `j0`, in a
/// grid of `nz` rows, whose node index (in the padded grid) begins at
/// `base`: the minimum height over the nodes inside each footprint,
/// [`OFF`] where none is finite. [`push_tile`] of one start row.
#[inline(always)]
pub fn push_block<const W: usize>(
    table: &WindowMin,
    rows: &PushRows,
    j0: usize,
    nz: usize,
    base: usize,
) -> [Rank; W] {
    let [yr] = push_tile::<W, 1>(table, rows, j0, nz, 0, base);
    yr
}

/// The paper's push for one start, literally: the minimum over every node
/// inside the footprint.
pub fn push_start_literal(grid: &PaddedGrid, fp: &GridFootprint, i0: usize, j0: usize) -> f64 {
    let mut yr = f64::INFINITY;
    for row in &fp.rows {
        let Some(j) = grid.row_of(j0, row.dj) else {
            continue;
        };
        for k in row.klo..=row.khi {
            yr = fmin(yr, grid.h[grid.index(j as i64, k) + i0]);
        }
    }
    yr
}
