//! The grid engine's driver: for every angle, push and slide every start
//! and collect the colliding mask `C_theta`; then the composite count.
//!
//! Work is split across angles and, within an angle, across bands of
//! `BAND_ROWS` start rows, each band deciding the strikes in the window of
//! rows its slides reach and ORing them into the angle's mask. OR is
//! order-independent, so the masks are identical whatever the thread count.
//!
//! **Invariant:** the engine does no I/O and reads no clock; progress is
//! reported through a callback.

mod band;
mod options;
mod padded;
mod paper;
mod probe;
mod push;
mod ranked;
mod simd;
mod slide;

use rayon::prelude::*;

use crate::engine::band::{BandResult, Fast, fast_window};
pub use crate::engine::options::{Algorithm, EngineOptions};
use crate::engine::padded::PaddedGrid;
use crate::engine::paper::{PaperCounts, PaperScratch, paper_row};
pub(crate) use crate::engine::probe::Probe;
use crate::engine::push::{PushRows, WindowMin, push_block};
use crate::engine::ranked::{Rank, RankedGrid};
use crate::engine::slide::window_depth;
use crate::grid::{GridSpec, HeightGrid};
use crate::kneeform::GridFootprint;
use crate::strike::{Level, StrikeRule};
use crate::surface::{SurfaceFootprint, SurfaceGrid};

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

impl AngleMask {
    /// The result at `angle_deg` whose colliding nodes are those of `mask`
    /// (the count derived from it), with `placed` starts and the probes met.
    pub fn new(angle_deg: f64, mask: Vec<u8>, placed: usize, probes_met: Vec<bool>) -> AngleMask {
        AngleMask {
            angle_deg,
            colliding: mask.iter().filter(|&&m| m != 0).count(),
            mask,
            placed,
            probes_met,
        }
    }
}

/// Starts per block of [`push_levels`]: two AVX2 registers of ranks. The
/// analysis's blocks are wider, per instruction set ([`band::fast_band`]).
const LANES: usize = 16;

/// Start rows per band: the unit of work within an angle. A band's slides
/// record their reach in a window of the rows the band's footprints span
/// (the band and the footprint's height), not in a whole grid, so that an
/// angle in flight holds a few MiB whatever the grid, and memory stays
/// flat in the thread count. Deciding strikes per window costs one pass
/// over `(BAND_ROWS + footprint rows) / BAND_ROWS` times the grid per
/// angle. Within a band every block of starts is swept over all its start
/// rows, so the footprint rows they share stay in cache. Taller bands
/// pass over the grid fewer times but hold more memory per thread; 512
/// was measured against 128 and 1024 (`results/design.md`, "Band rows").
pub(crate) const BAND_ROWS: usize = 512;

/// Runs push and slide for every footprint (one per angle) on `grid`.
/// `on_angle` is called once per finished angle (for a progress bar).
///
/// Angles run in parallel; when there are fewer angles than threads, the
/// bands of start rows within an angle do too. At most one task per
/// thread holds a reach window (`BAND_ROWS`), and at most
/// `min(threads, angles)` angles hold an unfinished mask.
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
    if options.rule.level == Level::Surface {
        return surface_masks(grid, footprints, options, on_angle);
    }
    let padded = PaddedGrid::deep(
        grid,
        footprints,
        window_depth(&options.rule, grid.spec.pitch),
    );
    let ranked = match options.algorithm {
        Algorithm::Fast => Some(RankedGrid::new(&padded)),
        Algorithm::Paper => None,
    };
    let max_width = WindowMin::max_width(footprints);
    let fast = ranked
        .as_ref()
        .map(|ranked| Fast::new(&padded, ranked, max_width, &options.rule));
    let rows: Vec<usize> = match &options.start_rows {
        Some(rows) => rows.iter().copied().filter(|&j| j < grid.spec.nz).collect(),
        None => (0..grid.spec.nz).collect(),
    };
    // Bands within an angle run in parallel only when the angles alone
    // cannot keep every thread busy; otherwise an angle's task would steal
    // other angles while it waits for its bands, and hold their masks too.
    let nested = footprints.len() < rayon::current_num_threads();
    footprints
        .par_iter()
        .map(|fp| {
            let run = |band: &[usize]| match &fast {
                Some(fast) => fast_window(&padded, fast, fp, band, options),
                None => {
                    let mut mask = vec![0u8; padded.h.len()];
                    let placed = paper_band(&padded, fp, band, &options.rule, &mut mask);
                    BandResult {
                        first_row: 0,
                        strikes: mask,
                        placed,
                        probe_levels: vec![f64::NEG_INFINITY; options.probes.len()],
                    }
                }
            };
            let mut acc = std::sync::Mutex::new(AngleAcc::new(&padded, options.probes.len()));
            if nested {
                rows.par_chunks(BAND_ROWS).for_each(|band| {
                    let result = run(band);
                    acc.lock().expect("no band panics").add(&padded, result);
                });
            } else {
                for band in rows.chunks(BAND_ROWS) {
                    acc.get_mut()
                        .expect("no band panics")
                        .add(&padded, run(band));
                }
            }
            let AngleAcc {
                mask,
                placed,
                probe_levels,
            } = acc.into_inner().expect("no band panics");
            on_angle();
            let probes_met = options
                .probes
                .iter()
                .zip(&probe_levels)
                .map(|(probe, &level)| probe.y < level - options.rule.e0)
                .collect();
            AngleMask::new(fp.angle_deg, mask, placed, probes_met)
        })
        .collect()
}

