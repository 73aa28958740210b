//! The fast path over one band of start rows at one angle: every start
//! pushed ([`push_block`], [`push_tile`]) and slid ([`slide_block`],
//! [`slide_block_window`]) in blocks of a register's width, the reach (or,
//! under the window rule, the strikes) recorded in the window of padded
//! rows the band's footprints span. The driver ([`super::colliding_masks`])
//! ORs the bands' results into each angle's mask.

use crate::engine::options::EngineOptions;
use crate::engine::padded::PaddedGrid;
use crate::engine::probe::Probe;
use crate::engine::probe::ProbeVisits;
use crate::engine::push::{PushRows, WindowMin, WindowOf, push_block, push_tile};
use crate::engine::ranked::{NEVER, OFF, Rank, RankedGrid};
use crate::engine::simd::dispatch;
use crate::engine::slide::{
    Extension, LayerRows, WindowLayers, WindowSlide, slide_block, slide_block_window, slide_carried,
};
use crate::kneeform::GridFootprint;
use crate::strike::StrikeRule;

/// Start rows pushed at once ([`push_tile`]).
const TILE: usize = 4;

/// Starts slid together under the window rule ([`slide_block_window`]):
/// one AVX-512 register of ranks. A block's starts span levels a footprint
/// wide, so fewer of its rows lie below all of a run of 16 starts' levels.
const SUB_LANES: usize = 64;

/// The fast path's tables, built once for every angle: the height ranks,
/// the window minima of the push, and each node's strike threshold.
pub(super) struct Fast<'a> {
    pub(super) ranked: &'a RankedGrid,
    pub(super) table: WindowMin<'a>,
    /// Per node, the lowest level that strikes it (under the window rule:
    /// that makes it a contact).
    pub(super) thresholds: Vec<Rank>,
    /// Under the window rule, its `W` (mm) and per node the lowest level
    /// `W` back that passes its deflection test.
    pub(super) window: Option<(f64, Vec<Rank>)>,
    /// Whether the slides that change nothing are skipped
    /// ([`fast_band_impl`]): always, except in the tests that compare the
    /// results with and without.
    pub(super) skip_still: bool,
}

impl<'a> Fast<'a> {
    /// The tables of `padded` (ranked as `ranked`) for push windows up to
    /// `max_width` nodes and strikes by `rule`.
    pub(super) fn new(
        padded: &PaddedGrid,
        ranked: &'a RankedGrid,
        max_width: usize,
        rule: &StrikeRule,
    ) -> Fast<'a> {
        Fast {
            ranked,
            table: WindowMin::new(padded, &ranked.ranks, max_width),
            thresholds: ranked.thresholds(padded, rule),
            window: rule
                .window_mm()
                .map(|w| (w, ranked.window_thresholds(padded, rule))),
            skip_still: true,
        }
    }
}

/// What a band of start rows found: the strikes in a window of padded
/// rows, the starts it placed and the face level that met each probe.
pub(super) struct BandResult {
    /// The window's first padded row.
    pub(super) first_row: usize,
    /// Per node of the window, 1 where it is struck.
    pub(super) strikes: Vec<u8>,
    pub(super) placed: usize,
    pub(super) probe_levels: Vec<f64>,
}

/// The fast path over one band: push and slide every start of the band,
/// recording reach in the window of padded rows its footprints span, then
/// SPEC's strike rule over that window.
pub(super) fn fast_window(
    padded: &PaddedGrid,
    fast: &Fast,
    fp: &GridFootprint,
    band: &[usize],
    options: &EngineOptions,
) -> BandResult {
    let (dj_lo, dj_hi) = fp.dj_range();
    let (j_first, j_last) = (band[0], band[band.len() - 1]);
    // Padded rows j + dj + pad_rows, for every start row j of the band and
    // every footprint row dj: never negative, never past the padding.
    let first_row = (j_first as i64 + i64::from(dj_lo) + padded.pad_rows as i64) as usize;
    let last_row = (j_last as i64 + i64::from(dj_hi) + padded.pad_rows as i64) as usize;
    let start = first_row * padded.stride;
    let end = (last_row + 1) * padded.stride;
    let mut reach = vec![NEVER; end - start];
    let visits = ProbeVisits::new(padded, fp, band, start, end - start, &options.probes);
    // Under the window rule the slides mark their strikes themselves.
    let mut struck = match fast.window {
        Some(_) => vec![0u8; end - start],
        None => Vec::new(),
    };
    let out = BandOut {
        reach: &mut reach,
        struck: &mut struck,
    };
    let placed = fast_band(padded, fast, fp, band, start, &visits, out);
    let strikes = match fast.window {
        Some(_) => struck,
        None => strike_mask(&fast.thresholds[start..end], &reach),
    };
    let probe_levels = probe_levels(padded, start, &reach, &options.probes)
        .into_iter()
        .map(|r| fast.ranked.height(r))
        .collect();
    BandResult {
        first_row,
        strikes,
        placed,
        probe_levels,
    }
}

