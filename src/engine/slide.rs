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
//! done for a block of starts at once (vectorised across starts: each
//! footprint row is a contiguous run of heights, the levels stay in vector
//! registers), then a scalar pass for the starts that are not placed but
//! carry a level.
//!
//! Rather than apply SPEC's strike rule at every visit, each node keeps its
//! **reach**, the highest level that met it; the rule
//! ([`StrikeRule::strikes`](crate::strike::StrikeRule::strikes)) is
//! monotone in the level, so applying it to the reach at the end gives the
//! same mask with a `max` per visit instead of a compare-and-store.
//!
//! Heights and levels are taken as their ranks ([`crate::engine::ranked`]), and
//! the rule as each node's threshold rank: the same comparisons, exactly.

use crate::engine::padded::PaddedGrid;
use crate::engine::push::WindowOf;
use crate::engine::ranked::{NEVER, OFF, Rank};
use crate::grid::NODE_TOL;
use crate::kneeform::GridFootprint;
use crate::strike::{LevelHistory, StrikeRule};

/// The first layer of one footprint, ready for [`slide_block`]: the offset
/// from a start's node to the first node in front in each footprint row, in
/// slide order, and the tie groups (runs of that order whose distances
/// agree within [`NODE_TOL`]).
#[derive(Debug, Clone)]
pub(crate) struct LayerRows {
    offsets: Vec<isize>,
    /// Each offset's tie group, numbered in slide order: a group is the
    /// run of offsets with one number.
    group: Vec<u32>,
    /// Each offset's footprint row `dj`.
    dj: Vec<i32>,
    /// Whether each offset's footprint row has nodes inside the footprint.
    /// Where it does, the first node in front (`kf = klo - 1`) is inside
    /// the footprint of the start one column to -x.
    inside: Vec<bool>,
    /// Each offset's slide distance `d0` (mm): the travel at which the
    /// start meets it.
    d: Vec<f64>,
}

impl LayerRows {
    /// Lays out `fp`'s first layer on `grid`.
    pub fn new(grid: &PaddedGrid, fp: &GridFootprint) -> LayerRows {
        let rows = || fp.slide_order.iter().map(|&r| &fp.rows[r as usize]);
        LayerRows {
            offsets: rows().map(|row| grid.offset(row.dj, row.kf)).collect(),
            group: fp
                .groups
                .iter()
                .zip(0..)
                .flat_map(|(g, n)| g.clone().map(move |_| n))
                .collect(),
            dj: rows().map(|row| row.dj).collect(),
            inside: rows().map(|row| row.khi >= row.klo).collect(),
            d: rows().map(|row| row.d0).collect(),
        }
    }

    /// The offsets of the first nodes in front in footprint rows with no
    /// node inside: the layer's nodes that are not inside the footprint of
    /// the start one column to -x.
    pub fn outside(&self) -> impl Iterator<Item = isize> + '_ {
        self.offsets
            .iter()
            .zip(&self.inside)
            .filter(|&(_, &inside)| !inside)
            .map(|(&offset, _)| offset)
    }

    /// Each footprint row `dj` of the layer with the offset of its first
    /// node in front.
    pub fn rows(&self) -> impl Iterator<Item = (i32, isize)> + '_ {
        self.dj.iter().copied().zip(self.offsets.iter().copied())
    }

    /// The layer of a start in row `j0` of a grid of `nz` rows without the
    /// nodes on the `+inf` padding rows: there a visit changes no level and
    /// its reach is never judged, so skipping it changes nothing but the
    /// time. Borrowed where every row is real.
    pub fn within(&self, j0: usize, nz: usize) -> std::borrow::Cow<'_, LayerRows> {
        let real = |dj: i32| (0..nz as i64).contains(&(j0 as i64 + i64::from(dj)));
        if self.dj.iter().all(|&dj| real(dj)) {
            return std::borrow::Cow::Borrowed(self);
        }
        let mut layer = LayerRows {
            offsets: Vec::new(),
            group: Vec::new(),
            dj: Vec::new(),
            inside: Vec::new(),
            d: Vec::new(),
        };
        for n in (0..self.offsets.len()).filter(|&n| real(self.dj[n])) {
            layer.offsets.push(self.offsets[n]);
            layer.group.push(self.group[n]);
            layer.dj.push(self.dj[n]);
            layer.inside.push(self.inside[n]);
            layer.d.push(self.d[n]);
        }
        std::borrow::Cow::Owned(layer)
    }
}

