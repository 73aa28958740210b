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
//! **Most footprint rows are never read.** The rows are taken in groups of
//! sixteen, and a second table (`GroupMin`: minima over blocks of eight
//! grid rows) gives, in a few loads, a lower bound of every
//! height a group covers for the whole block of starts. The groups are
//! read lowest bound first, and once a group's bound is no lower than the
//! highest level found so far among the block's starts, neither it nor any
//! group after it can lower a level: the minimum is already exact. On a
//! part's surface the lowest node of a footprint lies near one edge, and
//! the groups far from it are passed over (measured: `results/design.md`,
//! "The push's row groups"). Where no
//! group can be passed over (a rough surface, a block of starts with one
//! that meets no node), the bounds add a few scalar loads to the 64
//! vector loads each group's row costs a tile.
//!
//! Heights are taken as their ranks ([`crate::engine::ranked`]): minima of ranks
//! are the ranks of minima, exactly.

use crate::engine::padded::{LANE_SLACK, PaddedGrid, fmin};
use crate::engine::ranked::{NEVER, OFF, Rank};
use crate::kneeform::GridFootprint;

/// Row window minima of a padded height grid's real rows, for every
/// power-of-two width.
///
/// Level 0 is the grid's own height ranks (borrowed, not copied), and the
/// padding rows above and below the grid are left out: they hold only
/// `+inf`, which never lowers a minimum, so the push skips the
/// footprint rows that fall on them. That keeps the table at `levels - 1`
/// copies of the real rows, the largest item of an analysis's memory.
#[derive(Debug)]
pub(crate) struct WindowMin<'a> {
    /// The padded grid's real rows' ranks: level 0.
    heights: &'a [Rank],
    /// `levels[l - 1][row * stride + x]` = min of the ranks over
    /// `x .. x + 2^l` in the real row `row` ([`OFF`] past its end).
    levels: Vec<Vec<Rank>>,
    /// Padded index of the first real row's first node.
    first: usize,
    /// The length of a row.
    stride: usize,
    /// Lower bounds over blocks of rows, for the pruned push.
    groups: GroupMin,
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
    /// the ranks of `grid`'s heights ([`crate::engine::ranked::RankedGrid`]).
    pub fn new(grid: &PaddedGrid, ranks: &'a [Rank], max_width: usize) -> WindowMin<'a> {
        let stride = grid.stride;
        let first = grid.pad_rows * stride;
        let heights = &ranks[first..first + grid.spec.nz * stride];
        let mut levels: Vec<Vec<Rank>> = Vec::new();
        for l in 1..WindowMin::levels(max_width) {
            let prev = levels.last().map_or(heights, Vec::as_slice);
            levels.push(doubled(prev, stride, 1 << (l - 1)));
        }
        WindowMin {
            heights,
            levels,
            first,
            stride,
            groups: GroupMin::new(heights, stride, max_width),
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

    /// The bytes [`WindowMin::bytes`] will be for a grid of `nz` real rows
    /// of `stride` nodes and windows up to `max_width` nodes.
    pub fn bytes_for(nz: usize, stride: usize, max_width: usize) -> usize {
        let rows = (WindowMin::levels(max_width) - 1) * nz;
        let group_rows = GroupMin::levels(max_width) * nz.div_ceil(GROUP_ROWS);
        (rows + group_rows) * stride * size_of::<Rank>()
    }
}

/// The next level of a table of row window minima: from the minima over
/// `width` nodes in `prev` (rows of `stride` nodes), the minima over
/// `2 * width`. A window running past its row's end takes only the nodes
/// in the row (the rest would be `+inf`).
fn doubled(prev: &[Rank], stride: usize, width: usize) -> Vec<Rank> {
    let mut next = vec![OFF; prev.len()];
    for (dst, src) in next.chunks_exact_mut(stride).zip(prev.chunks_exact(stride)) {
        let n = stride - width;
        for x in 0..n {
            dst[x] = src[x].min(src[x + width]);
        }
        dst[n..].copy_from_slice(&src[n..]);
    }
    next
}

/// Grid rows per block of [`GroupMin`].
const GROUP_ROWS: usize = 8;

/// Footprint rows per group of the pruned push ([`push_tile`]).
const PUSH_GROUP: usize = 16;

/// The minima over blocks of [`GROUP_ROWS`] real rows and power-of-two
/// runs of columns: a lower bound, in a few loads, of the heights in any
/// rectangle of the grid (exact in its columns, its rows rounded out to
/// whole blocks).
#[derive(Debug)]
struct GroupMin {
    /// `levels[l][b * stride + x]` = min of the ranks over the real rows
    /// `GROUP_ROWS * b ..` (the block `b`) and the columns `x .. x + 2^l`
    /// ([`OFF`] past the row's end).
    levels: Vec<Vec<Rank>>,
    stride: usize,
    /// Real rows.
    nz: usize,
}

impl GroupMin {
    /// The levels the table holds for footprint rows up to `max_width`
    /// nodes wide: runs as wide as a group's rectangle for the widest
    /// block of starts ([`LANE_SLACK`] lanes) on top.
    fn levels(max_width: usize) -> usize {
        WindowMin::levels(max_width + LANE_SLACK)
    }

    /// The blocks of `heights` (real rows of `stride` nodes) for footprint
    /// rows up to `max_width` nodes wide ([`GroupMin::levels`]).
    fn new(heights: &[Rank], stride: usize, max_width: usize) -> GroupMin {
        let nz = heights.len() / stride;
        let mut level0 = vec![OFF; nz.div_ceil(GROUP_ROWS) * stride];
        for (dst, rows) in level0
            .chunks_exact_mut(stride)
            .zip(heights.chunks(GROUP_ROWS * stride))
        {
            for row in rows.chunks_exact(stride) {
                for (d, &h) in dst.iter_mut().zip(row) {
                    *d = (*d).min(h);
                }
            }
        }
        let mut levels = vec![level0];
        for l in 1..GroupMin::levels(max_width) {
            let prev = levels.last().expect("level 0 is there");
            levels.push(doubled(prev, stride, 1 << (l - 1)));
        }
        GroupMin { levels, stride, nz }
    }

    /// A lower bound of the ranks in the real rows `rows` (any, clipped to
    /// the grid) and the columns `x_lo ..= x_hi` of a row.
    #[inline(always)]
    fn below(&self, rows: std::ops::RangeInclusive<i64>, x_lo: usize, x_hi: usize) -> Rank {
        let lo = (*rows.start()).max(0);
        let hi = (*rows.end()).min(self.nz as i64 - 1);
        if lo > hi {
            return OFF;
        }
        // Runs of the widest level the width allows, the last ending at
        // `x_hi`: two, unless the width is past the table's widest.
        let l = ((x_hi - x_lo + 1).ilog2() as usize).min(self.levels.len() - 1);
        let (level, run) = (&self.levels[l], 1 << l);
        let mut bound = OFF;
        for block in lo as usize / GROUP_ROWS..=hi as usize / GROUP_ROWS {
            let row = &level[block * self.stride..];
            let mut x = x_lo;
            while x + run <= x_hi {
                bound = bound.min(row[x]);
                x += run;
            }
            bound = bound.min(row[x_hi + 1 - run]);
        }
        bound
    }
}

/// A level of [`WindowMin`]: the minimum over a fixed number of
/// consecutive nodes of a real row, from any node.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WindowOf<'a> {
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
pub(crate) struct PushRows {
    rows: Vec<PushRow>,
    /// Each row's `dj`, ascending.
    dj: Vec<i32>,
    /// The rows in runs of [`PUSH_GROUP`], in order.
    groups: Vec<PushGroup>,
}

/// A run of consecutive rows of [`PushRows`] and the rectangle (relative to
/// a start) that holds their nodes inside the footprint.
#[derive(Debug, Clone)]
struct PushGroup {
    rows: std::ops::Range<usize>,
    /// The first and last row's `dj`.
    dj: (i32, i32),
    /// The lowest `klo` and highest `khi` of the rows.
    k: (i32, i32),
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
        let groups = (0..inside.len())
            .step_by(PUSH_GROUP)
            .map(|first| {
                let run = &inside[first..(first + PUSH_GROUP).min(inside.len())];
                PushGroup {
                    rows: first..first + run.len(),
                    dj: (run[0].dj, run[run.len() - 1].dj),
                    k: (
                        run.iter().map(|r| r.klo).min().expect("a run has rows"),
                        run.iter().map(|r| r.khi).max().expect("a run has rows"),
                    ),
                }
            })
            .collect();
        PushRows {
            rows,
            dj: inside.iter().map(|r| r.dj).collect(),
            groups,
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
/// first-level cache; and group by group, lowest bound first, until no
/// group left can lower a level (the module's doc).
#[inline(always)]
pub(crate) fn push_tile<const W: usize, const T: usize>(
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
    // The groups of footprint rows, lowest bound first: a group whose
    // bound is no lower than every level found so far cannot lower one.
    let x = base - j0 * table.stride;
    let mut order: Vec<(Rank, u32)> = rows
        .groups
        .iter()
        .zip(0..)
        .filter(|(g, _)| g.rows.start < hi && g.rows.end > lo)
        .map(|(g, n)| {
            let rows = j0 as i64 + i64::from(g.dj.0)..=(j0 + T - 1) as i64 + i64::from(g.dj.1);
            let x_lo = x.wrapping_add_signed(g.k.0 as isize);
            let x_hi = x.wrapping_add_signed((W - 1) as isize + g.k.1 as isize);
            (table.groups.below(rows, x_lo, x_hi), n)
        })
        .collect();
    order.sort_unstable();
    let live: [bool; T] = std::array::from_fn(|t| !ranges[t].is_empty());
    let mut top = OFF;
    for (bound, n) in order {
        if bound >= top {
            break;
        }
        let group = rows.groups[n as usize].rows.clone();
        for e in group.start.max(lo)..group.end.min(hi) {
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
        top = NEVER;
        for (yr, _) in yr.iter().zip(live).filter(|&(_, live)| live) {
            for &level in yr {
                top = top.max(level);
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
pub(crate) fn push_block<const W: usize>(
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
pub(crate) fn push_start_literal(
    grid: &PaddedGrid,
    fp: &GridFootprint,
    i0: usize,
    j0: usize,
) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::ranked::RankedGrid;
    use crate::grid::{GridSpec, HeightGrid};
    use crate::kneeform::KneeForm;

    /// The pruned push ([`push_tile`] passing over groups of footprint
    /// rows whose lower bound cannot lower a level) gives every start the
    /// paper's push, the minimum over every node of its footprint, on
    /// surfaces where the lowest node lies anywhere: a bowl, slopes both
    /// ways with pits, a plateau of equal heights, rough ground with holes
    /// and islands in a part mostly off.
    #[test]
    fn pruned_push_is_the_minimum_over_the_footprint() {
        let knee = KneeForm {
            triangle_side: 40.0,
            radius: 8.0,
            thickness: 100.0,
        };
        let spec = GridSpec {
            pitch: 0.9,
            i_origin: -30,
            j_origin: -20,
            nx: 120,
            nz: 70,
        };
        let mut rng = crate::harness::compare::SplitMix(11);
        let mut noise = move || (rng.next() >> 11) as f64 / (1u64 << 53) as f64;
        let surfaces: Vec<Vec<f64>> = vec![
            // A bowl: the lowest node in the footprint's middle.
            (0..spec.len())
                .map(|n| {
                    let (x, z) = (spec.x(n % spec.nx), spec.z(n / spec.nx));
                    0.01 * ((x - 40.0).powi(2) + (z - 10.0).powi(2))
                })
                .collect(),
            // Slopes along x and z with sparse pits deeper than the slope.
            (0..spec.len())
                .map(|n| {
                    let (i, j) = (n % spec.nx, n / spec.nx);
                    let pit = noise() < 0.01;
                    0.3 * i as f64 - 0.2 * j as f64 - if pit { 30.0 } else { 0.0 }
                })
                .collect(),
            // A plateau: every level ties.
            vec![2.5; spec.len()],
            // Rough ground with holes.
            (0..spec.len())
                .map(|_| {
                    let r = noise();
                    if r < 0.1 {
                        f64::INFINITY
                    } else {
                        (r * 40.0).floor()
                    }
                })
                .collect(),
            // Islands in a part mostly off: many footprints meet none.
            (0..spec.len())
                .map(|n| {
                    let (i, j) = (n % spec.nx, n / spec.nx);
                    if i % 37 < 3 && j % 23 < 4 {
                        -(i as f64) - j as f64
                    } else {
                        f64::INFINITY
                    }
                })
                .collect(),
        ];
        for h in surfaces {
            let grid = HeightGrid { spec, h };
            for angle in [-30.0, -7.0, 0.0, 13.0, 30.0] {
                let fp = GridFootprint::new(&knee, angle, &spec);
                assert!(fp.rows.len() > 2 * PUSH_GROUP, "several groups of rows");
                let padded = PaddedGrid::new(&grid, std::slice::from_ref(&fp));
                let ranked = RankedGrid::new(&padded);
                let table = WindowMin::new(
                    &padded,
                    &ranked.ranks,
                    WindowMin::max_width(std::slice::from_ref(&fp)),
                );
                let rows = PushRows::new(&padded, &fp);
                let nz = spec.nz;
                let check = |j0: usize, block: i64, yr: &[Rank]| {
                    for (w, &yr) in yr.iter().enumerate() {
                        let i0 = block + w as i64;
                        if (0..spec.nx as i64).contains(&i0) {
                            let literal = push_start_literal(&padded, &fp, i0 as usize, j0);
                            assert_eq!(
                                ranked.height(yr),
                                literal,
                                "start ({i0}, {j0}) at {angle} degrees"
                            );
                        }
                    }
                };
                for block in (-16..spec.nx as i64).step_by(16) {
                    for j0 in 0..nz {
                        let base = padded
                            .index(j0 as i64, 0)
                            .wrapping_add_signed(block as isize);
                        check(j0, block, &push_block::<16>(&table, &rows, j0, nz, base));
                    }
                    for j0 in 0..nz - 3 {
                        let base = padded
                            .index(j0 as i64, 0)
                            .wrapping_add_signed(block as isize);
                        let tile = push_tile::<16, 4>(&table, &rows, j0, nz, padded.stride, base);
                        for (t, yr) in tile.iter().enumerate() {
                            check(j0 + t, block, yr);
                        }
                    }
                }
            }
        }
    }
}