/// Per probe, the highest face level (rank) that met one of its cell's
/// corners in a band whose reach window begins at padded index `start`
/// ([`NEVER`] where none did).
pub(super) fn probe_levels(
    padded: &PaddedGrid,
    start: usize,
    reach: &[Rank],
    probes: &[Probe],
) -> Vec<Rank> {
    probes
        .iter()
        .map(|probe| {
            probe
                .corner_nodes(padded)
                .filter_map(|node| reach.get(node.checked_sub(start)?).copied())
                .fold(NEVER, Rank::max)
        })
        .collect()
}

dispatch! {
    /// The fast path over a band of start rows: blocks of starts from +x
    /// to -x, each swept over every start row of the band, carrying each
    /// row's slide level from one block into the next. Records in `reach`
    /// (whose first element is the padded node `window`) each node's reach,
    /// as far as the strikes and `visits` depend on it (see
    /// [`fast_band_impl`]), and returns the number of placed starts.
    ///
    /// A block is 128 starts with AVX-512 (eight registers of ranks), 64
    /// with AVX2 (eight), 16 without: wider blocks walk the footprint's
    /// offsets fewer times (measured: `results/design.md`, "Block
    /// widths"). [`LANE_SLACK`](crate::engine::padded::LANE_SLACK) covers
    /// the widest block.
    pub(super) fn fast_band(padded: &PaddedGrid, fast: &Fast, fp: &GridFootprint, band: &[usize], window: usize, visits: &ProbeVisits, out: BandOut) -> usize => fast_band_impl::<128, 64, 16>
}

/// The band's work in blocks of `W` starts.
///
/// **Slides that change nothing are skipped.** A placed start's first
/// layer, in every footprint row with a node inside, is that row's first
/// node inside the footprint of the start one column to -x (`kf = klo - 1`,
/// [`crate::kneeform::FootprintRow`]). So when that start's push level is
/// not below this one's, and neither is any height of the layer's other
/// nodes ([`LayerRows::outside`]), no node of the layer lies below the
/// level: the slide's level stays `yr` across the layer, and every node it
/// meets is met at a level no higher than its own height, below its strike
/// threshold ([`RankedGrid::thresholds`]), so it strikes nothing. A block
/// whose placed starts are all like that leaves its reach alone, except at
/// the probed nodes, which are told the level (`visits`). The push of the
/// start left of a block's first lane is the last lane of the next block,
/// so each row's block waits for its left neighbour's push before it
/// slides.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn fast_band_impl<const W: usize>(
    padded: &PaddedGrid,
    fast: &Fast,
    fp: &GridFootprint,
    band: &[usize],
    window: usize,
    visits: &ProbeVisits,
    out: BandOut,
) -> usize {
    let BandOut { reach, struck } = out;
    let push_rows = PushRows::new(padded, fp);
    let nz = padded.spec.nz;
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
    let layers: Vec<_> = band.iter().map(|&j0| layer.within(j0, nz)).collect();
    let window_layers = fast
        .window
        .as_ref()
        .map(|(w, _)| WindowLayers::new(padded, fp, *w));
    let slider = Slider {
        skip_still: fast.skip_still,
        still: fast.table.windows_of(W),
        h: &fast.ranked.ranks[window..],
        window,
        nx: padded.spec.nx as i64,
        nz,
        visits,
        rule: fast.window.as_ref().map(|(w, deflected)| WindowRule {
            window: *w,
            pitch: padded.spec.pitch,
            contact: &fast.thresholds[window..],
            deflected: &deflected[window..],
        }),
        table: &fast.table,
    };
    let (mut slid, mut slid_rows, mut slid_bits) = (Vec::new(), Vec::new(), Vec::new());
    let mut lowered = Vec::new();
    let mut sink = Sink {
        reach,
        struck,
        slid: &mut slid,
        slid_bits: &mut slid_bits,
        rows: &mut slid_rows,
        lowered: &mut lowered,
        window_layers: None,
    };
    let mut rows: Vec<RowState<W>> = band
        .iter()
        .zip(&active)
        .map(|(&j0, active)| RowState {
            first: padded.index(j0 as i64, 0),
            j0,
            first_active: active.start,
            carry: NEVER,
            pending: None,
            extensions: Vec::new(),
        })
        .collect();
    let mut placed = 0;
    let mut block_end = hi;
    while block_end > lo {
        // The block may reach below `lo`: those starts do nothing, and the
        // padding's slack keeps them inside the array.
        let block = block_end - W as i64;
        let inside = |k: usize| {
            !(active[k].is_empty() || block >= active[k].end || block_end <= active[k].start)
        };
        let mut k = 0;
        while k < band.len() {
            let base = rows[k].first.wrapping_add_signed(block as isize);
            // A tile of consecutive start rows is pushed at once.
            let tile = band
                .get(k..k + TILE)
                .filter(|tile| tile[TILE - 1] - tile[0] == TILE - 1);
            if let Some(tile) = tile {
                let yr: Option<[[Rank; W]; TILE]> = (k..k + TILE)
                    .any(inside)
                    .then(|| push_tile(&fast.table, &push_rows, tile[0], nz, padded.stride, base));
                for t in 0..TILE {
                    let yr = yr.filter(|_| inside(k + t)).map(|yr| yr[t]);
                    sink.window_layers = window_layers.as_ref();
                    placed +=
                        rows[k + t].advance(&slider, &mut sink, &layers[k + t], k + t, block, yr);
                }
                k += TILE;
            } else {
                let yr =
                    inside(k).then(|| push_block::<W>(&fast.table, &push_rows, band[k], nz, base));
                sink.window_layers = window_layers.as_ref();
                placed += rows[k].advance(&slider, &mut sink, &layers[k], k, block, yr);
                k += 1;
            }
        }
        block_end = block;
    }
    for (k, row) in rows.iter_mut().enumerate() {
        if let Some((right, yr_right)) = row.pending.take() {
            // Left of the last block lie no active starts.
            sink.window_layers = window_layers.as_ref();
            placed += slider.slide(&mut sink, &layers[k], k, row, right, yr_right, [OFF; W]);
        }
    }
    placed
}