/// Slides `W` consecutive starts over their first layers. `h` are the
/// height ranks, `base` the padded node index of the first start,
/// `level[w]` the level it enters with (`yr` if placed,
/// [`NEVER`] if not). Every node of the layer
/// records in `reach` the highest face level that met it; whether it is
/// struck is decided once at the end by SPEC's strike rule applied to that
/// reach (the rule is monotone in the level). Returns the levels after the
/// layer.
///
/// With `still`, the minima of the `W` nodes from each node of a real row
/// (whose padded index is `still.1` more than its index in `h`), a layer
/// row whose `W` nodes are none below any start's level is passed over: it
/// lowers no level, and it meets each node at a level no higher than the
/// node's own height, below its strike threshold
/// ([`crate::engine::ranked::RankedGrid::thresholds`]), so it decides no strike.
/// Its reach stays as it was, so a caller that reads the reach at levels
/// below the nodes (the engine's probes) passes `None`.
#[inline(always)]
pub(crate) fn slide_block<const W: usize>(
    h: &[Rank],
    reach: &mut [Rank],
    layer: &LayerRows,
    base: usize,
    mut level: [Rank; W],
    still: Option<(WindowOf, usize)>,
) -> [Rank; W] {
    // Levels only fall along the slide: the highest at the start bounds
    // them all.
    let top = level.iter().copied().max().unwrap_or(NEVER);
    // The level before the current tie group: its nodes are all met at it.
    let mut group = None;
    let mut before = level;
    // The layer's rows by chunks of 64: first which of them to slide over,
    // with no branch between the minima's loads (they mostly miss the
    // cache, and a branch on each made them wait on one another), then
    // those rows in slide order.
    for (chunk, offsets) in layer.offsets.chunks(64).enumerate() {
        let slid = match still {
            Some((minima, shift)) => offsets.iter().enumerate().fold(0u64, |slid, (n, &offset)| {
                let a = base.wrapping_add_signed(offset);
                slid | u64::from(minima.at(a + shift) < top) << n
            }),
            None => u64::MAX >> (64 - offsets.len()),
        };
        for n in ones(slid) {
            let e = chunk * 64 + n;
            // Passed-over rows change no level, so the level on entering a
            // group's first slid row is the level before the group.
            if group != Some(layer.group[e]) {
                group = Some(layer.group[e]);
                before = level;
            }
            let a = base.wrapping_add_signed(offsets[n]);
            let hv: &[Rank; W] = h[a..a + W].try_into().expect("W values");
            let r: &mut [Rank; W] = (&mut reach[a..a + W]).try_into().expect("W values");
            for w in 0..W {
                r[w] = r[w].max(before[w]);
                level[w] = level[w].min(hv[w]);
            }
        }
    }
    level
}

/// The set bits of `word`, lowest first.
pub(crate) fn ones(mut word: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (word != 0).then(|| {
            let bit = word.trailing_zeros() as usize;
            word &= word - 1;
            bit
        })
    })
}

/// The scalar slide of one start that is not placed but carries the level
/// `carry` of the start on its +x side, over its first layer; returns the
/// level it carries on. A layer with no finite height (past the part's
/// edge) is not slid over: no node of it exists to be met.
pub(crate) fn slide_carried(
    h: &[Rank],
    reach: &mut [Rank],
    layer: &LayerRows,
    node: usize,
    mut carry: Rank,
) -> Rank {
    let at = |offset: &isize| node.wrapping_add_signed(*offset);
    if layer.offsets.iter().all(|o| h[at(o)] == OFF) {
        return carry;
    }
    let mut group = None;
    let mut before = carry;
    for (offset, &g) in layer.offsets.iter().zip(&layer.group) {
        if group != Some(g) {
            group = Some(g);
            before = carry;
        }
        let a = at(offset);
        reach[a] = reach[a].max(before);
        carry = carry.min(h[a]);
    }
    carry
}

