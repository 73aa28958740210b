//! The grid engine's driver: for every angle, push and slide every start
//! and collect the colliding mask `C_theta`; then the composite count.
//!
//! Work is split across angles and, within an angle, across bands of start
//! rows, each band ORing into its own mask. OR is order-independent, so the
//! masks are identical whatever the thread count.
//!
//! **Invariant:** the engine does no I/O and reads no clock; progress is
//! reported through a callback.

use rayon::prelude::*;

use crate::grid::HeightGrid;
use crate::kneeform::GridFootprint;
use crate::padded::PaddedGrid;
use crate::paper::{PaperCounts, PaperScratch, paper_row};
use crate::push::{PushRows, WindowMin, push_block};
use crate::simd::dispatch;
use crate::slide::{LayerRows, slide_block, slide_carried};
use crate::strike::StrikeRule;

/// Which implementation of push and slide to run. Both give identical masks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum Algorithm {
    /// The paper's sections 3 and 4, literally: the reference and baseline.
    Paper,
    /// Sliding-window-minimum push and the one-layer streaming slide.
    Fast,
}

/// How to run the engine.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineOptions {
    /// SPEC's strike rule: rounding tolerance `e0` and deflection
    /// threshold `sigma`.
    pub rule: StrikeRule,
    /// The implementation.
    pub algorithm: Algorithm,
    /// Start rows to run (`None`: all). The benchmark runs the paper
    /// algorithm on a sample of rows.
    pub start_rows: Option<Vec<usize>>,
    /// Cells to probe (fast path only): whether the knee-form's face meets
    /// each at a level its `y` sticks out past ([`AngleMask::probes_met`]).
    pub probes: Vec<Probe>,
}

/// A grid cell and a height in it: a point of the part between the
/// cell's four corner nodes (a blind spot's lowest point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// The cell's first corner node `(i, j)`; it spans `i..=i + 1` and
    /// `j..=j + 1`.
    pub cell: (usize, usize),
    /// The height (mm).
    pub y: f64,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions {
            rule: StrikeRule::default(),
            algorithm: Algorithm::Fast,
            start_rows: None,
            probes: Vec::new(),
        }
    }
}

/// The result at one angle.
#[derive(Debug, Clone, PartialEq)]
pub struct AngleMask {
    /// The angle (degrees).
    pub angle_deg: f64,
    /// `mask[j * nx + i]` is 1 where the node is colliding.
    pub mask: Vec<u8>,
    /// Number of placed starts.
    pub placed: usize,
    /// Number of colliding nodes.
    pub colliding: usize,
    /// Per probe of [`EngineOptions::probes`]: whether a face level that met
    /// one of the cell's corner nodes lies past the probe's height by more
    /// than `e0` (its point would be a contact). All false on the paper
    /// path, which keeps no levels.
    pub probes_met: Vec<bool>,
}

/// Starts per block of the fast path: four AVX-512 registers of levels
/// (32 lanes), four AVX2 ones (16). A block is swept over every start row
/// before the next, so the heights it reads (the footprint's rows at the
/// block's columns) stay in cache from one start row to the next. Measured
/// on the benchmark: AVX-512 6.8 s at 32 lanes against 8.0 s at 16; AVX2
/// 9.4 s at 16 against 10.7 s at 32 (register spills).
const LANES: usize = 16;

/// Runs push and slide for every footprint (one per angle) on `grid`.
/// `on_angle` is called once per finished angle (for a progress bar).
///
/// # Panics
///
/// When a footprint was laid on a grid of another pitch
/// ([`GridFootprint::new`] takes the grid's spec): its rows would be
/// offsets on the wrong lattice.
pub fn colliding_masks(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    options: &EngineOptions,
    on_angle: &(dyn Fn() + Sync),
) -> Vec<AngleMask> {
    assert_same_pitch(grid, footprints);
    let padded = PaddedGrid::new(grid, footprints);
    let table = match options.algorithm {
        Algorithm::Fast => Some(WindowMin::new(&padded, WindowMin::max_width(footprints))),
        Algorithm::Paper => None,
    };
    let rows: Vec<usize> = match &options.start_rows {
        Some(rows) => rows.iter().copied().filter(|&j| j < grid.spec.nz).collect(),
        None => (0..grid.spec.nz).collect(),
    };
    // Enough independent tasks to keep every thread busy: whole angles when
    // there are many, bands of start rows when there are few. Start rows
    // are independent, so any split gives the same masks.
    let bands = rayon::current_num_threads()
        .div_ceil(footprints.len().max(1))
        .max(1)
        * 2
        - 1;
    let band_len = rows.len().div_ceil(bands).max(1);
    footprints
        .par_iter()
        .map(|fp| {
            let no_levels = || vec![f64::NEG_INFINITY; options.probes.len()];
            let (padded_mask, placed, probe_levels) = rows
                .par_chunks(band_len)
                .map(|band| match &table {
                    Some(table) => {
                        let mut reach = vec![f64::NEG_INFINITY; padded.h.len()];
                        let placed = fast_band(&padded, table, fp, band, &mut reach);
                        let mask = strike_mask(&padded, &reach, &options.rule);
                        (mask, placed, probe_levels(&padded, &reach, &options.probes))
                    }
                    None => {
                        let mut mask = vec![0u8; padded.h.len()];
                        let placed = paper_band(&padded, fp, band, &options.rule, &mut mask);
                        (mask, placed, no_levels())
                    }
                })
                .reduce(
                    || (vec![0u8; padded.h.len()], 0, no_levels()),
                    |(mut a, pa, mut la), (b, pb, lb)| {
                        a.iter_mut().zip(&b).for_each(|(x, y)| *x |= y);
                        la.iter_mut().zip(&lb).for_each(|(x, y)| *x = x.max(*y));
                        (a, pa + pb, la)
                    },
                );
            let mask = padded.unpad(&padded_mask);
            on_angle();
            AngleMask {
                angle_deg: fp.angle_deg,
                colliding: mask.iter().filter(|&&m| m != 0).count(),
                mask,
                placed,
                probes_met: options
                    .probes
                    .iter()
                    .zip(&probe_levels)
                    .map(|(probe, &level)| probe.y < level - options.rule.e0)
                    .collect(),
            }
        })
        .collect()
}