/// What a band's slides record, per node of its reach window: the highest
/// level that met it, and (under the window rule) whether it was struck.
pub(super) struct BandOut<'a> {
    pub(super) reach: &'a mut [Rank],
    pub(super) struck: &'a mut [u8],
}

/// What the slides of a band write, and the window rule's slide list of
/// the row at hand.
struct Sink<'a, 'b> {
    reach: &'a mut [Rank],
    struck: &'a mut [u8],
    slid: &'a mut Vec<u32>,
    slid_bits: &'a mut Vec<u64>,
    rows: &'a mut Vec<u32>,
    lowered: &'a mut Vec<u32>,
    window_layers: Option<&'b WindowLayers>,
}

/// The window rule as the slides of a band read it.
struct WindowRule<'a> {
    /// `W` (mm).
    window: f64,
    pitch: f64,
    /// Per node from the reach window's first, the lowest level that makes
    /// it a contact ([`RankedGrid::thresholds`]).
    contact: &'a [Rank],
    /// ... and the lowest level `W` back that passes the deflection test
    /// ([`RankedGrid::window_thresholds`]).
    deflected: &'a [Rank],
}

/// One start row's state in [`fast_band_impl`].
struct RowState<const W: usize> {
    /// The start row.
    j0: usize,
    /// The first of its active starts ([`PaddedGrid::active_starts`]):
    /// past it to -x no first layer holds a finite height.
    first_active: i64,
    /// The padded index of the row's column 0.
    first: usize,
    /// The level the slides carry into the next block, from +x.
    carry: Rank,
    /// The block pushed but not yet slid: its first start column and the
    /// starts' push levels.
    pending: Option<(i64, [Rank; W])>,
    /// Under the window rule, the slides of placed starts that go on past
    /// starts that are not placed ([`Extension`]).
    extensions: Vec<Extension>,
}

impl<const W: usize> RowState<W> {
    /// Takes the push levels `yr` of the row's block from column `block`
    /// (`None` where the block has none of the row's active starts), and
    /// slides the block pushed before it, whose left neighbour it is.
    /// Returns the starts placed.
    #[inline(always)]
    fn advance(
        &mut self,
        slider: &Slider,
        sink: &mut Sink,
        layer: &LayerRows,
        k: usize,
        block: i64,
        yr: Option<[Rank; W]>,
    ) -> usize {
        let mut placed = 0;
        if let Some((right, yr_right)) = self.pending.take() {
            // Outside the row's active starts, no start is placed: no
            // finite height lies inside its footprint.
            let left = yr.unwrap_or([OFF; W]);
            placed = slider.slide(sink, layer, k, self, right, yr_right, left);
        }
        self.pending = yr.map(|yr| (block, yr));
        placed
    }
}

/// A block of starts as the window rule's slides read it: its first
/// start's column, the padded index of that start's node less the reach
/// window's, the push levels of its starts and of the next block's (to
/// -x), and the levels its placed starts enter with ([`NEVER`] elsewhere).
#[derive(Clone, Copy)]
struct Block<const W: usize> {
    column: i64,
    base: usize,
    yr: [Rank; W],
    left: [Rank; W],
    level: [Rank; W],
}