/// How far (mm) a placed start must be slid under the window rule before
/// the start one column to -x, if placed, decides everything it would:
/// `W` and a pitch (the newer start's window must look back past its own
/// entry), and a pitch to spare for where its first nodes in front lie
/// (`d0 <= p`) and for rounding.
pub(crate) fn window_reach(window: f64, pitch: f64) -> f64 {
    window + 2.0 * pitch
}

/// Columns beyond the first layer that [`WindowLayers`] reach: what the
/// padding must add before column 0 for the virtual starts' deepest nodes.
pub(crate) fn window_depth(rule: &StrikeRule, pitch: f64) -> usize {
    match rule.window_mm() {
        Some(window) => (window_reach(window, pitch) / pitch).ceil() as usize + 1,
        None => 0,
    }
}

/// The window rule's slide list of one footprint: every node in front of a
/// start up to [`window_reach`] of travel, in slide order, with its tie
/// groups and, per group, which earlier groups lie the window `W` behind
/// it. Under the window rule a start's strike reads its level `W` back, so
/// a placed start is no longer decided by its first layer alone: the
/// newer start one column to -x dominates it (its level is at least as
/// high at both travels) only once that start has itself travelled `W`.
/// So each placed start slides this far, and further where the starts to
/// its -x are not placed ([`Extension`]).
#[derive(Debug, Clone)]
pub(crate) struct WindowLayers {
    /// Each entry's offset from the start's node, in slide order.
    offsets: Vec<isize>,
    /// Each entry's tie group, numbered in slide order.
    group: Vec<u32>,
    /// Each entry's column past the first layer: the entry is the first
    /// node in front of the start that many columns to -x.
    layer: Vec<u16>,
    /// Per footprint row, whether it has nodes inside the footprint: then
    /// its node in layer `m` lies inside the footprint of the start
    /// `m + 1` columns to -x, at or above that start's push level.
    inside: Vec<bool>,
    /// Per group: the number of groups that lie `W` behind it (travel
    /// `<= s - W + 1e-9`); its window level is the level after them.
    behind: Vec<u32>,
    /// Per footprint row: the offset of its deepest entry and the columns
    /// its entries span past that one.
    rows: Vec<(isize, usize)>,
    /// Each row's `dj`.
    dj: Vec<i32>,
    /// The entries of each row, ascending: row `r`'s are
    /// `by_row[row_start[r]..row_start[r + 1]]`.
    by_row: Vec<u32>,
    row_start: Vec<u32>,
}

impl WindowLayers {
    /// Lays out `fp`'s slide list on `grid` for the window `window` (mm).
    /// Each entry's distance is `d0 + m p`, exactly as the per-start
    /// trace computes it, and groups are chained within
    /// [`NODE_TOL`] as there.
    pub fn new(grid: &PaddedGrid, fp: &GridFootprint, window: f64) -> WindowLayers {
        let p = fp.pitch;
        // The start one column to -x dominates this one (its level is at
        // least as high at the node and `W` back) once its own window looks
        // back past its first group: from a travel of `W + p + d0` on,
        // `d0` its first node's distance (a micrometre spare for rounding).
        let d0 = fp.rows.iter().map(|r| r.d0).fold(f64::INFINITY, f64::min);
        let reach = (window + p + d0 + 1e-6).min(window_reach(window, p));
        // (distance, dj, row, offset, layer)
        let mut entries: Vec<(f64, i32, u32, isize, u16)> = Vec::new();
        let mut rows = Vec::with_capacity(fp.rows.len());
        for (r, row) in fp.rows.iter().enumerate() {
            let mut m = 0;
            loop {
                let d = row.d0 + m as f64 * p;
                if m > 0 && d > reach {
                    break;
                }
                let layer = u16::try_from(m).expect("a window of at most 1024 pitches");
                entries.push((d, row.dj, r as u32, grid.offset(row.dj, row.kf - m), layer));
                m += 1;
            }
            rows.push((grid.offset(row.dj, row.kf - (m - 1)), (m - 1) as usize));
        }
        entries.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut group = Vec::with_capacity(entries.len());
        let mut travel: Vec<f64> = Vec::new();
        for (e, entry) in entries.iter().enumerate() {
            if e == 0 || entry.0 - entries[e - 1].0 > NODE_TOL {
                travel.push(entry.0);
            }
            group.push(travel.len() as u32 - 1);
        }
        let mut behind = Vec::with_capacity(travel.len());
        let mut n = 0;
        for (g, &s) in travel.iter().enumerate() {
            let limit = s - window + StrikeRule::WINDOW_TOL;
            while n < g && travel[n] <= limit {
                n += 1;
            }
            behind.push(n as u32);
        }
        let row: Vec<u32> = entries.iter().map(|e| e.2).collect();
        let (by_row, row_start) = by_row(&row, rows.len());
        WindowLayers {
            offsets: entries.iter().map(|e| e.3).collect(),
            group,
            layer: entries.iter().map(|e| e.4).collect(),
            inside: fp.rows.iter().map(|r| r.khi >= r.klo).collect(),
            behind,
            rows,
            dj: fp.rows.iter().map(|r| r.dj).collect(),
            by_row,
            row_start,
        }
    }

