//! Probes: grid cells with a height in them (a blind spot's lowest point),
//! and the bitmaps through which a band's slides tell each probe the face
//! levels that met its cell's corners ([`AngleMask::probes_met`]).
//!
//! [`AngleMask::probes_met`]: super::AngleMask::probes_met

use crate::engine::padded::PaddedGrid;
use crate::engine::ranked::Rank;
use crate::engine::slide::{LayerRows, ones};
use crate::kneeform::GridFootprint;

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

impl Probe {
    /// The padded indices of the cell's corner nodes that lie on `padded`'s
    /// grid (a cell of the last row has only two).
    pub(super) fn corner_nodes<'a>(
        &self,
        padded: &'a PaddedGrid,
    ) -> impl Iterator<Item = usize> + 'a {
        let (i, j) = (self.cell.0 as i64, self.cell.1 as i64);
        let nz = padded.spec.nz as i64;
        [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
            .into_iter()
            .filter(move |&(_, jj)| jj < nz)
            .map(|(ii, jj)| padded.index(jj, ii as i32))
    }
}

/// The probed nodes the slides of a band meet. A skipped block of slides
/// ([`fast_band_impl`]) still raises their reach to the level that met
/// them, so that the probes see every level, as without the skip.
///
/// Two bitmaps, so that neither time nor memory grows with the probes
/// beyond one pass over their corners: the probes' corner nodes over the
/// band's reach window, and per start row of the band the starts whose
/// first layer holds one (a part with tens of thousands of blind spots
/// once made sorted lists of these visits take most of an analysis's time
/// and eight times its memory estimate).
pub(super) struct ProbeVisits {
    /// A bit per node of the reach window: the probes' corner nodes.
    corners: Vec<u64>,
    /// Per start row of the band, a bit per column of its padded row: the
    /// starts whose first layer holds a corner. Empty without probes.
    starts: Vec<Vec<u64>>,
    /// Per start row of the band, the padded index of its row's first node.
    row_first: Vec<usize>,
    /// The padded index of the reach window's first node.
    window: usize,
}

impl ProbeVisits {
    /// The visits of `probes` by the slides of `band` at the angle of `fp`,
    /// with the reach window the `len` padded nodes from `window`.
    pub(super) fn new(
        padded: &PaddedGrid,
        fp: &GridFootprint,
        band: &[usize],
        window: usize,
        len: usize,
        probes: &[Probe],
    ) -> ProbeVisits {
        let stride = padded.stride;
        let row_first: Vec<usize> = band
            .iter()
            .map(|&j0| padded.index(j0 as i64, 0) - padded.pad_lo)
            .collect();
        let corners: Vec<usize> = probes
            .iter()
            .flat_map(|probe| probe.corner_nodes(padded))
            .filter(|node| (window..window + len).contains(node))
            .collect();
        if corners.is_empty() || band.is_empty() {
            return ProbeVisits {
                corners: Vec::new(),
                starts: Vec::new(),
                row_first,
                window,
            };
        }
        let mut corner_bits = vec![0u64; len.div_ceil(64)];
        for &node in &corners {
            set_bit(&mut corner_bits, node - window);
        }
        // The band's start rows by row (a band need not be consecutive rows).
        let lo = *band.iter().min().expect("a band has rows");
        let hi = *band.iter().max().expect("a band has rows");
        let mut k_of = vec![None; hi - lo + 1];
        for (k, &j0) in band.iter().enumerate() {
            k_of[j0 - lo] = Some(k);
        }
        let layer = LayerRows::new(padded, fp);
        let mut starts = vec![vec![0u64; stride.div_ceil(64)]; band.len()];
        for &node in &corners {
            let (row, column) = ((node / stride) as i64, (node % stride) as i64);
            for (dj, offset) in layer.rows() {
                // The start `node - offset`: `dj` rows and `kf` columns back.
                let kf = offset as i64 - i64::from(dj) * stride as i64;
                let j0 = row - padded.pad_rows as i64 - i64::from(dj);
                let start = column - kf;
                let k = usize::try_from(j0 - lo as i64)
                    .ok()
                    .and_then(|r| k_of.get(r).copied().flatten());
                if let Some(k) = k
                    && (0..stride as i64).contains(&start)
                {
                    set_bit(&mut starts[k], start as usize);
                }
            }
        }
        ProbeVisits {
            corners: corner_bits,
            starts,
            row_first,
            window,
        }
    }

    /// Whether any probe's corner lies in the band's reach window: only
    /// then is the reach read.
    pub(super) fn probed(&self) -> bool {
        !self.corners.is_empty()
    }

    /// Whether a start of the `k`-th start row's block of `width` starts
    /// from the padded node `first` meets a probed node.
    pub(super) fn any(&self, k: usize, first: usize, width: usize) -> bool {
        self.starts
            .get(k)
            .is_some_and(|starts| any_bit(starts, first - self.row_first[k], width))
    }

    /// Raises the reach of the probed nodes met by the `k`-th start row's
    /// block of starts from the padded node `first`, whose levels, unchanged
    /// across their first layers (`layer`), are `level`.
    pub(super) fn record<const W: usize>(
        &self,
        k: usize,
        first: usize,
        layer: &LayerRows,
        level: &[Rank; W],
        reach: &mut [Rank],
    ) {
        if !self.any(k, first, W) {
            return;
        }
        for (_, offset) in layer.rows() {
            let a = first.wrapping_add_signed(offset) - self.window;
            for n in set_bits(&self.corners, a, W) {
                reach[n] = reach[n].max(level[n - a]);
            }
        }
    }
}

/// Sets bit `n` of `bits`.
fn set_bit(bits: &mut [u64], n: usize) {
    bits[n / 64] |= 1 << (n % 64);
}

/// The bits `from .. from + len` of `bits`, a word at a time: each word's
/// part as `(first bit, its bits shifted down)`.
fn bit_runs(bits: &[u64], from: usize, len: usize) -> impl Iterator<Item = (usize, u64)> + '_ {
    let end = from + len;
    std::iter::successors(Some(from).filter(|&n| n < end), move |&n| {
        Some(n + 64 - n % 64).filter(|&n| n < end)
    })
    .map(move |n| {
        let take = (64 - n % 64).min(end - n);
        let word = bits.get(n / 64).copied().unwrap_or(0) >> (n % 64);
        (
            n,
            if take == 64 {
                word
            } else {
                word & ((1 << take) - 1)
            },
        )
    })
}

/// Whether any of the bits `from .. from + len` of `bits` is set.
fn any_bit(bits: &[u64], from: usize, len: usize) -> bool {
    bit_runs(bits, from, len).any(|(_, word)| word != 0)
}

/// The set bits among `from .. from + len` of `bits`, ascending.
fn set_bits(bits: &[u64], from: usize, len: usize) -> impl Iterator<Item = usize> + '_ {
    bit_runs(bits, from, len).flat_map(|(n, word)| ones(word).map(move |bit| n + bit))
}
