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
//! Heights and levels are taken as their ranks ([`crate::ranked`]), and
//! the rule as each node's threshold rank: the same comparisons, exactly.

use crate::kneeform::GridFootprint;
use crate::padded::PaddedGrid;
use crate::push::WindowOf;
use crate::ranked::{NEVER, OFF, Rank};

/// The first layer of one footprint, ready for [`slide_block`]: the offset
/// from a start's node to the first node in front in each footprint row, in
/// slide order, and the tie groups (runs of that order whose distances
/// agree within [`NODE_TOL`](crate::kneeform::NODE_TOL)).
#[derive(Debug, Clone)]
pub struct LayerRows {
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
        };
        for n in (0..self.offsets.len()).filter(|&n| real(self.dj[n])) {
            layer.offsets.push(self.offsets[n]);
            layer.group.push(self.group[n]);
            layer.dj.push(self.dj[n]);
            layer.inside.push(self.inside[n]);
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
/// ([`crate::ranked::RankedGrid::thresholds`]), so it decides no strike.
/// Its reach stays as it was, so a caller that reads the reach at levels
/// below the nodes (the engine's probes) passes `None`.
#[inline(always)]
pub fn slide_block<const W: usize>(
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
pub fn slide_carried(
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