/// Per probe, the highest face level that met one of its cell's corners
/// in this band (`-inf` where none did).
fn probe_levels(padded: &PaddedGrid, reach: &[f64], probes: &[Probe]) -> Vec<f64> {
    let nz = padded.spec.nz as i64;
    probes
        .iter()
        .map(|probe| {
            let (i, j) = (probe.cell.0 as i64, probe.cell.1 as i64);
            [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
                .into_iter()
                .filter(|&(_, jj)| jj < nz)
                .map(|(ii, jj)| reach[padded.index(jj, ii as i32)])
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .collect()
}

/// Refuses footprints laid on a grid of another pitch than `grid`'s.
pub(crate) fn assert_same_pitch(grid: &HeightGrid, footprints: &[GridFootprint]) {
    for fp in footprints {
        assert!(
            fp.pitch == grid.spec.pitch,
            "a footprint laid at pitch {} mm used on a {} mm grid",
            fp.pitch,
            grid.spec.pitch
        );
    }
}

dispatch! {
    /// The fast path over a band of start rows: blocks of starts (32 with
    /// AVX-512, else [`LANES`]) from +x to -x, each swept over every start row of the band, carrying
    /// each row's slide level from one block into the next. Records each
    /// node's reach (see [`crate::slide`]) and returns the number of placed
    /// starts.
    fn fast_band(padded: &PaddedGrid, table: &WindowMin, fp: &GridFootprint, band: &[usize], reach: &mut [f64]) -> usize => fast_band_impl::<32, 16, 16>
}

#[inline(always)]
fn fast_band_impl<const W: usize>(
    padded: &PaddedGrid,
    table: &WindowMin,
    fp: &GridFootprint,
    band: &[usize],
    reach: &mut [f64],
) -> usize {
    let push_rows = PushRows::new(padded, fp);
    let layer = LayerRows::new(padded, fp);
    let active: Vec<std::ops::Range<i64>> = band
        .iter()
        .map(|&j0| padded.active_starts(j0, fp))
        .collect();
    let lo = active
        .iter()
        .filter(|r| !r.is_empty())
        .map(|r| r.start)
        .min();
    let hi = active.iter().filter(|r| !r.is_empty()).map(|r| r.end).max();
    let (Some(lo), Some(hi)) = (lo, hi) else {
        return 0;
    };
    let nx = padded.spec.nx as i64;
    let mut carry = vec![f64::NEG_INFINITY; band.len()];
    let mut placed = 0;
    let mut block_end = hi;
    while block_end > lo {
        // The block may reach below `lo`: those starts do nothing, and the
        // padding's slack keeps them inside the array.
        let block = block_end - W as i64;
        for (k, &j0) in band.iter().enumerate() {
            if active[k].is_empty() || block >= active[k].end || block_end <= active[k].start {
                continue;
            }
            let base = padded
                .index(j0 as i64, 0)
                .wrapping_add_signed(block as isize);
            let yr: [f64; W] = push_block(table, &push_rows, base);
            // Only real starts are placed.
            let mut level = [f64::NEG_INFINITY; W];
            for w in 0..W {
                let i0 = block + w as i64;
                if (0..nx).contains(&i0) && yr[w].is_finite() {
                    level[w] = yr[w];
                    placed += 1;
                }
            }
            let (after, layer_min) = slide_block(&padded.h, reach, &layer, base, level);
            // Starts that are not placed continue the slide of the start on
            // their +x side, from +x to -x.
            let mut c = carry[k];
            for w in (0..W).rev() {
                if level[w] != f64::NEG_INFINITY {
                    c = after[w];
                } else if c != f64::NEG_INFINITY && layer_min[w] != f64::INFINITY {
                    c = slide_carried(&padded.h, reach, &layer, base + w, c);
                }
            }
            carry[k] = c;
        }
        block_end = block;
    }
    placed
}

/// SPEC's strike rule applied once per node to its reach, the highest face
/// level that met it (`-inf`: never met). The rule is monotone in the
/// level, so this is the union of the strikes of every slide that met the
/// node. The node behind `n` is `n + 1` (the next column; the padding's
/// `+inf` past the grid's +x edge).
fn strike_mask(padded: &PaddedGrid, reach: &[f64], rule: &StrikeRule) -> Vec<u8> {
    let p = padded.spec.pitch;
    let h = &padded.h;
    let mut mask: Vec<u8> = h
        .windows(2)
        .zip(reach)
        .map(|(w, &r)| u8::from(rule.strikes(w[0], w[1], r, p)))
        .collect();
    // The last padded node is padding (`+inf`), never struck.
    mask.push(0);
    mask
}

/// The paper algorithm over a band of start rows.
fn paper_band(
    padded: &PaddedGrid,
    fp: &GridFootprint,
    band: &[usize],
    rule: &StrikeRule,
    mask: &mut [u8],
) -> usize {
    let mut scratch = PaperScratch::default();
    let mut counts = PaperCounts::default();
    band.iter()
        .map(|&j0| paper_row(padded, fp, j0, rule, mask, &mut scratch, &mut counts))
        .sum()
}

/// SPEC's push alone, for every start at one angle: `yr[j * nx + i]` (mm),
/// `+inf` where the start is not placed. For comparisons with the exact
/// oracle; [`colliding_masks`] computes these on the way.
pub fn push_levels(grid: &HeightGrid, fp: &GridFootprint) -> Vec<f64> {
    assert_same_pitch(grid, std::slice::from_ref(fp));
    let padded = PaddedGrid::new(grid, std::slice::from_ref(fp));
    let table = WindowMin::new(&padded, WindowMin::max_width(std::slice::from_ref(fp)));
    let rows = PushRows::new(&padded, fp);
    let nx = grid.spec.nx;
    let mut yr = vec![f64::INFINITY; grid.spec.len()];
    for (j0, out) in yr.chunks_exact_mut(nx).enumerate() {
        for (block, out) in out.chunks_mut(LANES).enumerate() {
            // The padding's slack covers the lanes past the last column.
            let levels: [f64; LANES] =
                push_block(&table, &rows, padded.index(j0 as i64, 0) + block * LANES);
            out.copy_from_slice(&levels[..out.len()]);
        }
    }
    yr
}

/// SPEC's composite: for every node, the number of angles whose mask holds it.
pub fn composite(masks: &[AngleMask]) -> Vec<u16> {
    let n = masks.first().map_or(0, |m| m.mask.len());
    let mut count = vec![0u16; n];
    for m in masks {
        for (c, &v) in count.iter_mut().zip(&m.mask) {
            *c += u16::from(v);
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::kneeform::KneeForm;

    /// The block width is a tuning knob per instruction set: every width
    /// gives the same reach and placed count (the tests elsewhere run only
    /// the width this machine's instruction set picks).
    #[test]
    fn every_block_width_gives_the_same_result() {
        let spec = GridSpec {
            pitch: 2.5,
            i_origin: -40,
            j_origin: -20,
            nx: 150,
            nz: 60,
        };
        let h: Vec<f64> = (0..spec.len())
            .map(|n| {
                let (x, z) = (spec.x(n % spec.nx), spec.z(n / spec.nx));
                let hole = (x - 60.0).hypot(z - 10.0) < 25.0;
                if hole {
                    f64::INFINITY
                } else {
                    0.1 * x + 3.0 * (0.07 * x).sin() * (0.05 * z).cos()
                }
            })
            .collect();
        let grid = HeightGrid { spec, h };
        let knee = KneeForm {
            triangle_side: 80.0,
            radius: 20.0,
            thickness: 100.0,
        };
        let rows: Vec<usize> = (0..spec.nz).collect();
        for angle in [-30.0, 0.0, 17.0] {
            let fp = GridFootprint::new(&knee, angle, &spec);
            let padded = PaddedGrid::new(&grid, std::slice::from_ref(&fp));
            let table = WindowMin::new(&padded, 512);
            let run =
                |f: fn(&PaddedGrid, &WindowMin, &GridFootprint, &[usize], &mut [f64]) -> usize| {
                    let mut reach = vec![f64::NEG_INFINITY; padded.h.len()];
                    let placed = f(&padded, &table, &fp, &rows, &mut reach);
                    (reach, placed)
                };
            let w16 = run(fast_band_impl::<16>);
            assert!(w16.1 > 0);
            assert!(run(fast_band_impl::<8>) == w16, "angle {angle}: 8 lanes");
            assert!(run(fast_band_impl::<32>) == w16, "angle {angle}: 32 lanes");
        }
    }
}
