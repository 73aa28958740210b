//! Step 2b of SPEC, the slide, in its streaming one-layer form: the fast
//! path.
//!
//! For one angle and one start row, every start sees the rows in front in
//! the same merged order. A start that is placed has, right after it
//! enters, the face level `M = yr` exactly (every earlier start swept its
//! whole footprint), so it only has to judge its **first layer**: the first
//! node in front in each footprint row, in slide order. The level carries on
//! from the start on its +x side only across starts that are not placed,
//! and on past the grid's -x edge through virtual starts.
//!
//! So the work is one pass over the first layers of all starts of the row,
//! done for all placed starts at once (vectorised across starts: each
//! footprint row is a contiguous run of heights), then a scalar fix-up for
//! the starts that are not placed but carry a level.

use crate::kneeform::GridFootprint;
use crate::padded::{PaddedGrid, fmin};
use crate::simd::dispatch;

/// Scratch space for [`slide_row`], reused across start rows.
#[derive(Debug, Default)]
pub struct SlideScratch {
    level: Vec<f64>,
    layer_min: Vec<f64>,
    group_min: Vec<f64>,
    rows: Vec<usize>,
    groups: Vec<std::ops::Range<usize>>,
}

/// The rows of the footprint that exist for start row `j0`, in slide order,
/// as the padded index of start 0's first-layer node (heights and mask share
/// the layout), and their tie groups.
fn layer_rows(grid: &PaddedGrid, fp: &GridFootprint, j0: usize, scratch: &mut SlideScratch) {
    scratch.rows.clear();
    scratch.groups.clear();
    let mut last_d = f64::NAN;
    for &r in &fp.slide_order {
        let row = &fp.rows[r as usize];
        let Some(j) = grid.row_of(j0, row.dj) else { continue };
        let idx = grid.index(j, row.kf);
        let n = scratch.rows.len();
        if n == 0 || row.d0 - last_d > crate::kneeform::NODE_TOL {
            scratch.groups.push(n..n + 1);
        } else {
            scratch.groups.last_mut().expect("a group is open").end = n + 1;
        }
        last_d = row.d0;
        scratch.rows.push(idx);
    }
}

dispatch! {
    /// Slides the starts `lanes` of start row `j0` at one angle (lanes below
    /// column 0 are the virtual starts past the grid's -x edge) and ORs the
    /// colliding nodes into `mask` (padded like `grid`). `yr[n]` is the push
    /// level of start `lanes.start + n` (`+inf`: not placed; ignored for
    /// virtual starts). `carry` is the level carried in from the start just
    /// right of the lanes (`-inf`: none); the level carried out of the
    /// lowest lane is returned. `eps` is SPEC's contact tolerance (mm).
    #[allow(clippy::too_many_arguments)]
    pub fn slide_lanes(
        grid: &PaddedGrid,
        fp: &GridFootprint,
        j0: usize,
        lanes: std::ops::Range<i64>,
        yr: &[f64],
        carry: f64,
        eps: f64,
        mask: &mut [u8],
        scratch: &mut SlideScratch,
    ) -> f64 => slide_lanes_impl
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn slide_lanes_impl(
    grid: &PaddedGrid,
    fp: &GridFootprint,
    j0: usize,
    lanes: std::ops::Range<i64>,
    yr: &[f64],
    mut carry: f64,
    eps: f64,
    mask: &mut [u8],
    scratch: &mut SlideScratch,
) -> f64 {
    let n = (lanes.end - lanes.start) as usize;
    if n == 0 {
        return carry;
    }
    let shift = lanes.start as isize;
    layer_rows(grid, fp, j0, scratch);
    let SlideScratch {
        level,
        layer_min,
        group_min,
        rows,
        groups,
    } = scratch;
    level.clear();
    level.extend(yr.iter().zip(lanes.clone()).map(|(&y, i0)| if i0 >= 0 && y.is_finite() { y } else { f64::NEG_INFINITY }));
    layer_min.clear();
    layer_min.resize(n, f64::INFINITY);
    group_min.resize(n, f64::INFINITY);

    // Vectorised pass: every placed start judges its first layer from
    // M = yr; the others (level -inf) collide nothing but record whether
    // their layer holds any finite height.
    for g in groups.iter() {
        if g.len() == 1 {
            let idx = rows[g.start].wrapping_add_signed(shift);
            let h = &grid.h[idx..idx + n];
            let out = &mut mask[idx..idx + n];
            for (((&hv, m), lm), o) in h.iter().zip(level.iter_mut()).zip(layer_min.iter_mut()).zip(out) {
                *o |= u8::from(hv < *m - eps);
                *m = fmin(*m, hv);
                *lm = fmin(*lm, hv);
            }
        } else {
            group_min[..n].fill(f64::INFINITY);
            for &idx in &rows[g.clone()] {
                let idx = idx.wrapping_add_signed(shift);
                let h = &grid.h[idx..idx + n];
                let out = &mut mask[idx..idx + n];
                for (((&hv, &m), gm), o) in h.iter().zip(level.iter()).zip(group_min.iter_mut()).zip(out) {
                    *o |= u8::from(hv < m - eps);
                    *gm = fmin(*gm, hv);
                }
            }
            for ((m, lm), &gm) in level.iter_mut().zip(layer_min.iter_mut()).zip(group_min.iter()) {
                *m = fmin(*m, gm);
                *lm = fmin(*lm, gm);
            }
        }
    }

    // Scalar fix-up, from +x to -x: a start that is not placed continues
    // the slide of the start on its +x side with that start's level.
    for lane in (0..n).rev() {
        let i0 = lanes.start + lane as i64;
        if i0 >= 0 && yr[lane].is_finite() {
            carry = level[lane];
            continue;
        }
        if carry == f64::NEG_INFINITY || layer_min[lane] == f64::INFINITY {
            continue;
        }
        for g in groups.iter() {
            let mut gmin = f64::INFINITY;
            for &idx in &rows[g.clone()] {
                let node = idx.wrapping_add_signed(shift) + lane;
                let hv = grid.h[node];
                if hv < carry - eps {
                    mask[node] = 1;
                }
                gmin = fmin(gmin, hv);
            }
            carry = fmin(carry, gmin);
        }
    }
    carry
}
