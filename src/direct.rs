//! The direct approach (`--approach direct`), push-and-slide's predecessor
//! (Inui et al., instrument-panel knee contact): the knee-form comes from
//! far in +x and moves in -x until it first touches the part; the
//! contacted area is the set of first-contact points over every knee
//! position and angle.
//!
//! # Frames
//!
//! In SPEC's analysis frame (the part placed by `--frame` and `--side`)
//! the knee moves in -x and the analysed surface faces +x. The part is
//! turned into the **direct frame** by the proper rotation
//! `D: (x, y, z) -> (x', y', z') = (y, -x, z)` (`to_direct`), where the
//! knee moves in +y' and the surface faces -y', so that SPEC's height grid
//! ([`crate::grid::HeightGrid`], the z-buffer from -y) sampled on the
//! turned part is the depth grid of the direct approach:
//! `h(x', z') = min y' = -(max x)` over the line, the first surface the
//! knee meets. Results go back by `D^-1: (x', y', z') -> (-y', x', z')`
//! (`from_direct`, exact: only a sign and a swap), then by
//! [`crate::frame::Placement::to_part`].
//!
//! # The definition
//!
//! A knee **position** is a grid node `(i0, j0)`: the knee's width `W` is
//! centred on `x'_i0` (it covers `|x' - x'_i0| <= W/2`, i.e. the part's
//! `y` in `[y0 - W/2, y0 + W/2]`), its reference point `v0` at height
//! `z_j0`, and `K_theta` is SPEC's cross-section at angle theta (rotated
//! about `v0`). Its leading surface at row offset `dz = z_j - z_j0` is at
//! `y' = Y - a(dz)` (`Y` the reference point's `y'`), where `a(dz)` is
//! the left end of SPEC's row interval ([`Footprint::row_interval`]: the
//! smallest x of `K_theta` on the line `z = dz`, relative to `v0`).
//!
//! * **Footprint**: the nodes `(i0 + k, j0 + dj)` with `|k| p <= W/2 +
//!   1e-9` mm and `dj p` within `K_theta`'s z-range (closed within
//!   `NODE_TOL`, as SPEC's rows). Nodes off the grid are `+inf`.
//! * **First contact**: `Y*(i0, j0) = min (h[i][j] + a(dz))` over the
//!   footprint's nodes (`+inf` heights never win). A position whose
//!   footprint holds no finite height is **not placed**.
//! * **Contacts (ties)**: every footprint node with a finite height and
//!   `h[i][j] + a(dz) <= Y* + e0` (`e0`: SPEC's rounding tolerance, default
//!   1e-6 mm): the points touched at first contact.
//! * The mask of an angle is the union of its placed positions' contacts;
//!   the composite, the areas and the outputs are the slide's.
//!
//! The deflection threshold and the rate rule play no part: the knee does
//! not slide. The knee's width `W` does (the slide ignores it).
//!
//! # The fast form, and why it is exact
//!
//! `Y*` is a grey-scale erosion of `h` by the knee's front, separable: a
//! flat sliding-window minimum along x' over the width (the push's window
//! minima, here with van Herk's blocks), then per footprint row `dj` the
//! minimum of `window(h)[j0 + dj] + a(dj p)`. The contacts are found
//! without visiting each position's footprint again: node `(i, j)` is a
//! contact of some position iff for some row `dj`,
//! `h + a <= max(Y* + e0)` over the positions `i0` of row `j - dj` whose
//! width covers `i`: a sliding-window maximum of `Y*`. Both forms compute
//! `h + a` and `Y* + e0` with the same operands, and rounding is monotone
//! (`x <= y` implies `fl(x + c) <= fl(y + c)`), so the minimum and maximum
//! can be taken before or after the addition: the fast form gives the
//! brute force's masks to the bit (`tests/direct.rs`).

use rayon::prelude::*;

use crate::engine::{AngleMask, Probe};
use crate::grid::NODE_TOL;
use crate::grid::{GridSpec, HeightGrid};
use crate::kneeform::{Footprint, KneeForm};
use crate::mesh::Bbox;

/// The knee-form's front at one angle, laid on a grid of pitch `pitch`:
/// the half width in nodes and, per footprint row, its offset `a`.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectFootprint {
    /// The angle (degrees).
    pub angle_deg: f64,
    /// The pitch of the grid it is laid on (mm).
    pub pitch: f64,
    /// The largest `k` with `k p <= W/2 + NODE_TOL`: the width covers
    /// `i0 - half_width ..= i0 + half_width`.
    pub half_width: usize,
    /// Per footprint row, `(dj, a(dj p))`: the row offset and the left end
    /// of `K_theta`'s row interval (mm, relative to the reference point),
    /// in increasing `dj`.
    pub rows: Vec<(i32, f64)>,
}