    /// The columns the deepest entry lies past the first layer.
    pub fn depth(&self) -> usize {
        self.rows.iter().map(|r| r.1).max().unwrap_or(0)
    }

    /// The rows of a start in row `j0` of a grid of `nz` rows (rows on the
    /// `+inf` padding change nothing, and the minima do not cover them)
    /// any of whose nodes over `lanes` lanes from `base` lies below `top`,
    /// by the minima over `lanes` nodes (`still`; every real row without
    /// it), into `rows`.
    #[allow(clippy::too_many_arguments)]
    pub fn rows_below(
        &self,
        j0: usize,
        nz: usize,
        base: usize,
        lanes: usize,
        top: Rank,
        still: Option<(WindowOf, usize)>,
        rows: &mut Vec<u32>,
    ) {
        rows.clear();
        let real = |dj: i32| (0..nz as i64).contains(&(j0 as i64 + i64::from(dj)));
        for (r, (&(offset, span), &dj)) in self.rows.iter().zip(&self.dj).enumerate() {
            if real(dj) && row_below(base, offset, span, lanes, top, still) {
                rows.push(r as u32);
            }
        }
    }
}

/// Entry indices grouped by row (`row[e]` is entry `e`'s), each group
/// ascending, and where each row's group begins (one more for the end).
fn by_row(row: &[u32], rows: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; rows + 1];
    for &r in row {
        start[r as usize + 1] += 1;
    }
    for r in 0..rows {
        start[r + 1] += start[r];
    }
    let mut next = start.clone();
    let mut by_row = vec![0u32; row.len()];
    for (e, &r) in row.iter().enumerate() {
        by_row[next[r as usize] as usize] = e as u32;
        next[r as usize] += 1;
    }
    (by_row, start)
}

/// Whether a row whose deepest entry is `offset` from `base` and whose
/// entries span `span` more columns holds a node below `top` over `lanes`
/// lanes, by the minima over `lanes` nodes (`true` without them).
#[inline(always)]
fn row_below(
    base: usize,
    offset: isize,
    span: usize,
    lanes: usize,
    top: Rank,
    still: Option<(WindowOf, usize)>,
) -> bool {
    let Some((minima, shift)) = still else {
        return true;
    };
    let first = base.wrapping_add_signed(offset) + shift;
    let last = first + span;
    let mut at = first;
    loop {
        if minima.at(at.min(last)) < top {
            return true;
        }
        if at >= last {
            return false;
        }
        at += lanes;
    }
}

/// What [`slide_block_window`] reads and writes besides the heights.
pub(crate) struct WindowSlide<'a> {
    /// Per node, the lowest level (rank) at which it is a contact.
    pub contact: &'a [Rank],
    /// Per node, the lowest level (rank) `W` back at which it passes the
    /// window's deflection test.
    pub deflected: &'a [Rank],
    /// Per node, the highest level that met it (for the probes).
    pub reach: &'a mut [Rank],
    /// Per node, 1 where a slide struck it.
    pub struck: &'a mut [u8],
    /// Whether to record the reach: only the probes read it.
    pub record_reach: bool,
    /// Scratch: the entries slid over, as bits and in slide order.
    pub slid_bits: &'a mut Vec<u64>,
    /// Scratch: the entries slid over.
    pub slid: &'a mut Vec<u32>,
    /// Scratch: the rows a block may slide.
    pub rows: &'a mut Vec<u32>,
    /// Scratch: the entries that lowered a level.
    pub lowered: &'a mut Vec<u32>,
}