/// [`colliding_masks`] under the surface level (SPEC v4): the union of the
/// per-start slides of [`crate::surface::trace`], start rows in parallel,
/// each row's starts through [`crate::surface::trace_row`] (a start stops
/// where it continues an earlier start's slide). There is no streaming
/// form across rows yet: on the README console at 1.24 mm an angle takes
/// about 80 s on a loaded 2-core machine (the paper workload's angle),
/// where the node level's takes under a second (`results/ab.md`). The blind spots' probes are still judged at the node level,
/// which is never below the surface level (the surface's minimum is taken
/// over the nodes too), so a blind spot the surface level meets is
/// reported.
fn surface_masks(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    options: &EngineOptions,
    on_angle: &(dyn Fn() + Sync),
) -> Vec<AngleMask> {
    let probes = if options.probes.is_empty() {
        vec![Vec::new(); footprints.len()]
    } else {
        let node = EngineOptions {
            rule: options.rule.with_level(Level::Node),
            ..options.clone()
        };
        colliding_masks(grid, footprints, &node, &|| {})
            .into_iter()
            .map(|m| m.probes_met)
            .collect()
    };
    let surface = SurfaceGrid::new(grid).with_spans();
    let rows: Vec<usize> = match &options.start_rows {
        Some(rows) => rows.iter().copied().filter(|&j| j < grid.spec.nz).collect(),
        None => (0..grid.spec.nz).collect(),
    };
    footprints
        .iter()
        .zip(probes)
        .map(|(fp, probes_met)| {
            let outline = SurfaceFootprint::new(fp);
            let (mask, placed) = rows
                .par_iter()
                .fold(
                    || (vec![0u8; grid.spec.len()], 0usize),
                    |(mut mask, mut placed), &j0| {
                        placed += crate::surface::trace_row(
                            &surface,
                            &outline,
                            j0,
                            &options.rule,
                            &mut mask,
                        );
                        (mask, placed)
                    },
                )
                .reduce(
                    || (vec![0u8; grid.spec.len()], 0usize),
                    |(mut a, pa), (b, pb)| {
                        for (x, y) in a.iter_mut().zip(&b) {
                            *x |= y;
                        }
                        (a, pa + pb)
                    },
                );
            on_angle();
            AngleMask::new(fp.angle_deg, mask, placed, probes_met)
        })
        .collect()
}

/// An angle's result so far: the union of its bands'.
struct AngleAcc {
    /// The (unpadded) mask.
    mask: Vec<u8>,
    placed: usize,
    probe_levels: Vec<f64>,
}

impl AngleAcc {
    fn new(padded: &PaddedGrid, probes: usize) -> AngleAcc {
        AngleAcc {
            mask: vec![0u8; padded.spec.len()],
            placed: 0,
            probe_levels: vec![f64::NEG_INFINITY; probes],
        }
    }

    /// ORs a band's strikes in. OR, sum and max are order-independent, so
    /// the result does not depend on the order bands finish in.
    fn add(&mut self, padded: &PaddedGrid, band: BandResult) {
        let GridSpec { nx, nz, .. } = padded.spec;
        let rows = band.strikes.chunks_exact(padded.stride);
        for (r, strikes) in (band.first_row..).zip(rows) {
            let Some(j) = r.checked_sub(padded.pad_rows).filter(|&j| j < nz) else {
                continue;
            };
            let strikes = &strikes[padded.pad_lo..padded.pad_lo + nx];
            for (m, &s) in self.mask[j * nx..(j + 1) * nx].iter_mut().zip(strikes) {
                *m |= s;
            }
        }
        self.placed += band.placed;
        for (l, b) in self.probe_levels.iter_mut().zip(band.probe_levels) {
            *l = l.max(b);
        }
    }
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
    let mut levels = Vec::new();
    for_each_push_levels(grid, std::slice::from_ref(fp), |yr| levels = yr);
    levels
}

