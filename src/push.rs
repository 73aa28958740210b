//! Step 2a of SPEC, the push: for every start, the face level `yr` at which
//! the knee-form pushed in +y first touches a grid point, `min h` over the
//! nodes inside the footprint.
//!
//! The footprint is a union of row intervals, so `yr` is a minimum of row
//! window minima. [`WindowMin`] is a sparse table per grid row (levels of
//! `2^l`-wide minima, built once for all angles): any window is the minimum
//! of two overlapping power-of-two windows, so each (start, footprint row)
//! costs two loads and two comparisons, and the loop over the starts of a
//! row is contiguous and vectorises.

use crate::kneeform::GridFootprint;
use crate::padded::{PaddedGrid, fmin};
use crate::simd::dispatch;

/// Row window minima of a padded height grid, for every power-of-two width.
#[derive(Debug)]
pub struct WindowMin {
    /// `levels[l][row * stride + x]` = min of `h` over `x .. x + 2^l` in the
    /// padded row (`+inf` past its end).
    levels: Vec<Vec<f64>>,
}

impl WindowMin {
    /// Builds the table for windows up to `max_width` nodes.
    pub fn new(grid: &PaddedGrid, max_width: usize) -> WindowMin {
        let mut levels = vec![grid.h.clone()];
        let stride = grid.stride;
        let mut width = 1;
        while width * 2 <= max_width.max(1) {
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

dispatch! {
    /// Face levels `yr[n]` of the starts `lanes.start + n` of start row
    /// `j0` (all real: `lanes.start >= 0`): the minimum height over the
    /// nodes inside the footprint, `+inf` where none is finite (the start
    /// is not placed).
    pub fn push_lanes(grid: &PaddedGrid, table: &WindowMin, fp: &GridFootprint, j0: usize, lanes: std::ops::Range<i64>, yr: &mut [f64]) => push_lanes_impl
}

#[inline(always)]
fn push_lanes_impl(grid: &PaddedGrid, table: &WindowMin, fp: &GridFootprint, j0: usize, lanes: std::ops::Range<i64>, yr: &mut [f64]) {
    debug_assert!(lanes.start >= 0 && yr.len() == (lanes.end - lanes.start) as usize);
    yr.fill(f64::INFINITY);
    let from = lanes.start as usize;
    for row in &fp.rows {
        if row.khi < row.klo {
            continue;
        }
        let Some(j) = grid.row_of(j0, row.dj) else { continue };
        let width = (row.khi - row.klo + 1) as usize;
        let level = width.ilog2() as usize;
        let second = width - (1 << level);
        let t = &table.levels[level];
        let start = grid.index(j, row.klo) + from;
        let first = &t[start..start + yr.len()];
        let last = &t[start + second..start + second + yr.len()];
        for ((y, &u), &v) in yr.iter_mut().zip(first).zip(last) {
            *y = fmin(*y, fmin(u, v));
        }
    }
}

/// The paper's push for one start, literally: the minimum over every node
/// inside the footprint.
pub fn push_start_literal(grid: &PaddedGrid, fp: &GridFootprint, i0: usize, j0: usize) -> f64 {
    let mut yr = f64::INFINITY;
    for row in &fp.rows {
        let Some(j) = grid.row_of(j0, row.dj) else { continue };
        for k in row.klo..=row.khi {
            yr = fmin(yr, grid.h[grid.index(j, k) + i0]);
        }
    }
    yr
}