/// What the slides of a band share.
struct Slider<'a> {
    /// The height ranks from the reach window's first node on.
    h: &'a [Rank],
    /// The padded index of the reach window's first node.
    window: usize,
    nx: i64,
    nz: usize,
    visits: &'a ProbeVisits,
    /// [`Fast::skip_still`].
    skip_still: bool,
    /// The minima over a block's width of nodes, where the table holds
    /// that width ([`slide_block`]).
    still: Option<WindowOf<'a>>,
    /// The window rule, when it is the rule (else the reach decides).
    rule: Option<WindowRule<'a>>,
    /// The push table's minima, for the window rule's runs of lanes.
    table: &'a WindowMin<'a>,
}

impl Slider<'_> {
    /// Slides the block of starts from column `block` (push levels `yr`) of
    /// the band's `k`-th start row, whose next block to -x has the push
    /// levels `left`; returns the starts placed.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn slide<const W: usize>(
        &self,
        sink: &mut Sink,
        layer: &LayerRows,
        k: usize,
        row: &mut RowState<W>,
        block: i64,
        yr: [Rank; W],
        left: [Rank; W],
    ) -> usize {
        let base = row.first.wrapping_add_signed(block as isize) - self.window;
        // Only real starts are placed.
        let mut level = [NEVER; W];
        let mut placed = 0;
        for w in 0..W {
            let i0 = block + w as i64;
            if (0..self.nx).contains(&i0) && yr[w] != OFF {
                level[w] = yr[w];
                placed += 1;
            }
        }
        if let (Some(rule), Some(layers)) = (&self.rule, sink.window_layers) {
            let b = Block {
                column: block,
                base,
                yr,
                left,
                level,
            };
            self.slide_window(rule, layers, sink, layer, k, row, &b);
            return placed;
        }
        let reach = &mut *sink.reach;
        let after = if self.moves(layer, 0, base, &left, &yr, &level) {
            // Rows of the layer that change nothing are passed over, where
            // no probe needs their reach.
            let still = (self.skip_still && !self.visits.any(k, base + self.window, W))
                .then_some(self.still)
                .flatten()
                .map(|minima| (minima, self.window));
            slide_block(self.h, reach, layer, base, level, still)
        } else {
            self.visits
                .record(k, base + self.window, layer, &level, reach);
            level
        };
        // Starts that are not placed continue the slide of the start on
        // their +x side, from +x to -x.
        let mut c = row.carry;
        for w in (0..W).rev() {
            if level[w] != NEVER {
                c = after[w];
            } else if c != NEVER {
                c = slide_carried(self.h, reach, layer, base + w, c);
            }
        }
        row.carry = c;
        placed
    }

    /// [`Slider::slide`] under the window rule: each placed start of the
    /// block slides over its [`WindowLayers`], deciding its strikes as it
    /// goes, and a placed start whose start one column to -x is not placed
    /// slides on past it, one column at a time ([`Extension`]), until a
    /// placed start has travelled far enough to decide for it.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn slide_window<const W: usize>(
        &self,
        rule: &WindowRule,
        layers: &WindowLayers,
        sink: &mut Sink,
        layer: &LayerRows,
        k: usize,
        row: &mut RowState<W>,
        b: &Block<W>,
    ) {
        let Block {
            column: block,
            base,
            yr,
            left,
            level,
        } = *b;
        let real = |lane: i64| (0..self.nx).contains(&(block + lane));
        let mut out = WindowSlide {
            contact: rule.contact,
            deflected: rule.deflected,
            reach: sink.reach,
            struck: sink.struck,
            record_reach: self.visits.probed(),
            slid: sink.slid,
            slid_bits: sink.slid_bits,
            rows: sink.rows,
            lowered: sink.lowered,
        };
        if self.moves(layer, layers.depth(), base, &left, &yr, &level) {
            let pass_over = self.skip_still && !self.visits.any(k, base + self.window, W);
            let still = |lanes| {
                pass_over
                    .then(|| self.table.windows_of(lanes))
                    .flatten()
                    .map(|minima| (minima, self.window))
            };
            // The rows the whole block may slide, then each run of lanes'
            // own: a block's starts span many levels, a run of them few.
            let top = level.iter().copied().max().unwrap_or(NEVER);
            let mut rows = std::mem::take(out.rows);
            let nz = self.nz;
            layers.rows_below(row.j0, nz, base, W, top, still(W), &mut rows);
            // Per run of lanes, the layers in which a push level to -x
            // lies below some start's: only there can a node inside a
            // footprint lie below a level.
            let depth = layers.depth().min(63);
            let moving = |lanes: std::ops::Range<usize>| {
                let mut bits = 0u64;
                for m in 0..=depth {
                    let lower = lanes.clone().any(|w| {
                        let at = w as i64 - m as i64 - 1;
                        let beside = match at {
                            0.. => yr[at as usize],
                            _ if at >= -(W as i64) => left[(W as i64 + at) as usize],
                            _ => NEVER,
                        };
                        beside < level[w]
                    });
                    bits |= u64::from(lower) << m;
                }
                // The probes read the reach of every node met, below its
                // level or not.
                if layers.depth() >= 64 || !pass_over {
                    bits = !0;
                }
                bits
            };
            if W > SUB_LANES {
                for (c, run) in level.chunks_exact(SUB_LANES).enumerate() {
                    let run: [Rank; SUB_LANES] = run.try_into().expect("SUB_LANES levels");
                    let lanes = c * SUB_LANES..(c + 1) * SUB_LANES;
                    let moving = moving(lanes);
                    let base = base + c * SUB_LANES;
                    let still = still(SUB_LANES);
                    slide_block_window(self.h, &mut out, layers, base, run, &rows, moving, still);
                }
            } else {
                let moving = moving(0..W);
                slide_block_window(
                    self.h,
                    &mut out,
                    layers,
                    base,
                    level,
                    &rows,
                    moving,
                    still(W),
                );
            }
            *out.rows = rows;
        } else {
            self.visits
                .record(k, base + self.window, layer, &level, out.reach);
        }
        // From +x to -x: the slides that go on past starts not placed.
        let placed_at = |w: i64| match w {
            0.. => level[w as usize] != NEVER,
            _ => real(w) && left[(W as i64 + w) as usize] != OFF,
        };
        // Most blocks have none: every start placed, or none.
        let begins = |w: usize| placed_at(w as i64) && !placed_at(w as i64 - 1);
        if row.extensions.is_empty() && !(0..W).any(begins) {
            return;
        }
        for w in (0..W).rev() {
            let column = block + w as i64;
            let here = placed_at(w as i64);
            if row.extensions.is_empty() && !begins(w) {
                continue;
            }
            // Past the row's active starts a slide meets nothing more.
            if column < row.first_active {
                row.extensions.clear();
                break;
            }
            row.extensions.retain_mut(|e| {
                let shift = (e.column - column) as f64 * rule.pitch;
                let on = e.goes_on(shift, here, rule.window, rule.pitch);
                if on {
                    e.advance(self.h, &mut out, layer, base + w, shift, rule.window);
                }
                on
            });
            if here && !placed_at(w as i64 - 1) {
                let mut e = Extension::new(column, level[w]);
                e.advance(self.h, &mut out, layer, base + w, 0.0, rule.window);
                row.extensions.push(e);
            }
        }
    }

    /// Whether the first `depth + 1` columns' first layers of some placed
    /// start of the block (levels `level`, [`NEVER`] where not placed) hold
    /// a node below its level: one layer under the x-slope rule, a start's
    /// [`WindowLayers`] under the window rule. The first layer of the
    /// start `c` columns to -x of a lane lies, in rows with nodes inside,
    /// inside the footprint of the start one column further, so at or
    /// above that start's push level (`yr`, the next block's `left` past
    /// the first lane); the other rows are read.
    #[inline(always)]
    fn moves<const W: usize>(
        &self,
        layer: &LayerRows,
        depth: usize,
        base: usize,
        left: &[Rank; W],
        yr: &[Rank; W],
        level: &[Rank; W],
    ) -> bool {
        if !self.skip_still || depth >= W {
            return true;
        }
        let mut lower = 0u32;
        for c in 0..=depth {
            // The push level of the start c + 1 columns to -x of each lane.
            let beside: [Rank; W] = std::array::from_fn(|w| {
                let at = w as i64 - c as i64 - 1;
                if at >= 0 {
                    yr[at as usize]
                } else {
                    left[(W as i64 + at) as usize]
                }
            });
            for w in 0..W {
                lower |= u32::from(beside[w] < level[w]);
            }
            for offset in layer.outside() {
                let a = base.wrapping_add_signed(offset - c as isize);
                let hv: &[Rank; W] = self.h[a..a + W].try_into().expect("W values");
                for w in 0..W {
                    lower |= u32::from(hv[w] < level[w]);
                }
            }
            if lower != 0 {
                return true;
            }
        }
        false
    }
}