/// [`push_levels`] at every angle of `footprints` in turn, handed to
/// `each` in their order: the padded grid, its ranks and the push table
/// are built once for all of them.
pub(crate) fn for_each_push_levels(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    mut each: impl FnMut(Vec<f64>),
) {
    assert_same_pitch(grid, footprints);
    let padded = PaddedGrid::new(grid, footprints);
    let ranked = RankedGrid::new(&padded);
    let table = WindowMin::new(&padded, &ranked.ranks, WindowMin::max_width(footprints));
    let nx = grid.spec.nx;
    for fp in footprints {
        let rows = PushRows::new(&padded, fp);
        let mut yr = vec![f64::INFINITY; grid.spec.len()];
        for (j0, out) in yr.chunks_exact_mut(nx).enumerate() {
            for (block, out) in out.chunks_mut(LANES).enumerate() {
                // The padding's slack covers the lanes past the last column.
                let levels: [Rank; LANES] = push_block(
                    &table,
                    &rows,
                    j0,
                    grid.spec.nz,
                    padded.index(j0 as i64, 0) + block * LANES,
                );
                for (y, &r) in out.iter_mut().zip(&levels) {
                    *y = ranked.height(r);
                }
            }
        }
        each(yr);
    }
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

/// The engine's working memory on `spec` at the angles of `footprints`
/// under `rule`, `threads` angles at a time at most, by item (bytes): the
/// height grid and its padded copy, the ranks and thresholds, the push's
/// window-minimum table, the bands running and the angles in flight. The
/// engine owns these figures because it owns the buffers;
/// [`crate::memory::MemoryEstimate::analysis`] adds the part, the masks
/// and the writers.
pub(crate) fn working_bytes(
    spec: &GridSpec,
    footprints: &[GridFootprint],
    rule: &StrikeRule,
    threads: usize,
) -> Vec<(&'static str, f64)> {
    let n = spec.nx as f64 * spec.nz as f64;
    let padding = padded::Padding::deep(spec, footprints, slide::window_depth(rule, spec.pitch));
    let padded = padding.nodes(spec) as f64;
    let threads = threads.max(1);
    let angles_in_flight = threads.min(footprints.len().max(1)) as f64;
    let span = footprints
        .iter()
        .map(|fp| {
            let (lo, hi) = fp.dj_range();
            (hi - lo) as usize + 1
        })
        .max()
        .unwrap_or(1);
    let band = BAND_ROWS.min(spec.nz.max(1));
    let window = (padding.stride * (band - 1 + span)) as f64;
    let bands = footprints.len().max(1) * spec.nz.div_ceil(band).max(1);
    let tasks = threads.min(bands) as f64;
    let thresholds = if rule.window_mm().is_some() { 2.0 } else { 1.0 };
    // The surface level's tables beside the heights: the row spans and
    // their tall windows (`2 * SPAN_LEVELS` copies of the heights), the
    // block minima, their prefix and the block `tau`s (under one copy),
    // and each thread's fold of the angle's mask; its rows' trails and
    // bounds are a few MiB a thread (`THREAD_BYTES` and the slack).
    let surface = match rule.level {
        Level::Surface => vec![(
            "surface tables",
            8.0 * n * (2 * crate::surface::SPAN_LEVELS + 1) as f64 + threads as f64 * n,
        )],
        Level::Node => Vec::new(),
    };
    let mut items = vec![
        ("height grid", 8.0 * n + 8.0 * padded),
        // The ranks, the strike thresholds (two under the window rule) and
        // the distinct heights (at most one per node).
        ("ranks", 4.0 * padded + 4.0 * thresholds * padded + 8.0 * n),
        (
            "push table",
            WindowMin::bytes_for(spec.nz, padding.stride, WindowMin::max_width(footprints)) as f64,
        ),
        // A rank of reach, a strike byte and a probe-corner bit per window
        // node.
        ("bands running", tasks * (5.125 * window).max(padded)),
        ("angles in flight", angles_in_flight * n),
    ];
    items.extend(surface);
    items
}
