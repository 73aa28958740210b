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
use crate::push::{WindowMin, push_row};
use crate::slide::{SlideScratch, slide_row};

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

/// Start rows per parallel task: a band of rows shares one mask and one
/// scratch, and is enough work to amortise them.
const BAND_ROWS: usize = 8;

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
    footprints
        .par_iter()
        .map(|fp| {
            let (padded_mask, placed) = rows
                .par_chunks(BAND_ROWS)
                .fold(
                    || (vec![0u8; padded.h.len()], 0usize, Scratch::default()),
                    |(mut mask, mut placed, mut scratch), band| {
                        for &j0 in band {
                            placed += run_row(&padded, table.as_ref(), fp, j0, options.eps, &mut mask, &mut scratch);
                        }
                        (mask, placed, scratch)
                    },
                )
                .map(|(mask, placed, _)| (mask, placed))
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

#[derive(Default)]
struct Scratch {
    yr: Vec<f64>,
    slide: SlideScratch,
    paper: PaperScratch,
    counts: PaperCounts,
}

/// One start row at one angle; returns the number of placed starts.
fn run_row(
    padded: &PaddedGrid,
    table: Option<&WindowMin>,
    fp: &GridFootprint,
    j0: usize,
    eps: f64,
    mask: &mut [u8],
    scratch: &mut Scratch,
) -> usize {
    match table {
        Some(table) => {
            scratch.yr.resize(padded.spec.nx, f64::INFINITY);
            push_row(padded, table, fp, j0, &mut scratch.yr);
            slide_row(padded, fp, j0, &scratch.yr, eps, mask, &mut scratch.slide);
            scratch.yr.iter().filter(|y| y.is_finite()).count()
        }
        None => paper_row(padded, fp, j0, eps, mask, &mut scratch.paper, &mut scratch.counts),
    }
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