/// SPEC's strike rule applied once per node to its reach, the highest face
/// level that met it ([`NEVER`]: never met), over a window of whole padded
/// rows: a node is struck when its reach is at least its threshold
/// ([`RankedGrid::thresholds`]), the lowest level the rule strikes it at.
/// The rule is monotone in the level, so this is the union of the strikes
/// of every slide that met the node.
fn strike_mask(thresholds: &[Rank], reach: &[Rank]) -> Vec<u8> {
    thresholds
        .iter()
        .zip(reach)
        .map(|(&t, &r)| u8::from(r >= t))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::slide::window_depth;
    use crate::engine::{Algorithm, BAND_ROWS, EngineOptions, colliding_masks, probe::Probe};
    use crate::grid::GridSpec;
    use crate::grid::HeightGrid;
    use crate::kneeform::KneeForm;

    /// [`fast_band`]'s signature.
    type BandFn =
        fn(&PaddedGrid, &Fast, &GridFootprint, &[usize], usize, &ProbeVisits, BandOut) -> usize;

    /// Both rules: the window (the default) and the x-slope.
    fn rules() -> [StrikeRule; 2] {
        [
            StrikeRule::default(),
            StrikeRule::default().with_rate(crate::strike::RateEstimate::XSlope),
        ]
    }

    /// The fast path over `rows` with one reach and one strike array over
    /// the whole padded grid: the strikes, the reach and the starts placed.
    fn whole_band(
        f: BandFn,
        padded: &PaddedGrid,
        fast: &Fast,
        fp: &GridFootprint,
        rows: &[usize],
        visits: &ProbeVisits,
    ) -> (Vec<u8>, Vec<Rank>, usize) {
        let mut reach = vec![NEVER; padded.h.len()];
        let mut struck = vec![0u8; padded.h.len()];
        let out = BandOut {
            reach: &mut reach,
            struck: &mut struck,
        };
        let placed = f(padded, fast, fp, rows, 0, visits, out);
        let mask = match fast.window {
            Some(_) => struck,
            None => strike_mask(&fast.thresholds, &reach),
        };
        (mask, reach, placed)
    }

    /// The block width is a tuning knob per instruction set: every width
    /// gives the same strikes, probe answers and placed count (the tests
    /// elsewhere run only the width this machine's instruction set picks).
    /// The reach itself may differ where it decides nothing: the slides
    /// skipped are those of whole blocks.
    #[test]
    fn every_block_width_gives_the_same_result() {
        let spec = GridSpec {
            pitch: 2.5,
            i_origin: -40,
            j_origin: -20,
            nx: 150,
            nz: 60,
        };
        let grid = HeightGrid::from_fn(spec, |x, z| {
            let hole = (x - 60.0).hypot(z - 10.0) < 25.0;
            if hole {
                f64::INFINITY
            } else {
                0.1 * x + 3.0 * (0.07 * x).sin() * (0.05 * z).cos()
            }
        });
        let knee = KneeForm {
            triangle_side: 80.0,
            radius: 20.0,
            thickness: 100.0,
        };
        let rows: Vec<usize> = (0..spec.nz).collect();
        for (angle, rule) in [-30.0, 0.0, 17.0]
            .into_iter()
            .flat_map(|a| rules().map(|r| (a, r)))
        {
            let fp = GridFootprint::new(&knee, angle, &spec);
            let depth = window_depth(&rule, spec.pitch);
            let padded = PaddedGrid::deep(&grid, std::slice::from_ref(&fp), depth);
            let ranked = RankedGrid::new(&padded);
            let fast = Fast::new(&padded, &ranked, 512, &rule);
            let probes: Vec<Probe> = (0..spec.nz - 1)
                .step_by(7)
                .flat_map(|j| (0..spec.nx - 1).step_by(13).map(move |i| (i, j)))
                .map(|cell| Probe {
                    cell,
                    y: -1.0 + 0.02 * (cell.0 + cell.1) as f64,
                })
                .collect();
            let visits = ProbeVisits::new(&padded, &fp, &rows, 0, padded.h.len(), &probes);
            let mut still = Fast::new(&padded, &ranked, 512, &rule);
            still.skip_still = false;
            let run_with = |fast: &Fast, f: BandFn| {
                let (mask, reach, placed) = whole_band(f, &padded, fast, &fp, &rows, &visits);
                (mask, probe_levels(&padded, 0, &reach, &probes), placed)
            };
            let run = |f: BandFn| run_with(&fast, f);
            let w16 = run(fast_band_impl::<16>);
            assert!(w16.2 > 0);
            assert!(w16.0.contains(&1));
            // Probes both met and not, so that a lost visit shows.
            let met: Vec<bool> = (w16.1.iter().zip(&probes))
                .map(|(&level, probe)| probe.y < ranked.height(level) - 1e-6)
                .collect();
            assert!(met.contains(&true) && met.contains(&false), "angle {angle}");
            // Skipping the slides that change nothing changes nothing.
            assert!(
                run_with(&still, fast_band_impl::<64>) == w16,
                "angle {angle}: no skip"
            );
            assert!(run(fast_band_impl::<8>) == w16, "angle {angle}: 8 lanes");
            assert!(run(fast_band_impl::<32>) == w16, "angle {angle}: 32 lanes");
            assert!(run(fast_band_impl::<64>) == w16, "angle {angle}: 64 lanes");
            assert!(
                run(fast_band_impl::<128>) == w16,
                "angle {angle}: 128 lanes"
            );
        }
    }

    /// Skipping the slides that change nothing loses nothing: on rough
    /// random grids with plateaus and holes, at angles and pitches where
    /// some footprint rows hold no node, every node's reach where it lies
    /// above the node (where the strike rule can be met) and every probe's
    /// level are those of sliding every start. Probes on the plateau, below
    /// it, are met only by slides that do not fall, the skipped ones.
    /// Without probes, the rows of a sliding block's layer that change
    /// nothing are passed over as well ([`slide_block`]).
    #[test]
    fn skipped_slides_lose_nothing() {
        let knee = KneeForm {
            triangle_side: 30.0,
            radius: 6.0,
            thickness: 100.0,
        };
        let (mut empty_rows, mut skipped, mut passed_over) = (0, 0, 0);
        // Pitches and angles with rows of no node at the footprint's tips
        // (found by laying this knee-form at every whole angle).
        let cases: [(u64, f64, &[f64]); 4] = [
            (1, 2.5, &[-2.0, 2.0, -30.0]),
            (2, 1.6, &[-20.0, 15.0, 30.0]),
            (3, 2.6, &[-12.0, 0.0, 6.0, 19.0]),
            (4, 1.4, &[0.0, 11.0]),
        ];
        for (seed, pitch, angles) in cases {
            let spec = GridSpec {
                pitch,
                i_origin: -20,
                j_origin: -7,
                nx: 110,
                nz: 50,
            };
            let mut rng = crate::harness::compare::SplitMix(seed);
            // A plateau, then a slope rising to -x with a few pits (most
            // slides there do not fall), then rough ground with holes.
            let mixed: Vec<f64> = (0..spec.len())
                .map(|n| {
                    let (i, r) = (n % spec.nx, rng.next());
                    match (i, r % 17) {
                        (..25, _) => 1.0,
                        (25..55, 0) => -4.0,
                        (25..55, _) => -0.1 * i as f64,
                        (_, 0) => f64::INFINITY,
                        (_, _) => ((r >> 8) % 13) as f64 * 0.5 - 2.0,
                    }
                })
                .collect();
            // A low row with pits in high ground: a start whose footprint's
            // tip row of no node lies on the row meets a pit at the high
            // level, the other starts meeting it at the row's low level.
            let ridge: Vec<f64> = (0..spec.len())
                .map(|n| match (n / spec.nx, n % spec.nx % 9) {
                    (25, 4) => -4.0,
                    (25, _) => 1.0,
                    _ => 5.0,
                })
                .collect();
            for h in [mixed, ridge] {
                let grid = HeightGrid { spec, h };
                let probes: Vec<Probe> = (0..spec.nz - 1)
                    .step_by(3)
                    .flat_map(|j| (0..spec.nx - 1).step_by(2).map(move |i| (i, j)))
                    .map(|cell| Probe { cell, y: 0.5 })
                    .collect();
                let rows: Vec<usize> = (0..spec.nz).collect();
                for (&angle, rule) in angles.iter().flat_map(|a| rules().map(|r| (a, r))) {
                    let fp = GridFootprint::new(&knee, angle, &spec);
                    empty_rows += fp.rows.iter().filter(|r| r.khi < r.klo).count();
                    let depth = window_depth(&rule, spec.pitch);
                    let padded = PaddedGrid::deep(&grid, std::slice::from_ref(&fp), depth);
                    let ranked = RankedGrid::new(&padded);
                    let visits = ProbeVisits::new(&padded, &fp, &rows, 0, padded.h.len(), &probes);
                    // Without probes, the rows of a layer that change
                    // nothing are passed over too.
                    let unprobed = ProbeVisits::new(&padded, &fp, &rows, 0, padded.h.len(), &[]);
                    let run_with = |skip_still: bool, f: BandFn, visits: &ProbeVisits| {
                        let mut fast = Fast::new(&padded, &ranked, 64, &rule);
                        fast.skip_still = skip_still;
                        let (mask, reach, placed) =
                            whole_band(f, &padded, &fast, &fp, &rows, visits);
                        let above: Vec<Rank> = (reach.iter().zip(&ranked.ranks))
                            .map(|(&r, &own)| if r > own { r } else { NEVER })
                            .collect();
                        let levels = probe_levels(&padded, 0, &reach, &probes);
                        (reach, (above, mask), levels, placed)
                    };
                    let run = |skip_still: bool, f: BandFn| run_with(skip_still, f, &visits);
                    let all = run(false, fast_band_impl::<16>);
                    assert!(all.2.iter().any(|&l| l != NEVER));
                    // Narrow blocks: many first lanes, whose left neighbour's
                    // push is the next block's.
                    for f in [
                        fast_band_impl::<2> as BandFn,
                        fast_band_impl::<8>,
                        fast_band_impl::<16>,
                    ] {
                        let skip = run(true, f);
                        assert!(all.1 == skip.1, "seed {seed}, angle {angle}: reach above");
                        assert!(all.2 == skip.2, "seed {seed}, angle {angle}: probes");
                        assert_eq!(all.3, skip.3);
                        skipped += usize::from(all.0 != skip.0);
                        let unprobed = run_with(true, f, &unprobed);
                        assert!(all.1.1 == unprobed.1.1, "seed {seed}, angle {angle}: rows");
                        // Under the window rule the reach is kept for the
                        // probes only, so without probes there is none.
                        if rule.window_mm().is_none() {
                            assert!(all.1 == unprobed.1, "seed {seed}, angle {angle}: reach");
                        }
                        assert_eq!(all.3, unprobed.3);
                        passed_over += usize::from(skip.0 != unprobed.0);
                    }
                }
            }
        }
        // The cases the skip must get right did occur.
        assert!(
            empty_rows > 0 && skipped > 0 && passed_over > 0,
            "{empty_rows} {skipped} {passed_over}"
        );
    }

    /// Bands of start rows, their reach windows and the thread count are
    /// how the work is split, not what is computed: on a grid of several
    /// bands, every split gives the masks and probe answers of one slide
    /// over the whole grid with a whole-grid reach, and the paper path's.
    #[test]
    fn bands_windows_and_threads_do_not_change_the_result() {
        let spec = GridSpec {
            pitch: 2.0,
            i_origin: -30,
            j_origin: -100,
            nx: 90,
            nz: 3 * BAND_ROWS + 11,
        };
        let grid = HeightGrid::from_fn(spec, |x, z| {
            if (x - 40.0).hypot(z - 30.0) < 12.0 {
                f64::INFINITY
            } else {
                (0.5 * (0.9 * x).sin() * (0.13 * z).cos() + 0.02 * x).round() * 0.5
            }
        });
        let knee = KneeForm {
            triangle_side: 60.0,
            radius: 15.0,
            thickness: 100.0,
        };
        // Probes in cells on both sides of every band boundary.
        let probes: Vec<Probe> = [0, BAND_ROWS - 1, BAND_ROWS, 2 * BAND_ROWS - 1, spec.nz - 2]
            .into_iter()
            .flat_map(|j| [(5, j), (45, j), (80, j)])
            .map(|cell| Probe { cell, y: 0.2 })
            .collect();
        let angles = [-30.0, -7.0, 0.0, 12.0, 30.0];
        let footprints: Vec<GridFootprint> = angles
            .iter()
            .map(|&a| GridFootprint::new(&knee, a, &spec))
            .collect();
        let options = |algorithm| EngineOptions {
            algorithm,
            probes: probes.clone(),
            ..EngineOptions::default()
        };
        // The reference: one band of every start row, one whole-grid reach.
        let rule = StrikeRule::default();
        let padded = PaddedGrid::deep(&grid, &footprints, window_depth(&rule, spec.pitch));
        let ranked = RankedGrid::new(&padded);
        let fast = Fast::new(&padded, &ranked, WindowMin::max_width(&footprints), &rule);
        let rows: Vec<usize> = (0..spec.nz).collect();
        let expected: Vec<(Vec<u8>, usize, Vec<bool>)> = footprints
            .iter()
            .map(|fp| {
                let visits = ProbeVisits::new(&padded, fp, &rows, 0, padded.h.len(), &probes);
                let (mask, reach, placed) =
                    whole_band(fast_band, &padded, &fast, fp, &rows, &visits);
                let mask = padded.unpad(&mask);
                let met = probe_levels(&padded, 0, &reach, &probes)
                    .iter()
                    .zip(&probes)
                    .map(|(&level, probe)| probe.y < ranked.height(level) - rule.e0)
                    .collect();
                (mask, placed, met)
            })
            .collect();
        assert!(expected.iter().all(|(m, _, _)| m.contains(&1)));
        assert!(expected.iter().any(|(_, _, met)| met.contains(&true)));
        assert!(expected.iter().any(|(_, _, met)| met.contains(&false)));
        for threads in [1, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            // Five angles on 8 threads: bands in parallel within an angle.
            let got = pool
                .install(|| colliding_masks(&grid, &footprints, &options(Algorithm::Fast), &|| ()));
            for (m, (mask, placed, met)) in got.iter().zip(&expected) {
                assert!(&m.mask == mask, "{threads} threads, angle {}", m.angle_deg);
                assert_eq!(m.placed, *placed);
                assert_eq!(&m.probes_met, met);
            }
            let paper = pool.install(|| {
                colliding_masks(&grid, &footprints, &options(Algorithm::Paper), &|| ())
            });
            for (p, (mask, placed, _)) in paper.iter().zip(&expected) {
                assert!(
                    &p.mask == mask,
                    "paper, {threads} threads, angle {}",
                    p.angle_deg
                );
                assert_eq!(p.placed, *placed);
            }
        }
    }
}