/// Slides `S` consecutive starts over their [`WindowLayers`], each with
/// its own level and its own level `W` back, and marks every node a start
/// strikes by the window rule in `out.struck` (the strike is decided at
/// each visit: it reads two levels, so no single reach per node decides
/// it). `level[w]` is the level start `w` enters with (`yr`, or [`NEVER`]
/// where not placed: it meets nothing).
///
/// Only the footprint rows among `rows` are slid, and in rows with nodes
/// inside the footprint only the layers `m` whose bit is set in `moving`
/// (all from 64 on): the caller clears a layer's bit where no start's push
/// level lies above that of the start `m + 1` columns to -x, whose
/// footprint holds those nodes, so they are at or above every level. Of
/// those, with
/// `still` (the minima over `S` nodes, as in [`slide_block`]), only the
/// rows with a node over these lanes below some start's level: a row with
/// none lowers no level, so it moves no window level, and no node of it
/// is a contact. (The caller passes the rows the whole block may slide,
/// found with wider minima: fewer loads for the rows no lane slides.)
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn slide_block_window<const S: usize>(
    h: &[Rank],
    out: &mut WindowSlide,
    layers: &WindowLayers,
    base: usize,
    level: [Rank; S],
    rows: &[u32],
    moving: u64,
    still: Option<(WindowOf, usize)>,
) {
    let top = level.iter().copied().max().unwrap_or(NEVER);
    if top == NEVER {
        return;
    }
    out.slid_bits.clear();
    out.slid_bits.resize(layers.offsets.len().div_ceil(64), 0);
    for &r in rows {
        let (offset, span) = layers.rows[r as usize];
        if row_below(base, offset, span, S, top, still) {
            let (from, to) = (
                layers.row_start[r as usize],
                layers.row_start[r as usize + 1],
            );
            let inside = layers.inside[r as usize];
            for &e in &layers.by_row[from as usize..to as usize] {
                let m = u32::from(layers.layer[e as usize]);
                if inside && m < 64 && moving >> m & 1 == 0 {
                    continue;
                }
                // Where the rows may be passed over, an entry whose nodes
                // are none below their start's level on entry is passed
                // over too: levels only fall, so it lowers nothing and is
                // no contact. Read here, a row's entries at once (adjacent
                // columns), rather than one by one in slide order.
                if still.is_some() {
                    let a = base.wrapping_add_signed(layers.offsets[e as usize]);
                    let hv: &[Rank; S] = h[a..a + S].try_into().expect("S values");
                    let mut below = 0u32;
                    for w in 0..S {
                        below |= u32::from(hv[w] < level[w]);
                    }
                    if below == 0 {
                        continue;
                    }
                }
                out.slid_bits[e as usize / 64] |= 1 << (e % 64);
            }
        }
    }
    // In slide order.
    out.slid.clear();
    for (n, &word) in out.slid_bits.iter().enumerate() {
        out.slid.extend(ones(word).map(|bit| (n * 64 + bit) as u32));
    }
    let mut level = level;
    let mut before = level;
    let mut earlier = level;
    let mut group = None;
    // The entries that lowered some start's level, and how many of them
    // the window levels have taken in: an entry met at or above every
    // start's level changes no level, so no window level either.
    let mut lowered = std::mem::take(out.lowered);
    lowered.clear();
    let mut trail = 0;
    for k in 0..out.slid.len() {
        let e = out.slid[k] as usize;
        let g = layers.group[e];
        if group != Some(g) {
            group = Some(g);
            before = level;
            let behind = layers.behind[g as usize];
            while trail < lowered.len() && layers.group[lowered[trail] as usize] < behind {
                let a = base.wrapping_add_signed(layers.offsets[lowered[trail] as usize]);
                let hv: &[Rank; S] = h[a..a + S].try_into().expect("S values");
                for w in 0..S {
                    earlier[w] = earlier[w].min(hv[w]);
                }
                trail += 1;
            }
        }
        let a = base.wrapping_add_signed(layers.offsets[e]);
        let hv: &[Rank; S] = h[a..a + S].try_into().expect("S values");
        if out.record_reach {
            let r: &mut [Rank; S] = (&mut out.reach[a..a + S]).try_into().expect("S values");
            for w in 0..S {
                r[w] = r[w].max(before[w]);
            }
        }
        // A node at or above the level it is met at is no contact and
        // lowers nothing: most entries, so they are passed over here.
        let mut below = 0u32;
        for w in 0..S {
            below |= u32::from(hv[w] < before[w]);
        }
        if below == 0 {
            continue;
        }
        lowered.push(e as u32);
        let contact: &[Rank; S] = out.contact[a..a + S].try_into().expect("S values");
        let deflected: &[Rank; S] = out.deflected[a..a + S].try_into().expect("S values");
        let s: &mut [u8; S] = (&mut out.struck[a..a + S]).try_into().expect("S values");
        for w in 0..S {
            s[w] |= u8::from(before[w] >= contact[w]) & u8::from(earlier[w] >= deflected[w]);
            level[w] = level[w].min(hv[w]);
        }
    }
    *out.lowered = lowered;
}