impl DirectFootprint {
    /// The front of `knee` at `angle_deg` on a grid of pitch `pitch` (mm).
    pub fn new(knee: &KneeForm, angle_deg: f64, pitch: f64) -> DirectFootprint {
        let fp = Footprint::new(knee, angle_deg);
        let (zlo, zhi) = fp.z_range();
        let lo = ((zlo - NODE_TOL) / pitch).floor() as i32;
        let hi = ((zhi + NODE_TOL) / pitch).ceil() as i32;
        let rows = (lo..=hi)
            .filter_map(|dj| fp.row_interval(f64::from(dj) * pitch).map(|(a, _)| (dj, a)))
            .collect();
        let reach = knee.thickness / 2.0 + NODE_TOL;
        let mut half_width = (reach / pitch).floor() as usize;
        while (half_width + 1) as f64 * pitch <= reach {
            half_width += 1;
        }
        while half_width > 0 && half_width as f64 * pitch > reach {
            half_width -= 1;
        }
        DirectFootprint {
            angle_deg,
            pitch,
            half_width,
            rows,
        }
    }
}

/// The direct approach's default grid for a part whose bounding box in the
/// direct frame is `bbox`: every position whose footprint, at any of
/// `angles` or its mirror, can reach the box. The box grown by `W/2` in x'
/// and by the knee-form's z-extent in z, snapped outwards to multiples of
/// the pitch (as [`crate::kneeform::Footprint::grid_around`] does for the slide).
pub(crate) fn grid_around(bbox: &Bbox, knee: &KneeForm, angles: &[f64], pitch: f64) -> GridSpec {
    let (mut zl, mut zh) = (0.0f64, 0.0f64);
    for &a in angles {
        for fp in [Footprint::new(knee, a), Footprint::new(knee, -a)] {
            let (lo, hi) = fp.z_range();
            zl = zl.min(lo);
            zh = zh.max(hi);
        }
    }
    let half = knee.thickness / 2.0;
    GridSpec::reaching(bbox, (-half, half), (zl, zh), pitch)
}

/// Per grid row, the extreme (`pick`: `f64::min` or `f64::max`) of `row`
/// over the centred window `i - half ..= i + half` clipped to the row, into
/// `out`: van Herk's prefix and suffix extremes in blocks of the window's
/// width, `identity` past the ends.
fn window_extreme(
    row: &[f64],
    half: usize,
    identity: f64,
    pick: fn(f64, f64) -> f64,
    out: &mut [f64],
) {
    let (n, w) = (row.len(), 2 * half + 1);
    let padded: Vec<f64> = std::iter::repeat_n(identity, half)
        .chain(row.iter().copied())
        .chain(std::iter::repeat_n(identity, half))
        .collect();
    let m = padded.len();
    let mut prefix = padded.clone();
    let mut suffix = padded;
    for k in 1..m {
        if k % w != 0 {
            prefix[k] = pick(prefix[k], prefix[k - 1]);
        }
    }
    for k in (0..m - 1).rev() {
        if (k + 1) % w != 0 {
            suffix[k] = pick(suffix[k], suffix[k + 1]);
        }
    }
    for (i, o) in out.iter_mut().enumerate().take(n) {
        *o = pick(suffix[i], prefix[i + w - 1]);
    }
}

/// The first-contact level `Y*` of every position (mm, direct frame:
/// the reference point's y'), `h[j * nx + i]` order; `+inf` where the
/// position is not placed.
///
/// # Panics
///
/// When `fp` was laid on a grid of another pitch.
pub fn contact_levels(grid: &HeightGrid, fp: &DirectFootprint) -> Vec<f64> {
    assert_eq!(
        fp.pitch, grid.spec.pitch,
        "a direct footprint laid on a grid of another pitch"
    );
    let (nx, nz) = (grid.spec.nx, grid.spec.nz);
    let mut window = vec![f64::INFINITY; nx * nz];
    window
        .par_chunks_mut(nx.max(1))
        .zip(grid.h.par_chunks(nx.max(1)))
        .for_each(|(out, row)| window_extreme(row, fp.half_width, f64::INFINITY, f64::min, out));
    let mut levels = vec![f64::INFINITY; nx * nz];
    levels
        .par_chunks_mut(nx.max(1))
        .enumerate()
        .for_each(|(j0, out)| {
            for &(dj, a) in &fp.rows {
                let Some(j) = offset(j0, dj, nz) else {
                    continue;
                };
                for (y, &m) in out.iter_mut().zip(&window[j * nx..(j + 1) * nx]) {
                    *y = y.min(m + a);
                }
            }
        });
    levels
}

/// Row `j0 + dj` when it is on a grid of `nz` rows.
fn offset(j0: usize, dj: i32, nz: usize) -> Option<usize> {
    let j = j0 as i64 + i64::from(dj);
    (0..nz as i64).contains(&j).then_some(j as usize)
}

