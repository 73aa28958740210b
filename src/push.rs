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

use crate::kneeform::GridFootprint;
use crate::padded::{PaddedGrid, fmin};

/// Row window minima of a padded height grid, for every power-of-two width.
#[derive(Debug)]
pub struct WindowMin {
    /// `levels[l][row * stride + x]` = min of `h` over `x .. x + 2^l` in the
    /// padded row (`+inf` past its end).
    levels: Vec<Vec<f64>>,
}

impl WindowMin {
    /// The widest push window of `footprints` (nodes, at least 1): the
    /// width the table must cover.
    pub fn max_width(footprints: &[GridFootprint]) -> usize {
        footprints
            .iter()
            .flat_map(|fp| fp.rows.iter().map(|r| (r.khi - r.klo + 1).max(1) as usize))
            .max()
            .unwrap_or(1)
    }

    /// The levels a table for windows up to `max_width` nodes holds, each
    /// a copy of the padded grid: widths 1, 2, 4, ... up to `max_width`.
    pub fn levels(max_width: usize) -> usize {
        max_width.max(1).ilog2() as usize + 1
    }

    /// Builds the table for windows up to `max_width` nodes.
    pub fn new(grid: &PaddedGrid, max_width: usize) -> WindowMin {
        let mut levels = vec![grid.h.clone()];
        let stride = grid.stride;
        let mut width = 1;
        for _ in 1..WindowMin::levels(max_width) {
            let prev = levels.last().expect("level 0 exists");
            let mut next = vec![f64::INFINITY; prev.len()];
            for (dst, src) in next.chunks_exact_mut(stride).zip(prev.chunks_exact(stride)) {
                let n = stride - width;
                for x in 0..n {
                    dst[x] = fmin(src[x], src[x + width]);
                }
                dst[n..].copy_from_slice(&src[n..]);
            }
            levels.push(next);
            width *= 2;
        }
        WindowMin { levels }
    }

    /// Memory held (bytes).
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| l.len() * 8).sum()
    }
}

/// The push rows of one footprint, ready for [`push_block`]: for each row
/// with nodes inside, the offset from a start to its first inside node,
/// and the table level and second-window shift covering its width.
#[derive(Debug, Clone)]
pub struct PushRows {
    rows: Vec<(isize, u32, u32)>,
}

impl PushRows {
    /// Lays out `fp`'s rows on `grid`.
    pub fn new(grid: &PaddedGrid, fp: &GridFootprint) -> PushRows {
        let rows = fp
            .rows
            .iter()
            .filter(|r| r.khi >= r.klo)
            .map(|r| {
                let width = (r.khi - r.klo + 1) as u32;
                let level = width.ilog2();
                (grid.offset(r.dj, r.klo), level, width - (1 << level))
            })
            .collect();
        PushRows { rows }
    }
}

/// Face levels of `W` consecutive starts whose node index (in the padded
/// grid) begins at `base`: the minimum height over the nodes inside each
/// footprint, `+inf` where none is finite.
#[inline(always)]
pub fn push_block<const W: usize>(table: &WindowMin, rows: &PushRows, base: usize) -> [f64; W] {
    let mut yr = [f64::INFINITY; W];
    for &(offset, level, second) in &rows.rows {
        let t = &table.levels[level as usize];
        let a = base.wrapping_add_signed(offset);
        let first: &[f64; W] = t[a..a + W].try_into().expect("W values");
        let b = a + second as usize;
        let last: &[f64; W] = t[b..b + W].try_into().expect("W values");
        for w in 0..W {
            yr[w] = fmin(yr[w], fmin(first[w], last[w]));
        }
    }
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