/// The scalar slide of one placed start past its [`WindowLayers`]: where
/// the starts on its -x side are not placed, no newer start dominates it
/// there, so it slides on, one column's first layer at a time, until the
/// first placed start past them has itself travelled [`window_reach`].
#[derive(Debug, Clone)]
pub(crate) struct Extension {
    /// The start's column.
    pub column: i64,
    level: Rank,
    history: LevelHistory<Rank>,
    /// The travel (mm) past which a newer placed start decides for it.
    stop: Option<f64>,
}

impl Extension {
    /// The slide of the start in `column`, pushed to `yr`.
    pub fn new(column: i64, yr: Rank) -> Extension {
        Extension {
            column,
            level: yr,
            history: LevelHistory::new(yr),
            stop: None,
        }
    }

    /// Whether the column `shift` mm of travel on still matters, and if a
    /// placed start stands there (`placed`), from when on it no longer
    /// will.
    pub fn goes_on(&mut self, shift: f64, placed: bool, window: f64, pitch: f64) -> bool {
        if self.stop.is_some_and(|stop| shift > stop) {
            return false;
        }
        if placed && self.stop.is_none() {
            self.stop = Some(shift + window_reach(window, pitch));
        }
        true
    }

    /// Slides over the first layer `layer` of the column whose node is
    /// `node` (in `h`'s indexing), `shift` mm of this start's travel past
    /// its own node, judging each node by the window rule (`window` mm).
    #[allow(clippy::too_many_arguments)]
    pub fn advance(
        &mut self,
        h: &[Rank],
        out: &mut WindowSlide,
        layer: &LayerRows,
        node: usize,
        shift: f64,
        window: f64,
    ) {
        let at = |offset: &isize| node.wrapping_add_signed(*offset);
        if layer.offsets.iter().all(|o| h[at(o)] == OFF) {
            return;
        }
        let mut group = None;
        let mut before = self.level;
        let mut earlier = self.level;
        let mut travel = 0.0;
        for ((offset, &g), &d) in layer.offsets.iter().zip(&layer.group).zip(&layer.d) {
            if group != Some(g) {
                if group.is_some() && self.level < before {
                    self.history.push(travel, self.level);
                }
                group = Some(g);
                before = self.level;
                travel = d + shift;
                earlier = self.history.earlier(travel, window);
            }
            let a = at(offset);
            out.reach[a] = out.reach[a].max(before);
            out.struck[a] |=
                u8::from(before >= out.contact[a]) & u8::from(earlier >= out.deflected[a]);
            self.level = self.level.min(h[a]);
        }
        if group.is_some() && self.level < before {
            self.history.push(travel, self.level);
        }
    }
}