/// The direct approach at one angle: the contacts of every placed
/// position ([`contact_levels`], then the module's fast form), with
/// rounding tolerance `e0` (mm). `probes` (cells with a point between
/// their corner nodes, direct frame) are met when some position whose
/// footprint covers a corner would have touched the probe's point before
/// its first contact, by more than `e0`.
pub fn direct_mask(
    grid: &HeightGrid,
    fp: &DirectFootprint,
    e0: f64,
    probes: &[Probe],
) -> AngleMask {
    let (nx, nz) = (grid.spec.nx, grid.spec.nz);
    let levels = contact_levels(grid, fp);
    let placed = levels.iter().filter(|y| y.is_finite()).count();
    // Per row of positions, the largest `Y* + e0` over the positions whose
    // width covers each node; `-inf` where none is placed.
    let mut reach = vec![f64::NEG_INFINITY; nx * nz];
    reach
        .par_chunks_mut(nx.max(1))
        .zip(levels.par_chunks(nx.max(1)))
        .for_each(|(out, row)| {
            let placed: Vec<f64> = row
                .iter()
                .map(|&y| if y.is_finite() { y } else { f64::NEG_INFINITY })
                .collect();
            window_extreme(&placed, fp.half_width, f64::NEG_INFINITY, f64::max, out);
            for r in out.iter_mut() {
                *r += e0;
            }
        });
    let mut mask = vec![0u8; nx * nz];
    mask.par_chunks_mut(nx.max(1))
        .enumerate()
        .for_each(|(j, out)| {
            let h = &grid.h[j * nx..(j + 1) * nx];
            for &(dj, a) in &fp.rows {
                // The positions whose row `dj` is node row `j`.
                let Some(j0) = offset(j, -dj, nz) else {
                    continue;
                };
                for ((m, &h), &r) in out.iter_mut().zip(h).zip(&reach[j0 * nx..(j0 + 1) * nx]) {
                    *m |= u8::from(h.is_finite() && h + a <= r);
                }
            }
        });
    let probes_met = probes
        .iter()
        .map(|probe| {
            let (ci, cj) = probe.cell;
            let corners = [(ci, cj), (ci + 1, cj), (ci, cj + 1), (ci + 1, cj + 1)];
            corners.iter().any(|&(i, j)| {
                i < nx
                    && j < nz
                    && fp.rows.iter().any(|&(dj, a)| {
                        offset(j, -dj, nz)
                            .is_some_and(|j0| probe.y + a < reach[j0 * nx + i] - 2.0 * e0)
                    })
            })
        })
        .collect();
    AngleMask::new(fp.angle_deg, mask, placed, probes_met)
}

/// [`direct_mask`] at every angle of `footprints`, in their order, one
/// angle at a time (each angle's rows in parallel, so the working memory
/// is three grids' worth whatever the thread count). `on_angle` is called
/// once per finished angle.
pub(crate) fn direct_masks(
    grid: &HeightGrid,
    footprints: &[DirectFootprint],
    e0: f64,
    probes: &[Probe],
    on_angle: &(dyn Fn() + Sync),
) -> Vec<AngleMask> {
    footprints
        .iter()
        .map(|fp| {
            let mask = direct_mask(grid, fp, e0, probes);
            on_angle();
            mask
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{from_direct, to_direct};

    #[test]
    fn the_rotation_and_its_inverse_are_exact() {
        let p = [1.25, -3.5, 7.0];
        assert_eq!(to_direct(p), [-3.5, -1.25, 7.0]);
        assert_eq!(from_direct(to_direct(p)), p);
    }

    #[test]
    fn window_extremes_match_a_scan() {
        let row = [
            3.0,
            1.0,
            f64::INFINITY,
            4.0,
            1.0,
            5.0,
            9.0,
            2.0,
            6.0,
            5.0,
            3.0,
        ];
        for half in 0..6 {
            let mut got = vec![0.0; row.len()];
            window_extreme(&row, half, f64::INFINITY, f64::min, &mut got);
            let want: Vec<f64> = (0..row.len())
                .map(|i| {
                    row[i.saturating_sub(half)..(i + half + 1).min(row.len())]
                        .iter()
                        .copied()
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            assert_eq!(got, want, "half width {half}");
        }
    }

    #[test]
    fn the_front_at_zero_degrees_is_the_rounded_corner() {
        let knee = KneeForm::default();
        let fp = DirectFootprint::new(&knee, 0.0, 2.0);
        // W = 120: 30 nodes of 2 mm either side.
        assert_eq!(fp.half_width, 30);
        // The corner's disc: a(0) = -R, a(+-R) = 0 along the upper and
        // lower edges' bands only past it.
        let a0 = fp.rows.iter().find(|r| r.0 == 0).unwrap().1;
        assert!((a0 + 60.0).abs() < 1e-12);
        // The z-range is L/2 + R either side: rows -80..=80.
        assert_eq!(fp.rows.first().unwrap().0, -80);
        assert_eq!(fp.rows.last().unwrap().0, 80);
    }
}
