//! The height grid with `+inf` margins around it, wide enough that push and
//! slide can index any footprint offset of any start (and of the virtual
//! starts past the grid's -x edge) without a bounds branch in their inner
//! loops. Nodes outside the grid do not exist; `+inf` is exactly how SPEC's
//! rules treat them (never inside a push minimum, never colliding, never
//! lowering the face level).

use crate::grid::{GridSpec, HeightGrid};
use crate::kneeform::GridFootprint;

/// Extra margin columns on each side, so that a whole block of starts may
/// run past the active range without leaving the padding.
pub(crate) const LANE_SLACK: usize = 128;

/// A height grid with padded rows and columns.
#[derive(Debug)]
pub(crate) struct PaddedGrid {
    /// The grid's nodes.
    pub spec: GridSpec,
    /// Padding columns before column 0.
    pub pad_lo: usize,
    /// Padding rows before row 0.
    pub pad_rows: usize,
    /// Length of a padded row.
    pub stride: usize,
    /// Heights, `h[(j + pad_rows) * stride + pad_lo + i]`.
    pub h: Vec<f64>,
    /// Per grid row, the first and last column with a finite height.
    pub finite_span: Vec<Option<(i32, i32)>>,
}

/// The range of start columns, real and virtual, whose first layer (the
/// first node in front in each footprint row) can fall inside the grid:
/// from the last virtual start past the -x edge up to the last real start.
pub(crate) fn start_lanes(fp: &GridFootprint, nx: usize) -> std::ops::Range<i64> {
    let kf_max = fp.rows.iter().map(|r| r.kf).max().unwrap_or(0);
    (-i64::from(kf_max)).min(0)..nx as i64
}

/// The padding [`PaddedGrid::new`] gives a grid for some footprints,
/// known before anything is allocated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Padding {
    /// Padding columns before column 0.
    pub pad_lo: usize,
    /// Padding rows before row 0 (and after the last).
    pub pad_rows: usize,
    /// Length of a padded row.
    pub stride: usize,
}

impl Padding {
    /// The padding of `spec` for all of `footprints`, for slides that
    /// reach `depth` columns past their first layer (the window rule's,
    /// [`crate::engine::slide::window_depth`]).
    pub fn deep(spec: &GridSpec, footprints: &[GridFootprint], depth: usize) -> Padding {
        let nx = spec.nx;
        let (mut lo, mut hi, mut dj_max) = (0i64, 0i64, 0i64);
        for fp in footprints {
            let (k_lo, k_hi) = fp.k_range();
            let lanes = start_lanes(fp, nx);
            lo = lo.min(lanes.start + i64::from(k_lo)).min(i64::from(k_lo));
            hi = hi.max(i64::from(k_hi));
            let (dj_lo, dj_hi) = fp.dj_range();
            dj_max = dj_max
                .max(i64::from(dj_lo).abs())
                .max(i64::from(dj_hi).abs());
        }
        let pad_lo = (-lo) as usize + depth + LANE_SLACK;
        Padding {
            pad_lo,
            pad_rows: dj_max as usize,
            stride: pad_lo + nx + hi as usize + 1 + LANE_SLACK,
        }
    }

    /// Nodes of the padded grid of `spec`.
    pub fn nodes(&self, spec: &GridSpec) -> usize {
        self.stride * (spec.nz + 2 * self.pad_rows)
    }
}

impl PaddedGrid {
    /// Pads `grid` for all of `footprints`.
    pub fn new(grid: &HeightGrid, footprints: &[GridFootprint]) -> PaddedGrid {
        PaddedGrid::deep(grid, footprints, 0)
    }

    /// Pads `grid` for all of `footprints` and slides `depth` columns past
    /// their first layer ([`Padding::deep`]).
    pub fn deep(grid: &HeightGrid, footprints: &[GridFootprint], depth: usize) -> PaddedGrid {
        let GridSpec { nx, nz, .. } = grid.spec;
        let Padding {
            pad_lo,
            pad_rows,
            stride,
        } = Padding::deep(&grid.spec, footprints, depth);
        let mut h = vec![f64::INFINITY; stride * (nz + 2 * pad_rows)];
        for (dst, src) in h[pad_rows * stride..]
            .chunks_exact_mut(stride)
            .zip(grid.h.chunks_exact(nx))
        {
            dst[pad_lo..pad_lo + nx].copy_from_slice(src);
        }
        let finite_span = grid
            .h
            .chunks_exact(nx)
            .map(|row| {
                let first = row.iter().position(|h| h.is_finite())?;
                let last = row.iter().rposition(|h| h.is_finite())?;
                Some((first as i32, last as i32))
            })
            .collect();
        PaddedGrid {
            spec: grid.spec,
            pad_lo,
            pad_rows,
            stride,
            h,
            finite_span,
        }
    }

    /// The grid row `j0 + dj`, if it exists.
    pub fn row_of(&self, j0: usize, dj: i32) -> Option<usize> {
        let j = j0 as i64 + i64::from(dj);
        (0..self.spec.nz as i64).contains(&j).then_some(j as usize)
    }

    /// Index of column offset `k` of row `j` for the start at column 0; add
    /// the start's column to reach the node. `j` may be a padding row
    /// (negative, or `nz` and beyond) within the footprint's reach.
    pub fn index(&self, j: i64, k: i32) -> usize {
        let row = (j + self.pad_rows as i64) as usize;
        (row * self.stride + self.pad_lo).wrapping_add_signed(k as isize)
    }

    /// Offset from a start's node index to the node `(dj, k)` away from it.
    pub fn offset(&self, dj: i32, k: i32) -> isize {
        dj as isize * self.stride as isize + k as isize
    }

    /// The start columns of start row `j0` that can do anything at all:
    /// outside it, no start is placed (no finite height inside its
    /// footprint), and no first layer holds a finite height, so on its -x
    /// side a carried slide strikes nothing and on its +x side no slide has
    /// begun. Conservative: it may be wider than needed, never narrower.
    pub fn active_starts(&self, j0: usize, fp: &GridFootprint) -> std::ops::Range<i64> {
        let (mut lo, mut hi) = (i64::MAX, i64::MIN);
        for row in &fp.rows {
            let Some(j) = self.row_of(j0, row.dj) else {
                continue;
            };
            if let Some((first, last)) = self.finite_span[j] {
                // khi >= kf, so a start left of `first - khi` has even its
                // first layer left of the row's first finite node.
                lo = lo.min(i64::from(first) - i64::from(row.khi));
                hi = hi.max(i64::from(last) - i64::from(row.klo));
            }
        }
        let lanes = start_lanes(fp, self.spec.nx);
        let lo = lo.max(lanes.start);
        lo..(hi + 1).min(lanes.end).max(lo)
    }

    /// Drops the padding of a padded per-node array.
    #[cfg(test)]
    pub fn unpad<T: Copy>(&self, padded: &[T]) -> Vec<T> {
        let GridSpec { nx, nz, .. } = self.spec;
        padded[self.pad_rows * self.stride..]
            .chunks_exact(self.stride)
            .take(nz)
            .flat_map(|row| &row[self.pad_lo..self.pad_lo + nx])
            .copied()
            .collect()
    }
}

/// The smaller of two heights; written as a comparison so that loops over
/// it compile to packed `min` instructions (`f64::min` handles NaN, which
/// heights never are, and does not vectorise as well).
#[inline(always)]
pub(crate) fn fmin(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}
