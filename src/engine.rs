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
use crate::push::{WindowMin, push_lanes};
use crate::slide::{SlideScratch, slide_lanes};

/// Which implementation of push and slide to run. Both give identical masks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
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
    /// SPEC's contact tolerance `eps` (mm): a node collides when its height
    /// is below the face level by more than this.
    pub eps: f64,
    /// The implementation.
    pub algorithm: Algorithm,
    /// Start rows to run (`None`: all). The benchmark runs the paper
    /// algorithm on a sample of rows.
    pub start_rows: Option<Vec<usize>>,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions {
            eps: 1e-3,
            algorithm: Algorithm::Fast,
            start_rows: None,
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
}

/// Starts per block of the fast path. A block of starts is swept over
/// every start row before the next block: the heights it reads (the
/// footprint's rows at the block's columns, about `(BLOCK + 240) x 260`
/// values at 1.24 mm) then stay in a 2 MiB L2 cache, each loaded once and
/// used by some 260 start rows. Without blocking the engine is bound by
/// memory bandwidth (measured 3x slower on the benchmark).
const BLOCK: i64 = 256;

/// Runs push and slide for every footprint (one per angle) on `grid`.
/// `on_angle` is called once per finished angle (for a progress bar).
pub fn colliding_masks(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    options: &EngineOptions,
    on_angle: &(dyn Fn() + Sync),
) -> Vec<AngleMask> {
    let padded = PaddedGrid::new(grid, footprints);
    let table = match options.algorithm {
        Algorithm::Fast => {
            let max_width = footprints
                .iter()
                .flat_map(|fp| fp.rows.iter().map(|r| (r.khi - r.klo + 1).max(1) as usize))
                .max()
                .unwrap_or(1);
            Some(WindowMin::new(&padded, max_width))
        }
        Algorithm::Paper => None,
    };
    let rows: Vec<usize> = match &options.start_rows {
        Some(rows) => rows.iter().copied().filter(|&j| j < grid.spec.nz).collect(),
        None => (0..grid.spec.nz).collect(),
    };
    // Enough independent tasks to keep every thread busy: whole angles when
    // there are many, bands of start rows when there are few. Start rows
    // are independent, so any split gives the same masks.
    let bands = rayon::current_num_threads().div_ceil(footprints.len().max(1)).max(1) * 2 - 1;
    let band_len = rows.len().div_ceil(bands).max(1);
    footprints
        .par_iter()
        .map(|fp| {
            let (padded_mask, placed) = rows
                .par_chunks(band_len)
                .map(|band| {
                    let mut mask = vec![0u8; padded.h.len()];
                    let placed = match &table {
                        Some(table) => fast_band(&padded, table, fp, band, options.eps, &mut mask),
                        None => paper_band(&padded, fp, band, options.eps, &mut mask),
                    };
                    (mask, placed)
                })
                .reduce(
                    || (vec![0u8; padded.h.len()], 0),
                    |(mut a, pa), (b, pb)| {
                        a.iter_mut().zip(&b).for_each(|(x, y)| *x |= y);
                        (a, pa + pb)
                    },
                );
            let mask = unpad(&padded, &padded_mask);
            on_angle();
            AngleMask {
                angle_deg: fp.angle_deg,
                colliding: mask.iter().filter(|&&m| m != 0).count(),
                mask,
                placed,
            }
        })
        .collect()
}

/// The fast path over a band of start rows: blocks of [`BLOCK`] starts from
/// +x to -x, each swept over every start row of the band, carrying each
/// row's slide level from one block into the next. Returns the number of
/// placed starts.
fn fast_band(padded: &PaddedGrid, table: &WindowMin, fp: &GridFootprint, band: &[usize], eps: f64, mask: &mut [u8]) -> usize {
    let active: Vec<std::ops::Range<i64>> = band.iter().map(|&j0| padded.active_starts(j0, fp)).collect();
    let lo = active.iter().filter(|r| !r.is_empty()).map(|r| r.start).min();
    let hi = active.iter().filter(|r| !r.is_empty()).map(|r| r.end).max();
    let (Some(lo), Some(hi)) = (lo, hi) else { return 0 };
    let mut carry = vec![f64::NEG_INFINITY; band.len()];
    let mut yr = Vec::with_capacity(BLOCK as usize);
    let mut scratch = SlideScratch::default();
    let mut placed = 0;
    let mut block_end = hi;
    while block_end > lo {
        let block = (block_end - BLOCK).max(lo)..block_end;
        for (k, &j0) in band.iter().enumerate() {
            let lanes = block.start.max(active[k].start)..block.end.min(active[k].end);
            if lanes.is_empty() {
                continue;
            }
            // Virtual starts (left of column 0) are never placed.
            let real = lanes.start.max(0)..lanes.end.max(0);
            let virtual_lanes = (real.start - lanes.start) as usize;
            yr.clear();
            yr.resize((lanes.end - lanes.start) as usize, f64::INFINITY);
            if !real.is_empty() {
                push_lanes(padded, table, fp, j0, real, &mut yr[virtual_lanes..]);
                placed += yr.iter().filter(|y| y.is_finite()).count();
            }
            carry[k] = slide_lanes(padded, fp, j0, lanes, &yr, carry[k], eps, mask, &mut scratch);
        }
        block_end = block.start;
    }
    placed
}

/// The paper algorithm over a band of start rows.
fn paper_band(padded: &PaddedGrid, fp: &GridFootprint, band: &[usize], eps: f64, mask: &mut [u8]) -> usize {
    let mut scratch = PaperScratch::default();
    let mut counts = PaperCounts::default();
    band.iter()
        .map(|&j0| paper_row(padded, fp, j0, eps, mask, &mut scratch, &mut counts))
        .sum()
}

/// Drops the padding columns of a padded mask.
fn unpad(padded: &PaddedGrid, mask: &[u8]) -> Vec<u8> {
    let nx = padded.spec.nx;
    mask.chunks_exact(padded.stride)
        .flat_map(|row| &row[padded.pad_lo..padded.pad_lo + nx])
        .copied()
        .collect()
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
