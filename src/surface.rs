//! SPEC v4, "The level follows the grid's surface": the grid's
//! piecewise-linear surface `S` ([`SurfaceGrid`]), the knee-form's outline
//! as the surface level samples it ([`SurfaceFootprint`]), and one start's
//! push and slide on `S` ([`trace`]).
//!
//! `S` interpolates the node heights linearly on the two triangles of each
//! closed cell `[x_i, x_i+1] x [z_j, z_j+1]`, split along its diagonal from
//! `(i, j)` to `(i+1, j+1)`; a cell with a node of infinite height has no
//! surface (`+inf`). Positions are in grid units (`u = (x - x_0) / p`,
//! `w = (z - z_0) / p`), so a start's samples at travel `s_k = k p / 8`
//! sit at `u = (i0 - k / 8) + du`, the same position, to the bit, for
//! every start that reaches it.
//!
//! **The evaluation, as SPEC v4 writes it, with the readings where it
//! leaves a choice:**
//!
//! * the outline is sampled at every `p / 4` in z (which holds the rows'
//!   exact crossings), at its top and bottom, and between two samples more
//!   than `p / 4` apart at the midpoint in z, recursively (the outline runs
//!   steeply near its top and bottom);
//! * the **push** evaluates the nodes inside and the whole outline, leading
//!   (`a(dz)`) and trailing (`b(dz)`): `yr` is their minimum, its witness
//!   the first lowest point in the order leading, trailing, nodes;
//! * each **step** `k >= 1` evaluates the leading outline at `s_k`, then
//!   the nodes met in `(s_{k-1}, s_k]` (a node at distance `d` is met when
//!   `d <= s_k + 1e-9`), rows by `dj`; a step whose minimum lies more
//!   than `e0` below the level is a **contact**, its witness the first
//!   lowest point in that order, and the level falls to it; a smaller
//!   fall is rounding and leaves the level (SPEC's `e0`: so a plate at
//!   the level is skipped, not evaluated at every step);
//! * **bisection**: when a step's contact witness lies more than `p / 2`
//!   from the previous contact's (the push's for the first), the travel
//!   between the step before and this one is bisected, at most 5 levels:
//!   a midpoint evaluates the leading outline only; its witness is its
//!   first lowest point more than `e0` below the level `f0` held before
//!   the step (the left end's witness where none is); a half is bisected
//!   only while its end witnesses are more than `p / 2` apart; midpoints are
//!   applied in travel order, each fall of more than `e0` a contact;
//! * **ties**: a contact that strikes marks, beside its witness, every
//!   point of the leading outline at the same travel within `tau` of the
//!   new level, `tau` read at the witness's cell ([`SurfaceGrid::tau`]: a
//!   quarter of the largest second difference there, at most `p / 4`),
//!   as SPEC says, **each judged by the window rule on its own value**
//!   `v`, `f(s - W) - v > sigma W`, as the node level judges each node of
//!   a group. SPEC's words give every tie the contact's decision; read
//!   so, a site the knee-form rests on and is leaving is marked with a
//!   contact's drop elsewhere (its own is zero): the angled features'
//!   and the bump's false alarms of 82-190 mm (a SPEC change proposed;
//!   `results/gate.md`). Until 2026-11-29 the engine marked one point
//!   per contact site within its own cell's `tau`, which left the
//!   contact's side of a crease between node columns unmarked (the
//!   README console's area miss);
//! * **strike**: SPEC's window rule on this level curve, through
//!   [`StrikeRule::window_strikes`] with the new level as `h` (whatever the
//!   rule's rate: the surface level has the window rule only);
//! * the mask holds the node nearest each struck witness (a tie to the
//!   smaller `i`, then the smaller `j`).
//!
//! [`trace`] skips work where it provably changes nothing: a run of
//! [`BLOCK`] outline samples is not evaluated while a lower bound of every
//! node its cells read ([`SurfaceGrid::bound`]) is at or above the level
//! less `e0` (the level only falls), and the slide ends once such a bound
//! of everything still ahead is. `tests/surface.rs` holds it equal to a
//! brute force transcribed from SPEC that evaluates everything.

use crate::grid::{HeightGrid, NODE_TOL};
use crate::kneeform::GridFootprint;
use crate::strike::{LevelHistory, StrikeRule};

/// Steps per pitch: the travels `s_k = k p / 8`.
pub(crate) const STEPS_PER_PITCH: f64 = 8.0;
/// Outline samples per pitch, in z and at most apart along the outline.
const SAMPLES_PER_PITCH: f64 = 4.0;
/// Witnesses further apart than this (pitches) call for a bisection.
const BISECT_APART: f64 = 0.5;
/// Bisection levels.
const BISECT_DEPTH: u32 = 5;
/// Outline samples per run that [`trace`] skips as one.
pub(crate) const BLOCK: usize = 16;
/// Nodes per side of the blocks whose minima bound the surface.
const COARSE: usize = 4;
/// Levels of [`SurfaceGrid`]'s row spans: exact bounds over fewer than
/// `2^(SPAN_LEVELS + 1)` columns.
pub(crate) const SPAN_LEVELS: usize = 3;
/// Rows of [`SurfaceGrid`]'s tall spans.
const TALL: usize = 4;
/// The largest `tau`, in pitches.
const TAU_CAP: f64 = 0.25;

/// The grid's surface `S`, with the block minima that bound it.
#[derive(Debug)]
pub(crate) struct SurfaceGrid<'a> {
    grid: &'a HeightGrid,
    /// Minimum finite height per block of `COARSE x COARSE` nodes.
    coarse: Vec<f64>,
    /// Blocks per coarse row.
    cnx: usize,
    /// Per coarse row, the prefix minimum of `coarse` along it.
    prefix: Vec<f64>,
    /// `spans[k][j * nx + i]`: the least height of nodes `i..i + 2^(k+1)`
    /// of row `j` (those on the grid), for the runs' tight bounds; empty
    /// unless [`SurfaceGrid::with_spans`].
    spans: Vec<Vec<f64>>,
    /// `tall[k][j * nx + i]`: the least of `spans[k]` over rows `j..j +
    /// TALL` (rows `j <= nz - TALL`), so that a bound over `TALL ..= 2
    /// TALL` rows reads two overlapping windows of rows, not each row;
    /// empty unless [`SurfaceGrid::with_spans`].
    tall: Vec<Vec<f64>>,
}

impl<'a> SurfaceGrid<'a> {
    /// The surface of `grid`.
    pub fn new(grid: &'a HeightGrid) -> SurfaceGrid<'a> {
        let (nx, nz) = (grid.spec.nx, grid.spec.nz);
        let cnx = nx.div_ceil(COARSE).max(1);
        let cnz = nz.div_ceil(COARSE).max(1);
        let mut coarse = vec![f64::INFINITY; cnx * cnz];
        for j in 0..nz {
            for i in 0..nx {
                let c = &mut coarse[(j / COARSE) * cnx + i / COARSE];
                *c = c.min(grid.at(i, j));
            }
        }
        let mut prefix = coarse.clone();
        for row in prefix.chunks_exact_mut(cnx) {
            for b in 1..cnx {
                row[b] = row[b].min(row[b - 1]);
            }
        }
        SurfaceGrid {
            grid,
            coarse,
            cnx,
            prefix,
            spans: Vec::new(),
            tall: Vec::new(),
        }
    }

    /// With the row spans that make [`SurfaceGrid::bound`] exact over
    /// narrow runs (three more copies of the heights: for the engine's
    /// slides, not for one start's trace).
    pub fn with_spans(mut self) -> SurfaceGrid<'a> {
        let nx = self.grid.spec.nx;
        let mut spans: Vec<Vec<f64>> = Vec::with_capacity(SPAN_LEVELS);
        for k in 0..SPAN_LEVELS {
            let half = 1usize << k;
            let last = spans.last().unwrap_or(&self.grid.h);
            let mut next = last.clone();
            for (row, from) in next.chunks_exact_mut(nx).zip(last.chunks_exact(nx)) {
                for i in 0..nx.saturating_sub(half) {
                    row[i] = from[i].min(from[i + half]);
                }
            }
            spans.push(next);
        }
        let nz = self.grid.spec.nz;
        self.tall = spans
            .iter()
            .map(|span| {
                let mut tall = span.clone();
                for j in 0..(nz + 1).saturating_sub(TALL) {
                    for i in 0..nx {
                        tall[j * nx + i] = (0..TALL)
                            .fold(f64::INFINITY, |least, d| least.min(span[(j + d) * nx + i]));
                    }
                }
                tall
            })
            .collect();
        self.spans = spans;
        self
    }

    /// The cell `(i, j)` holding `(u, w)`, or `None` off the grid: the
    /// column [`SurfaceGrid::column_of`] finds and the row
    /// [`SurfaceGrid::row_of`] finds, as [`SurfaceGrid::at`] reads them. A
    /// point on the last column or row belongs to the cell before it.
    fn cell(&self, u: f64, w: f64) -> Option<(usize, usize)> {
        let (first, _) = self.row_of(w)?;
        let (i, _) = self.column_of(u)?;
        Some((i, first / self.grid.spec.nx))
    }

    /// `S` at `(u, w)` (grid units): `+inf` off the grid and on a cell
    /// with a node of infinite height.
    #[inline(always)]
    pub fn at(&self, u: f64, w: f64) -> f64 {
        self.at_in(u, self.row_of(w))
    }

    /// The cell row holding `w` (grid units) as [`SurfaceGrid::at_in`]
    /// reads it: the index of its first node and the position in it,
    /// `None` off the grid. The same for every sample of a start row at
    /// the same `dw`, so found once per row.
    #[inline(always)]
    pub fn row_of(&self, w: f64) -> Option<(usize, f64)> {
        let (nx, nz) = (self.grid.spec.nx, self.grid.spec.nz);
        if nx < 2 || nz < 2 || !(0.0..=(nz - 1) as f64).contains(&w) {
            return None;
        }
        // `w >= 0` here, where truncation is the floor.
        let j = (w as usize).min(nz - 2);
        Some((j * nx, w - j as f64))
    }

    /// The cell column holding `u` (grid units) and the position in it,
    /// `None` off the grid (a point on the last column belongs to the
    /// cell before it).
    #[inline(always)]
    fn column_of(&self, u: f64) -> Option<(usize, f64)> {
        let (nx, nz) = (self.grid.spec.nx, self.grid.spec.nz);
        if nx < 2 || nz < 2 || !(0.0..=(nx - 1) as f64).contains(&u) {
            return None;
        }
        // `u >= 0` here, where truncation is the floor.
        let i = (u as usize).min(nx - 2);
        Some((i, u - i as f64))
    }

    /// [`SurfaceGrid::at`] at `(u, w)`, `w`'s cell row `row` as
    /// [`SurfaceGrid::row_of`] finds it once per start row.
    #[inline(always)]
    pub fn at_in(&self, u: f64, row: Option<(usize, f64)>) -> f64 {
        let nx = self.grid.spec.nx;
        let (Some((first, fz)), Some((i, fx))) = (row, self.column_of(u)) else {
            return f64::INFINITY;
        };
        let h = &self.grid.h;
        let n = first + i;
        let (h00, h10, h01, h11) = (h[n], h[n + 1], h[n + nx], h[n + nx + 1]);
        if !(h00.is_finite() && h10.is_finite() && h01.is_finite() && h11.is_finite()) {
            return f64::INFINITY;
        }
        if fx >= fz {
            h00 + fx * (h10 - h00) + fz * (h11 - h10)
        } else {
            h00 + fz * (h01 - h00) + fx * (h11 - h01)
        }
    }

    /// A bound of `S`'s interpolation error at the cell holding `(u, w)`
    /// (mm): a quarter of the largest second difference of the heights
    /// (along x, z and both diagonals) centred on one of the cell's
    /// corners, at most `p / 4`. A second difference is `p^2 h''` on a
    /// smooth surface (the interpolation error is about `p^2 |h''| / 8`,
    /// so this is twice it) and `p |delta g|` across a crease (the error
    /// is `p |delta g| / 4`). Where the heights are all equal it is 0.
    pub fn tau(&self, u: f64, w: f64) -> f64 {
        let Some((i, j)) = self.cell(u, w) else {
            return 0.0;
        };
        self.tau_cell(i, j)
    }

    /// [`SurfaceGrid::tau`] at cell `(i, j)`.
    fn tau_cell(&self, i: usize, j: usize) -> f64 {
        let (nx, nz) = (self.grid.spec.nx as i64, self.grid.spec.nz as i64);
        let h = |i: i64, j: i64| {
            if (0..nx).contains(&i) && (0..nz).contains(&j) {
                self.grid.at(i as usize, j as usize)
            } else {
                f64::INFINITY
            }
        };
        let mut second = 0.0f64;
        for (ci, cj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (ci, cj) = (i as i64 + ci, j as i64 + cj);
            for (di, dj) in [(1, 0), (0, 1), (1, 1), (1, -1)] {
                let d = h(ci - di, cj - dj) - 2.0 * h(ci, cj) + h(ci + di, cj + dj);
                if d.is_finite() {
                    second = second.max(d.abs());
                }
            }
        }
        (second / 4.0).min(TAU_CAP * self.grid.spec.pitch)
    }

    /// A lower bound of `S` at every point of the cells in columns
    /// `c_lo..=c_hi` and rows `w_lo..=w_hi` (grid units): the least height
    /// of their nodes, read from the block minima (`+inf` off the grid),
    /// less a margin for rounding.
    ///
    /// Where the columns are fewer than `2^(SPAN_LEVELS + 1)` (and the
    /// spans are built) the least height is exact (the spans' two overlapping windows per row);
    /// otherwise it is read from the `COARSE x COARSE` block minima.
    #[inline]
    pub fn bound(&self, (c_lo, c_hi): (i64, i64), (w_lo, w_hi): (f64, f64)) -> f64 {
        let (nx, nz) = (self.grid.spec.nx as i64, self.grid.spec.nz as f64);
        if c_hi < 0 || c_lo > nx - 1 || w_hi < 0.0 || w_lo > nz - 1.0 {
            return f64::INFINITY;
        }
        let (lo, hi) = (
            c_lo.clamp(0, nx - 1) as usize,
            c_hi.clamp(0, nx - 1) as usize,
        );
        let k = (hi - lo + 1).ilog2() as usize;
        if k <= self.spans.len() {
            // The crate's `floor`: the library's is a call per bound.
            let node_row = |v: i64| v.clamp(0, nz as i64 - 1) as usize;
            let (r_lo, r_hi) = (node_row(floor(w_lo)), node_row(floor(w_hi) + 1));
            let (table, second) = match k {
                0 => (&self.grid.h, lo),
                _ => (&self.spans[k - 1], hi + 1 - (1 << k)),
            };
            let nx = nx as usize;
            let rows = r_hi - r_lo + 1;
            if k >= 1 && (TALL..=2 * TALL).contains(&rows) {
                // The same nodes, so the same least height, to the bit.
                let tall = &self.tall[k - 1];
                let (top, bottom) = (r_lo * nx, (r_hi + 1 - TALL) * nx);
                return below(
                    tall[top + lo]
                        .min(tall[top + second])
                        .min(tall[bottom + lo])
                        .min(tall[bottom + second]),
                );
            }
            let mut least = f64::INFINITY;
            for r in r_lo..=r_hi {
                least = least.min(table[r * nx + lo]).min(table[r * nx + second]);
            }
            return below(least);
        }
        let column = |c: i64| (c.clamp(0, nx - 1) as usize) / COARSE;
        let row = |v: i64| v.clamp(0, nz as i64 - 1) as usize / COARSE;
        let (b_lo, b_hi) = (column(c_lo), column(c_hi));
        let (r_lo, r_hi) = (row(floor(w_lo)), row(floor(w_hi) + 1));
        let mut least = f64::INFINITY;
        for r in r_lo..=r_hi {
            for &c in &self.coarse[r * self.cnx + b_lo..=r * self.cnx + b_hi] {
                least = least.min(c);
            }
        }
        below(least)
    }

    /// [`SurfaceGrid::bound`] of every node in columns `0..=u_hi` and rows
    /// `w_lo..=w_hi` (grid units). `memo` keeps the last block column read
    /// and its bound: a slide asks at every step for the same rows, and
    /// the block column changes once in `8 COARSE` steps.
    pub fn bound_before(
        &self,
        u_hi: f64,
        (w_lo, w_hi): (f64, f64),
        memo: &mut Option<(usize, f64)>,
    ) -> f64 {
        let (nx, nz) = (self.grid.spec.nx as i64, self.grid.spec.nz as f64);
        if u_hi < 0.0 || w_hi < 0.0 || w_lo > nz - 1.0 {
            return f64::INFINITY;
        }
        let b = (floor(u_hi) + 1).clamp(0, nx - 1) as usize / COARSE;
        if let Some((column, bound)) = *memo
            && column == b
        {
            return bound;
        }
        let clip = |v: f64, n: f64| (v.max(0.0).min(n - 1.0) as usize) / COARSE;
        let (r_lo, r_hi) = (clip(w_lo.floor(), nz), clip(w_hi.floor() + 1.0, nz));
        let mut least = f64::INFINITY;
        for r in r_lo..=r_hi {
            least = least.min(self.prefix[r * self.cnx + b]);
        }
        let bound = below(least);
        *memo = Some((b, bound));
        bound
    }
}

/// A value a little below `v`, by more than the rounding of an
/// interpolation between heights of its size.
#[inline(always)]
fn below(v: f64) -> f64 {
    if v.is_finite() {
        v - 1e-9 * (1.0 + v.abs())
    } else {
        v
    }
}

/// The knee-form's outline at one angle as the surface level samples it,
/// and the footprint's rows on the grid.
#[derive(Debug, Clone)]
pub(crate) struct SurfaceFootprint {
    /// The leading outline `(a(dz) / p, dz / p)`, by increasing `dz`.
    pub lead: Vec<[f64; 2]>,
    /// The trailing outline `(b(dz) / p, dz / p)`, by increasing `dz`.
    pub trail: Vec<[f64; 2]>,
    /// Runs of [`BLOCK`] leading samples: the range and its extent
    /// `(du_lo, du_hi, dw_lo, dw_hi)`.
    pub blocks: Vec<(std::ops::Range<usize>, [f64; 4])>,
    /// The same runs of the trailing samples.
    pub trail_blocks: Vec<(std::ops::Range<usize>, [f64; 4])>,
    /// The extent of the leading outline, `(du_max, dw_lo, dw_hi)`.
    pub extent: (f64, f64, f64),
    /// The footprint's rows: `(dj, klo, khi, kf, d0)`, by `dj`.
    pub rows: Vec<(i32, i32, i32, i32, f64)>,
    /// Indices into `rows` in the order the slide meets their first nodes
    /// in front (by `d0`, then `dj`).
    pub slide_order: Vec<u32>,
    /// The pitch (mm).
    pub pitch: f64,
}

impl SurfaceFootprint {
    /// The outline of `fp`'s shape, sampled as SPEC v4 says.
    pub fn new(fp: &GridFootprint) -> SurfaceFootprint {
        let p = fp.pitch;
        let shape = &fp.shape;
        let (z_lo, z_hi) = shape.z_range();
        let step = 1.0 / SAMPLES_PER_PITCH;
        let m_lo = (z_lo / p / step).ceil() as i64;
        let m_hi = (z_hi / p / step).floor() as i64;
        // dz / p: the bottom, the lattice of p / 4 (rows exactly), the top.
        let mut dws = vec![z_lo / p];
        dws.extend((m_lo..=m_hi).map(|m| {
            if m % 4 == 0 {
                (m / 4) as f64
            } else {
                m as f64 * step
            }
        }));
        dws.push(z_hi / p);
        dws.dedup();
        let side = |pick: fn((f64, f64)) -> f64| -> Vec<[f64; 2]> {
            let at = |dw: f64| shape.row_interval(dw * p).map(|iv| [pick(iv) / p, dw]);
            let mut out: Vec<[f64; 2]> = Vec::new();
            let mut prev: Option<[f64; 2]> = None;
            for &dw in &dws {
                let Some(here) = at(dw) else { continue };
                if let Some(before) = prev {
                    refine(&at, before, here, &mut out, 0);
                }
                out.push(here);
                prev = Some(here);
            }
            out
        };
        let lead = side(|iv| iv.0);
        let trail = side(|iv| iv.1);
        let blocks = runs(&lead);
        let trail_blocks = runs(&trail);
        let extent = lead.iter().fold(
            (f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY),
            |(u, lo, hi), &[du, dw]| (u.max(du), lo.min(dw), hi.max(dw)),
        );
        SurfaceFootprint {
            lead,
            trail,
            blocks,
            trail_blocks,
            extent,
            rows: fp
                .rows
                .iter()
                .map(|r| (r.dj, r.klo, r.khi, r.kf, r.d0))
                .collect(),
            slide_order: fp.slide_order.clone(),
            pitch: p,
        }
    }
}

/// Runs of [`BLOCK`] consecutive samples of `side` and their extents
/// `(du_lo, du_hi, dw_lo, dw_hi)` (grid units).
fn runs(side: &[[f64; 2]]) -> Vec<(std::ops::Range<usize>, [f64; 4])> {
    (0..side.len())
        .step_by(BLOCK)
        .map(|lo| {
            let hi = (lo + BLOCK).min(side.len());
            let mut e = [
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ];
            for &[du, dw] in &side[lo..hi] {
                e = [e[0].min(du), e[1].max(du), e[2].min(dw), e[3].max(dw)];
            }
            (lo..hi, e)
        })
        .collect()
}

/// Inserts, in z order, the outline samples between `a` and `b` (grid
/// units) that keep consecutive ones at most `p / 4` apart: the midpoint
/// in z, recursively (at most 20 levels).
fn refine(
    at: &impl Fn(f64) -> Option<[f64; 2]>,
    a: [f64; 2],
    b: [f64; 2],
    out: &mut Vec<[f64; 2]>,
    depth: u32,
) {
    let apart = (a[0] - b[0]).hypot(a[1] - b[1]);
    if apart <= 1.0 / SAMPLES_PER_PITCH || depth >= 20 {
        return;
    }
    let Some(mid) = at((a[1] + b[1]) / 2.0) else {
        return;
    };
    refine(at, a, mid, out, depth + 1);
    out.push(mid);
    refine(at, mid, b, out, depth + 1);
}

/// One start's push and slide on the surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct SurfaceTrace {
    /// The pushed level (mm), `+inf` when not placed.
    pub yr: f64,
    /// Each strike, in travel order (a node may recur).
    pub strikes: Vec<SurfaceStrike>,
    /// `(travel, level)` after each evaluation that lowered the level.
    pub levels: Vec<(f64, f64)>,
}

/// One strike of a [`SurfaceTrace`]: the node nearest its witness, and
/// what the window rule judged there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SurfaceStrike {
    /// The node `(i, j)` nearest the witness.
    pub node: (usize, usize),
    /// The travel of the strike (mm).
    pub travel: f64,
    /// The surface's value at the witness (mm): the new level for the
    /// contact's own witness, the tie's own value (within `slack` above
    /// the level) for a tie.
    pub value: f64,
    /// How far above the new level a witness could be and still count
    /// (mm): 0 for the contact's witness, the witness cell's `tau` for a
    /// tie.
    pub slack: f64,
}

/// A point evaluated: its value and where it is (grid units).
#[derive(Debug, Clone, Copy)]
struct Point {
    value: f64,
    at: [f64; 2],
}

/// A contact that struck: its level, its witness and the level over the
/// window behind (`f(s - W)`), all its ties read.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Struck {
    level: f64,
    at: [f64; 2],
    earlier: f64,
}

/// The first lowest of the points handed in.
#[derive(Debug, Clone, Copy)]
struct Lowest(Option<Point>);

impl Lowest {
    #[inline(always)]
    fn take(&mut self, value: f64, at: [f64; 2]) {
        if value < self.0.map_or(f64::INFINITY, |p| p.value) {
            self.0 = Some(Point { value, at });
        }
    }
}

/// [`SurfaceGrid::bound`] of each run of leading samples ([`BLOCK`]) of
/// one start row, by the first column the run reads: the same for every
/// start of the row, so read once per row.
#[derive(Debug, Default)]
struct Bounds {
    /// The first column of the table.
    lo: i64,
    /// Columns per run.
    width: usize,
    /// `[run * width + column - lo]`, NaN where not read yet.
    table: Vec<f64>,
    /// Per run, its columns beyond the first ([`span`]).
    spans: Vec<i64>,
    /// The least bound of each group of [`GROUP`] runs by position on the
    /// travel lattice: `[(m - m_lo) * per + group]` (a position's groups
    /// side by side: a step reads them in turn), NaN where not read yet.
    groups: Vec<f64>,
    /// Groups per position.
    per: usize,
    /// The first position of `groups`.
    m_lo: i64,
    /// Positions per group.
    positions: usize,
}

/// `read()`, kept in `table[n]` (NaN until read) where `n` is a slot;
/// read each time where it is not.
#[inline]
fn kept(table: &mut [f64], n: Option<usize>, read: impl FnOnce() -> f64) -> f64 {
    let Some(n) = n else {
        return read();
    };
    if table[n].is_nan() {
        table[n] = read();
    }
    table[n]
}

/// Runs per group of [`Bounds`]: a group whose least bound is at or above
/// the limit is skipped whole.
const GROUP: usize = 8;

impl Bounds {
    /// A table for the runs `blocks` over the columns the slides of a row
    /// of `nx` starts read (others are read as asked, not kept), `reach`
    /// columns left of column 0 at most.
    fn new(blocks: &[(std::ops::Range<usize>, [f64; 4])], nx: usize, reach: i64) -> Bounds {
        let (du_lo, du_hi) = blocks
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, e)| {
                (lo.min(e[0]), hi.max(e[0]))
            });
        let spans = blocks.iter().map(|(_, e)| span(e)).collect();
        if !(du_lo.is_finite() && du_hi.is_finite()) {
            return Bounds {
                spans,
                ..Bounds::default()
            };
        }
        let lo = floor(du_lo) - reach - 2;
        let hi = nx as i64 + floor(du_hi) + 2;
        let width = usize::try_from(hi - lo + 1).unwrap_or(0);
        let m_lo = -(STEPS_PER_PITCH as i64) * reach;
        let positions = usize::try_from(STEPS_PER_PITCH as i64 * nx as i64 - m_lo + 1).unwrap_or(0);
        Bounds {
            lo,
            width,
            table: vec![f64::NAN; blocks.len() * width],
            spans,
            groups: vec![f64::NAN; blocks.len().div_ceil(GROUP) * positions],
            per: blocks.len().div_ceil(GROUP),
            m_lo,
            positions,
        }
    }

    /// The columns run `b`, its extent `e`, reads when the outline's
    /// reference sits at `base`, and their slot in `table`
    /// (`None` where the table does not keep them).
    #[inline]
    fn slot(&self, b: usize, e: &[f64; 4], base: f64) -> ((i64, i64), Option<usize>) {
        let first = floor(base + e[0]);
        let n = usize::try_from(first - self.lo)
            .ok()
            .filter(|&c| c < self.width)
            .map(|c| b * self.width + c);
        ((first, first + self.spans[b]), n)
    }

    /// The bound of run `b`, its extent `e`, when the outline's reference
    /// sits at `(base, j0)`.
    #[inline]
    fn get(&mut self, sg: &SurfaceGrid, b: usize, e: &[f64; 4], (base, j0): (f64, f64)) -> f64 {
        let (cols, n) = self.slot(b, e, base);
        kept(&mut self.table, n, || {
            sg.bound(cols, (j0 + e[2], j0 + e[3]))
        })
    }

    /// The least bound of the runs of group `g` of `blocks` at `(base,
    /// j0)`: kept by position where `base` lies on the travel lattice.
    #[inline]
    fn group(
        &mut self,
        sg: &SurfaceGrid,
        blocks: &[(std::ops::Range<usize>, [f64; 4])],
        g: usize,
        (base, j0): (f64, f64),
    ) -> f64 {
        let runs = g * GROUP..((g + 1) * GROUP).min(blocks.len());
        let m = base * STEPS_PER_PITCH;
        // Whole (without the library's `trunc`): a position's slot.
        let slot = (m as i64 as f64 == m)
            .then(|| usize::try_from(m as i64 - self.m_lo).ok())
            .flatten()
            .filter(|&n| n < self.positions)
            .map(|n| n * self.per + g);
        if let Some(n) = slot
            && !self.groups[n].is_nan()
        {
            return self.groups[n];
        }
        let mut least = f64::INFINITY;
        for b in runs {
            least = least.min(self.get(sg, b, &blocks[b].1, (base, j0)));
        }
        if let Some(n) = slot {
            self.groups[n] = least;
        }
        least
    }
}

/// Buffers a slide reuses from strike to strike (and a row from start to
/// start).
#[derive(Debug, Default)]
struct Scratch {
    /// The leading outline's values with its reference at `u = base`
    /// (grid units), in the runs `have` marks.
    values: Vec<f64>,
    /// The position `values` holds (NaN where none).
    base: f64,
    /// Per run of [`BLOCK`] samples, whether `values` holds it.
    have: Vec<bool>,
    /// Per leading sample, its cell row ([`SurfaceGrid::row_of`]) in the
    /// start row `rows_of`.
    rows: Vec<Option<(usize, f64)>>,
    /// The start row `rows` holds.
    rows_of: Option<f64>,
}

impl Scratch {
    /// Ready to hold the outline `sf`'s values at position `base`: the
    /// runs held so far are kept where `base` is the one they were
    /// evaluated at (every value is a function of the position and the
    /// row alone).
    fn at(&mut self, sf: &SurfaceFootprint, base: f64) {
        if self.base != base || self.values.len() != sf.lead.len() {
            self.values.resize(sf.lead.len(), f64::INFINITY);
            self.have.clear();
            self.have.resize(sf.blocks.len(), false);
            self.base = base;
        }
    }

    /// Ready to read the cell rows of the outline `sf`'s samples in start
    /// row `j0`.
    fn rows_for(&mut self, sg: &SurfaceGrid, sf: &SurfaceFootprint, j0: f64) {
        if self.rows_of != Some(j0) || self.rows.len() != sf.lead.len() {
            self.rows.clear();
            self.rows
                .extend(sf.lead.iter().map(|&[_, dw]| sg.row_of(j0 + dw)));
            self.rows_of = Some(j0);
        }
    }
}

/// The slide's state.
struct Slide<'s, 'g> {
    sg: &'s SurfaceGrid<'g>,
    sf: &'s SurfaceFootprint,
    rule: &'s StrikeRule,
    i0: f64,
    j0: f64,
    f: f64,
    witness: [f64; 2],
    history: LevelHistory,
    out: SurfaceTrace,
    /// The runs' bounds.
    bounds: Bounds,
    /// The step's contact as an earlier slide struck it at this position,
    /// where the trail recorded one.
    prior: Option<Struck>,
    /// The step's contact, where it struck.
    struck: Option<Struck>,
    /// The tie scan's buffers.
    scratch: Scratch,
}

/// The columns a run with extent `e` reads beyond its first, whatever
/// the position: the run at reference `base` reads columns `first ..=
/// first + span` with `first = floor(base + e[0])`, a function of the
/// first column alone, so that a bound read for it holds while it stays.
fn span(e: &[f64; 4]) -> i64 {
    (e[1] - e[0]).ceil() as i64 + 2
}

/// `v.floor()` as an integer, for `|v| < 2^52`, without the library call
/// that the baseline instruction set needs for `floor` (a tenth of the
/// surface level's time where it was called per block and step).
#[inline(always)]
fn floor(v: f64) -> i64 {
    let t = v as i64;
    t - i64::from((t as f64) > v)
}

/// Whether two witnesses lie more than `p / 2` apart.
fn apart(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).hypot(a[1] - b[1]) > BISECT_APART
}

/// The node nearest `(u, w)` (a tie to the smaller index).
fn nearest(at: [f64; 2]) -> (usize, usize) {
    ((at[0] - 0.5).ceil() as usize, (at[1] - 0.5).ceil() as usize)
}

/// The leading outline of `sf` with its reference at `(base, j0)`, run
/// by run, a group of runs or a run passed over where `skip` holds for its
/// bound: `visit(value, at)` for each point of the runs read, in outline
/// order, each run evaluated once per position (kept in `scratch`).
#[inline(always)]
fn scan_runs(
    (sg, sf, (base, j0)): (&SurfaceGrid, &SurfaceFootprint, (f64, f64)),
    (bounds, scratch): (&mut Bounds, &mut Scratch),
    skip: impl Fn(f64) -> bool,
    mut visit: impl FnMut(f64, [f64; 2]),
) {
    scratch.at(sf, base);
    scratch.rows_for(sg, sf, j0);
    let Scratch {
        values, have, rows, ..
    } = scratch;
    let blocks = &sf.blocks;
    for g in 0..blocks.len().div_ceil(GROUP) {
        if skip(bounds.group(sg, blocks, g, (base, j0))) {
            continue;
        }
        for (b, (range, e)) in blocks.iter().enumerate().skip(g * GROUP).take(GROUP) {
            if skip(bounds.get(sg, b, e, (base, j0))) {
                continue;
            }
            if !have[b] {
                for n in range.clone() {
                    values[n] = sg.at_in(base + sf.lead[n][0], rows[n]);
                }
                have[b] = true;
            }
            for n in range.clone() {
                let [du, dw] = sf.lead[n];
                visit(values[n], [base + du, j0 + dw]);
            }
        }
    }
}

impl Slide<'_, '_> {
    /// The leading outline at travel `t` steps: its first lowest point
    /// below `limit`, skipping runs whose bound is at or above it.
    fn lowest_below(&mut self, t: f64, limit: f64) -> Lowest {
        let mut lowest = Lowest(None);
        let position = (self.i0 - t / STEPS_PER_PITCH, self.j0);
        scan_runs(
            (self.sg, self.sf, position),
            (&mut self.bounds, &mut self.scratch),
            |bound| bound >= limit,
            |value, at| {
                if value < limit {
                    lowest.take(value, at);
                }
            },
        );
        lowest
    }

    /// The level's fall to `value` at travel `t` steps, its witness `at`,
    /// where it falls by more than `e0` (a contact): judged and marked. A
    /// smaller fall is rounding and leaves the level as it is.
    fn fall(&mut self, t: f64, value: f64, at: [f64; 2]) {
        let before = self.f;
        if !self.rule.is_contact(value, before) {
            return;
        }
        let p = self.sf.pitch;
        let s = t * p / STEPS_PER_PITCH;
        let earlier = self.history.earlier(s, self.rule.window);
        if self.rule.window_strikes(value, earlier) {
            let struck = Struck {
                level: value,
                at,
                earlier,
            };
            self.struck = Some(struck);
            // The same contact struck by an earlier slide at this position
            // marked the same nodes (ties read the position, the level, the
            // witness and the level over the window behind only).
            if self.prior != Some(struck) {
                self.out.strikes.push(SurfaceStrike {
                    node: nearest(at),
                    travel: s,
                    value,
                    slack: 0.0,
                });
                self.ties(t, s, struck);
            }
        }
        self.witness = at;
        self.f = value;
        self.history.push(s, value);
        self.out.levels.push((s, value));
    }

    /// Marks the leading outline's points at travel `t` steps (`s` mm)
    /// that tie with the contact `struck` and strike on their own: SPEC
    /// v4's tie set, every outline point within the witness's cell's `tau`
    /// of the new level, each judged by the window rule on its own value
    /// `v`, `f(s - W) - v > sigma W` (a proposed SPEC reading: see the
    /// module comment). Only the runs whose bound lies within `tau` and
    /// passes the window test are evaluated.
    fn ties(&mut self, t: f64, s: f64, struck: Struck) {
        let Struck { level, at, earlier } = struck;
        let tau = self.sg.tau(at[0], at[1]);
        let limit = level + tau;
        let (rule, strikes) = (self.rule, &mut self.out.strikes);
        let position = (self.i0 - t / STEPS_PER_PITCH, self.j0);
        scan_runs(
            (self.sg, self.sf, position),
            (&mut self.bounds, &mut self.scratch),
            // A run whose bound fails either test holds no tie: both are
            // monotone in the value (a float subtraction is).
            |bound| bound > limit || !rule.window_strikes(bound, earlier),
            |v, here| {
                if v <= limit && here != at && rule.window_strikes(v, earlier) {
                    strikes.push(SurfaceStrike {
                        node: nearest(here),
                        travel: s,
                        value: v,
                        slack: tau,
                    });
                }
            },
        );
    }

    /// SPEC v4's bisection of the travel between `lo` and `hi` steps, the
    /// witnesses at its ends `w_lo` and `w_hi`, `f0` the level before the
    /// step at `hi`.
    fn bisect(
        &mut self,
        (lo, hi): (f64, f64),
        (w_lo, w_hi): ([f64; 2], [f64; 2]),
        f0: f64,
        depth: u32,
    ) {
        if depth >= BISECT_DEPTH || !apart(w_lo, w_hi) {
            return;
        }
        let mid = (lo + hi) / 2.0;
        let lowest = self.lowest_below(mid, f0 - self.rule.e0);
        let w_mid = lowest.0.map_or(w_lo, |p| p.at);
        self.bisect((lo, mid), (w_lo, w_mid), f0, depth + 1);
        if let Some(point) = lowest.0 {
            self.fall(mid, point.value, point.at);
        }
        self.bisect((mid, hi), (w_mid, w_hi), f0, depth + 1);
    }
}

/// SPEC v4's push and slide of the start at node `(i0, j0)` on the
/// surface of `sg`, its outline `sf`, under `rule` (whose window is read;
/// its rate and level are not).
#[cfg(any(test, feature = "harness"))]
pub(crate) fn trace(
    sg: &SurfaceGrid,
    sf: &SurfaceFootprint,
    (i0, j0): (usize, usize),
    rule: &StrikeRule,
) -> SurfaceTrace {
    slide_start(sg, sf, (i0, j0), rule, None)
}

/// The struck nodes (`mask[j * nx + i] = 1`) of every start of row `j0`
/// on the surface of `sg`, as [`trace`] strikes them, and how many starts
/// are placed. The starts run in increasing `i0` through one [`RowTrail`]:
/// a start stops where it provably continues an earlier start's slide.
pub(crate) fn trace_row(
    sg: &SurfaceGrid,
    sf: &SurfaceFootprint,
    j0: usize,
    rule: &StrikeRule,
    mask: &mut [u8],
) -> usize {
    let nx = sg.grid.spec.nx;
    let mut trail = RowTrail::new(sf, nx, rule);
    let mut placed = 0;
    let mut windows = PushWindows::new(sf, sg.grid, j0);
    for i0 in 0..nx {
        trail.windows.lowest = windows.advance(sg.grid, i0);
        let trace = slide_start(sg, sf, (i0, j0), rule, Some(&mut trail));
        placed += usize::from(trace.yr.is_finite());
        for SurfaceStrike { node: (i, j), .. } in trace.strikes {
            mask[j * nx + i] = 1;
        }
    }
    placed
}

/// How far left of column 0 (in columns) a slide's outline and its nodes
/// in front can reach, with a margin.
fn reach(sf: &SurfaceFootprint) -> i64 {
    sf.extent.0.abs().ceil() as i64
        + sf.rows
            .iter()
            .map(|r| i64::from(r.3).abs())
            .max()
            .unwrap_or(0)
        + 4
}

/// What a start's slide left at one position of the row's travel lattice.
#[derive(Debug, Clone, Copy)]
struct Record {
    /// The level after the step.
    level: f64,
    /// The last contact's witness (grid units).
    witness: [f64; 2],
    /// The slide that wrote it ([`RowTrail::UNWRITTEN`] where none).
    label: u32,
    /// Whether a bisection midpoint lowered the level within the step.
    mid: bool,
}

/// What the leading outline at one position is known to hold.
#[derive(Debug, Clone, Copy)]
enum Known {
    /// Its first lowest point.
    Lowest(Point),
    /// No point below this value.
    Above(f64),
}

/// The slides of one start row so far, by absolute position on the travel
/// lattice: position `m` is the outline's reference at `u = m / 8`, which
/// start `i0` reaches at step `k = 8 i0 - m`. Everything a step evaluates
/// there (the outline's samples, the nodes met, the bisection midpoints)
/// is the same, to the bit, for every start that reaches it (SPEC v4,
/// "Fast forms"), so a slide's future from `m` is a function of its state
/// there: its level, its last contact's witness and its level over the
/// window behind (the strike rule's `f(s - W)`). A start whose state
/// equals the one recorded at `m` by an earlier slide strikes from there
/// on exactly what that slide struck, so it stops: its mask is already
/// marked.
///
/// The window behind is compared position by position: the run of
/// consecutive positions where both levels are equal, both written by one
/// slide (labels joined where one slide continued another), and neither
/// lowered by a midpoint (whose travel lies between two positions). A run
/// longer than the window (plus one position each side) with equal
/// witnesses is the same state.
#[derive(Debug)]
pub(crate) struct RowTrail {
    /// Index of position `m` is `m + offset`.
    offset: i64,
    records: Vec<Record>,
    /// Per slide label, the slide it continues (itself where none).
    parent: Vec<u32>,
    /// Positions of agreement that make a state equal.
    need: u32,
    /// The push's nodes of the start in hand.
    windows: PushNodes,
    /// Per position, what its leading outline is known to hold.
    outline: Vec<Known>,
    /// Per position, the contact a slide struck there.
    struck: Vec<Option<Struck>>,
    /// The slides' buffers, handed from one to the next.
    scratch: Scratch,
    /// The leading runs' bounds, handed from one slide to the next.
    bounds: Bounds,
    /// The trailing runs' bounds (the push's).
    trail_bounds: Bounds,
}

/// The first lowest node inside the footprint of one start, as the push
/// reads them (rows in the footprint's order, columns increasing).
#[derive(Debug, Default)]
struct PushNodes {
    lowest: Option<Point>,
}

/// Per footprint row, the nodes inside the footprint of starts `i0 =
/// 0, 1, ...` of one start row as a sliding window: a queue of columns
/// whose heights increase (an equal height keeps the earlier column), so
/// its front is the row's first lowest node, as the push's scan finds it.
struct PushWindows {
    rows: Vec<PushWindow>,
}

/// One footprint row's window of [`PushWindows`].
struct PushWindow {
    /// Its grid row, `None` off the grid.
    row: Option<usize>,
    klo: i64,
    khi: i64,
    /// The next column to enter.
    next: i64,
    /// `(column, height)`, heights increasing.
    queue: std::collections::VecDeque<(i64, f64)>,
}

impl PushWindows {
    fn new(sf: &SurfaceFootprint, grid: &HeightGrid, j0: usize) -> PushWindows {
        let nz = grid.spec.nz as i64;
        let rows = sf
            .rows
            .iter()
            .map(|&(dj, klo, khi, _, _)| {
                let j = j0 as i64 + i64::from(dj);
                let on = (0..nz).contains(&j).then_some(j as usize);
                let (klo, khi) = (i64::from(klo), i64::from(khi));
                PushWindow {
                    row: on,
                    klo,
                    khi,
                    next: klo,
                    queue: std::collections::VecDeque::new(),
                }
            })
            .collect();
        PushWindows { rows }
    }

    /// The first lowest finite node inside start `i0`'s footprint; starts
    /// are asked in increasing `i0`.
    fn advance(&mut self, grid: &HeightGrid, i0: usize) -> Option<Point> {
        let nx = grid.spec.nx as i64;
        let i0 = i0 as i64;
        let mut lowest = Lowest(None);
        for PushWindow {
            row,
            klo,
            khi,
            next,
            queue,
        } in &mut self.rows
        {
            let Some(j) = *row else { continue };
            let hi = (i0 + *khi).min(nx - 1);
            while *next <= hi {
                let i = *next;
                *next += 1;
                if i < 0 {
                    continue;
                }
                let h = grid.at(i as usize, j);
                if !h.is_finite() {
                    continue;
                }
                while queue.back().is_some_and(|&(_, b)| b > h) {
                    queue.pop_back();
                }
                queue.push_back((i, h));
            }
            while queue.front().is_some_and(|&(i, _)| i < i0 + *klo) {
                queue.pop_front();
            }
            if let Some(&(i, h)) = queue.front() {
                lowest.take(h, [i as f64, j as f64]);
            }
        }
        lowest.0
    }
}

/// One slide's walk against a [`RowTrail`].
#[derive(Debug, Clone, Copy)]
struct Walk {
    label: u32,
    /// Positions of agreement so far.
    run: u32,
    /// The label recorded at the position before.
    prev: u32,
}

impl RowTrail {
    const UNWRITTEN: u32 = u32::MAX;

    fn new(sf: &SurfaceFootprint, nx: usize, rule: &StrikeRule) -> RowTrail {
        let lo = -(STEPS_PER_PITCH as i64) * reach(sf);
        let hi = STEPS_PER_PITCH as i64 * nx as i64;
        let window = (rule.window * STEPS_PER_PITCH / sf.pitch).ceil();
        RowTrail {
            offset: -lo,
            records: vec![
                Record {
                    level: f64::NAN,
                    witness: [f64::NAN; 2],
                    label: RowTrail::UNWRITTEN,
                    mid: false,
                };
                (hi - lo + 1) as usize
            ],
            outline: vec![Known::Above(f64::NEG_INFINITY); (hi - lo + 1) as usize],
            struck: vec![None; (hi - lo + 1) as usize],
            parent: Vec::new(),
            windows: PushNodes::default(),
            scratch: Scratch::default(),
            bounds: Bounds::new(&sf.blocks, nx, reach(sf)),
            trail_bounds: Bounds::new(&sf.trail_blocks, nx, reach(sf)),
            need: if window.is_finite() && window < f64::from(u32::MAX / 2) {
                window as u32 + 2
            } else {
                u32::MAX
            },
        }
    }

    /// A new slide's walk.
    fn start(&mut self) -> Walk {
        let label = self.parent.len() as u32;
        self.parent.push(label);
        Walk {
            label,
            run: 0,
            prev: RowTrail::UNWRITTEN,
        }
    }

    fn root(&mut self, mut label: u32) -> u32 {
        while self.parent[label as usize] != label {
            let up = self.parent[label as usize];
            self.parent[label as usize] = self.parent[up as usize];
            label = up;
        }
        label
    }

    /// The index of position `m`, where the trail has one.
    fn slot(&self, m: i64) -> Option<usize> {
        usize::try_from(m + self.offset)
            .ok()
            .filter(|&n| n < self.records.len())
    }

    /// The contact a slide struck at position `m` (its level and
    /// witness), if one did. A step's contact is the same for every slide
    /// that has one there (its point is the position's), so all but the
    /// first mark nodes already marked.
    fn struck(&self, m: i64) -> Option<Struck> {
        self.struck[self.slot(m)?]
    }

    /// [`Slide::lowest_below`] at position `m` (travel `t` steps of
    /// `slide`): the outline's first lowest point below `limit` is its
    /// first lowest point, if that lies below `limit`, so each position's
    /// is found once per row (or that none lies below the lowest limit
    /// asked so far).
    fn outline_below(&mut self, slide: &mut Slide, m: i64, t: f64, limit: f64) -> Lowest {
        let Some(n) = self.slot(m) else {
            return slide.lowest_below(t, limit);
        };
        match self.outline[n] {
            Known::Lowest(p) => Lowest((p.value < limit).then_some(p)),
            Known::Above(above) if limit <= above => Lowest(None),
            Known::Above(_) => {
                let lowest = slide.lowest_below(t, limit);
                self.outline[n] = match lowest.0 {
                    Some(p) => Known::Lowest(p),
                    None => Known::Above(limit),
                };
                lowest
            }
        }
    }

    /// The slide `walk` left `here` at position `m`: whether it continues
    /// the slide recorded there from now on (then it stops and is joined
    /// to it); otherwise its record replaces the one there.
    fn visit(&mut self, m: i64, here: Record, walk: &mut Walk) -> bool {
        let Some(slot) = self.slot(m) else {
            (walk.run, walk.prev) = (0, RowTrail::UNWRITTEN);
            return false;
        };
        let old = self.records[slot];
        let agree = old.label != RowTrail::UNWRITTEN
            && !old.mid
            && !here.mid
            && old.level == here.level
            && (walk.run == 0 || self.root(old.label) == self.root(walk.prev));
        walk.run = if agree { walk.run + 1 } else { 0 };
        walk.prev = old.label;
        if agree && walk.run >= self.need && old.witness == here.witness {
            let root = self.root(old.label);
            self.parent[walk.label as usize] = root;
            return true;
        }
        self.records[slot] = Record {
            label: walk.label,
            ..here
        };
        false
    }
}

/// [`trace`], continuing through `trail` where given: the trace then ends
/// where the slide continues one recorded there (its strikes from there
/// on are that slide's) and its levels stop there.
fn slide_start(
    sg: &SurfaceGrid,
    sf: &SurfaceFootprint,
    (i0, j0): (usize, usize),
    rule: &StrikeRule,
    mut trail: Option<&mut RowTrail>,
) -> SurfaceTrace {
    let grid = sg.grid;
    let (nx, nz) = (grid.spec.nx as i64, grid.spec.nz as i64);
    let p = sf.pitch;
    let (u0, w0) = (i0 as f64, j0 as f64);
    // The push: the whole outline, then the nodes inside; the nodes'
    // first lowest from the trail's windows where given.
    let nodes = match trail.as_deref() {
        Some(trail) => trail.windows.lowest,
        None => {
            let mut nodes = Lowest(None);
            let push_rows = sf.rows.iter().filter_map(|&(dj, klo, khi, _, _)| {
                let j = j0 as i64 + i64::from(dj);
                (0..nz).contains(&j).then_some((j as usize, klo, khi))
            });
            for (j, klo, khi) in push_rows {
                for k in klo..=khi {
                    let i = i0 as i64 + i64::from(k);
                    if (0..nx).contains(&i) {
                        nodes.take(grid.at(i as usize, j), [i as f64, j as f64]);
                    }
                }
            }
            nodes.0
        }
    };
    // A run of outline samples whose bound lies above the lowest point so
    // far (outline or nodes) holds no first lowest point: skipped.
    let (mut bounds, mut trail_bounds) = match trail.as_deref_mut() {
        Some(trail) => (
            std::mem::take(&mut trail.bounds),
            std::mem::take(&mut trail.trail_bounds),
        ),
        None => (
            Bounds::new(&sf.blocks, nx as usize, reach(sf)),
            Bounds::new(&sf.trail_blocks, nx as usize, reach(sf)),
        ),
    };
    let mut push = Lowest(None);
    let cut = nodes.map_or(f64::INFINITY, |n| n.value);
    for (side, blocks, bounds) in [
        (&sf.lead, &sf.blocks, &mut bounds),
        (&sf.trail, &sf.trail_blocks, &mut trail_bounds),
    ] {
        let mut above = false;
        for (b, (range, e)) in blocks.iter().enumerate() {
            let limit = push.0.map_or(cut, |p| p.value.min(cut));
            // The limit only falls: a group whose least bound lies above
            // it at its first run has every run above it at its own.
            if b % GROUP == 0 {
                above = bounds.group(sg, blocks, b / GROUP, (u0, w0)) > limit;
            }
            if above || bounds.get(sg, b, e, (u0, w0)) > limit {
                continue;
            }
            for &[du, dw] in &side[range.clone()] {
                let at = [u0 + du, w0 + dw];
                push.take(sg.at(at[0], at[1]), at);
            }
        }
    }
    if let Some(node) = nodes {
        push.take(node.value, node.at);
    }
    let rows: Vec<(usize, i64, f64)> = sf
        .slide_order
        .iter()
        .map(|&r| sf.rows[r as usize])
        .filter_map(|(dj, _, _, kf, d0)| {
            let j = j0 as i64 + i64::from(dj);
            (0..nz)
                .contains(&j)
                .then_some((j as usize, i0 as i64 + i64::from(kf), d0))
        })
        .collect();
    let Some(pushed) = push.0 else {
        if let Some(trail) = trail {
            (trail.bounds, trail.trail_bounds) = (bounds, trail_bounds);
        }
        return SurfaceTrace {
            yr: f64::INFINITY,
            ..SurfaceTrace::default()
        };
    };
    let mut slide = Slide {
        sg,
        sf,
        rule,
        i0: u0,
        j0: w0,
        f: pushed.value,
        witness: pushed.at,
        history: LevelHistory::new(pushed.value),
        out: SurfaceTrace {
            yr: pushed.value,
            ..SurfaceTrace::default()
        },
        bounds,
        prior: None,
        struck: None,
        scratch: trail
            .as_deref_mut()
            .map(|trail| std::mem::take(&mut trail.scratch))
            .unwrap_or_default(),
    };
    // The nodes in front as one stream by distance: layer `layer` (the
    // `layer`-th node in front of each row), rows in the slide's order;
    // `next` the next row of the layer.
    let (mut layer, mut next) = (0i64, 0usize);
    let first_most = rows.iter().map(|r| r.1).max().unwrap_or(-1);
    let (du_max, dw_lo, dw_hi) = sf.extent;
    let rows_span = (w0 + dw_lo, w0 + dw_hi);
    let mut met: Vec<(usize, f64, [f64; 2])> = Vec::new();
    let mut walk = trail.as_deref_mut().map(RowTrail::start);
    let mut ahead = None;
    let position = |k: u64| STEPS_PER_PITCH as i64 * i0 as i64 - k as i64;
    let mut k = 0u64;
    loop {
        k += 1;
        let t = k as f64;
        let s = t * p / STEPS_PER_PITCH;
        // The furthest column anything still ahead can read.
        let outline_at = u0 - t / STEPS_PER_PITCH + du_max;
        let node_at = first_most - layer;
        if outline_at < 0.0 && node_at < 0 {
            break;
        }
        let floor = slide.f - rule.e0;
        if sg.bound_before(outline_at.max(node_at as f64), rows_span, &mut ahead) >= floor {
            break;
        }
        let mut step = match trail.as_deref_mut() {
            Some(trail) => trail.outline_below(&mut slide, position(k), t, floor),
            None => slide.lowest_below(t, floor),
        };
        // The nodes met by this step, rows by j (one per row at most: a
        // step is shorter than a pitch).
        met.clear();
        while first_most - layer >= 0 && !rows.is_empty() {
            let (j, first, d0) = rows[next];
            if d0 + layer as f64 * p > s + NODE_TOL {
                break;
            }
            let i = first - layer;
            if (0..nx).contains(&i) {
                met.push((j, grid.at(i as usize, j), [i as f64, j as f64]));
            }
            next += 1;
            if next == rows.len() {
                (next, layer) = (0, layer + 1);
            }
        }
        // The first lowest in row order: the lowest, the smaller row on a
        // tie (met holds one node per row).
        let first = met.iter().fold(
            None,
            |best: Option<&(usize, f64, [f64; 2])>, m| match best {
                Some(b) if (b.1, b.0) <= (m.1, m.0) => Some(b),
                _ => Some(m),
            },
        );
        if let Some(&(_, value, at)) = first {
            step.take(value, at);
        }
        let groups = slide.out.levels.len();
        let mut mid = false;
        if let Some(point) = step.0 {
            if rule.is_contact(point.value, slide.f) && apart(slide.witness, point.at) {
                let (f0, w_lo) = (slide.f, slide.witness);
                slide.bisect((t - 1.0, t), (w_lo, point.at), f0, 0);
                mid = slide.out.levels.len() > groups;
            }
            slide.struck = None;
            slide.prior = trail.as_deref().and_then(|trail| trail.struck(position(k)));
            slide.fall(t, point.value, point.at);
            slide.prior = None;
            if let Some(n) = trail.as_deref().and_then(|trail| trail.slot(position(k)))
                && slide.struck.is_some()
            {
                trail.as_deref_mut().expect("a slot is the trail's").struck[n] = slide.struck;
            }
        }
        if let Some((trail, walk)) = trail.as_deref_mut().zip(walk.as_mut()) {
            let here = Record {
                level: slide.f,
                witness: slide.witness,
                label: walk.label,
                mid,
            };
            if trail.visit(position(k), here, walk) {
                break;
            }
        }
    }
    if let Some(trail) = trail {
        trail.scratch = std::mem::take(&mut slide.scratch);
        (trail.bounds, trail.trail_bounds) = (std::mem::take(&mut slide.bounds), trail_bounds);
    }
    slide.out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;
    use crate::kneeform::KneeForm;
    use crate::strike::Level;

    /// [`SurfaceGrid::bound`] with the spans (their tall windows of rows
    /// among them) is the least height of the nodes it covers, less its
    /// margin, to the bit, over the column and row ranges the runs read
    /// (1 to 9 columns, 1 to 10 rows, clipped at the grid's edges), on a
    /// grid with a hole (infinite heights).
    #[test]
    fn the_bound_is_the_least_height_of_the_nodes_it_covers() {
        let spec = GridSpec::explicit(0.0, 0.0, 23, 19, 1.0);
        let grid = HeightGrid::from_fn(spec, |x, z| {
            if (x - 7.0).hypot(z - 5.0) < 1.5 {
                f64::INFINITY
            } else {
                (0.9 * x).sin() * (0.4 * z).cos() + 0.01 * x * z
            }
        });
        let sg = SurfaceGrid::new(&grid).with_spans();
        let (nx, nz) = (spec.nx as i64, spec.nz as i64);
        let mut tall = 0;
        for c_lo in -2..nx + 2 {
            for width in 0..9 {
                for w_lo in [-1.5, 0.0, 0.3, 4.7, 12.2, 14.9, 17.9] {
                    for height in [0.0, 0.5, 2.0, 3.2, 4.6, 5.5, 6.9, 7.5] {
                        let (c_hi, w_hi) = (c_lo + width, w_lo + height);
                        let got = sg.bound((c_lo, c_hi), (w_lo, w_hi));
                        if c_hi < 0 || c_lo > nx - 1 || w_hi < 0.0 || w_lo > (nz - 1) as f64 {
                            assert_eq!(got, f64::INFINITY);
                            continue;
                        }
                        let rows = (w_lo.floor() as i64).clamp(0, nz - 1)
                            ..=(w_hi.floor() as i64 + 1).clamp(0, nz - 1);
                        tall += usize::from((TALL..=2 * TALL).contains(&rows.clone().count()));
                        let mut least = f64::INFINITY;
                        for j in rows {
                            for i in c_lo.clamp(0, nx - 1)..=c_hi.clamp(0, nx - 1) {
                                least = least.min(grid.at(i as usize, j as usize));
                            }
                        }
                        assert_eq!(
                            got.to_bits(),
                            below(least).to_bits(),
                            "columns {c_lo}..={c_hi}, rows {w_lo}..={w_hi}"
                        );
                    }
                }
            }
        }
        assert!(
            tall > 1000,
            "only {tall} bounds over {TALL} to {} rows",
            2 * TALL
        );
    }

    /// [`trace_row`] (starts joined through the row's trail, the push's
    /// nodes from sliding windows, each position's outline once) marks
    /// exactly the union of the per-start [`trace`]s and places the same
    /// starts, on a curved surface where many slides do join earlier ones
    /// (so the joining is what is tested), under windows shorter and
    /// longer than a pitch.
    #[test]
    fn a_row_of_joined_slides_strikes_what_its_starts_strike_alone() {
        let spec = GridSpec::explicit(0.0, 0.0, 48, 24, 1.0);
        // A bowl with ripples and a plateau of equal heights (ties), and a
        // hole (no surface).
        let grid = HeightGrid::from_fn(spec, |x, z| {
            if (x - 30.0).hypot(z - 12.0) < 2.5 {
                return f64::INFINITY;
            }
            let bowl = 0.02 * ((x - 20.0).powi(2) + (z - 10.0).powi(2));
            let ripple = 0.4 * (0.7 * x).sin() * (0.5 * z).cos();
            (bowl + ripple).min(6.0)
        });
        let knee = KneeForm {
            triangle_side: 9.0,
            radius: 3.0,
            thickness: 120.0,
        };
        let sg = SurfaceGrid::new(&grid);
        let mut joined = 0;
        for (angle, window, deflection) in [(0.0, 5.0, 0.5), (17.0, 0.6, 0.0), (-30.0, 3.0, 3.0)] {
            let fp = GridFootprint::new(&knee, angle, &spec);
            let sf = SurfaceFootprint::new(&fp);
            let rule = StrikeRule::new(deflection, StrikeRule::DEFAULT_E0)
                .with_window(window)
                .with_level(Level::Surface);
            for j0 in 0..spec.nz {
                let mut want = vec![0u8; spec.len()];
                let mut placed = 0;
                for i0 in 0..spec.nx {
                    let t = trace(&sg, &sf, (i0, j0), &rule);
                    placed += usize::from(t.yr.is_finite());
                    for SurfaceStrike { node: (i, j), .. } in t.strikes {
                        want[j * spec.nx + i] = 1;
                    }
                }
                let mut got = vec![0u8; spec.len()];
                let mut trail = RowTrail::new(&sf, spec.nx, &rule);
                let mut windows = PushWindows::new(&sf, &grid, j0);
                let mut got_placed = 0;
                for i0 in 0..spec.nx {
                    trail.windows.lowest = windows.advance(&grid, i0);
                    let t = slide_start(&sg, &sf, (i0, j0), &rule, Some(&mut trail));
                    got_placed += usize::from(t.yr.is_finite());
                    for SurfaceStrike { node: (i, j), .. } in t.strikes {
                        got[j * spec.nx + i] = 1;
                    }
                }
                joined += (0..trail.parent.len())
                    .filter(|&l| trail.parent[l] as usize != l)
                    .count();
                assert_eq!(got, want, "angle {angle}, window {window}, row {j0}");
                assert_eq!(got_placed, placed, "angle {angle}, row {j0}");
                let mut row_mask = vec![0u8; spec.len()];
                assert_eq!(trace_row(&sg, &sf, j0, &rule, &mut row_mask), placed);
                assert_eq!(row_mask, want, "trace_row, angle {angle}, row {j0}");
            }
        }
        assert!(joined > 100, "only {joined} slides joined an earlier one");
    }

    /// A tie is judged by its own value, as the node level judges each
    /// node of a group: a site the knee-form rests on and is leaving is
    /// not marked when a contact elsewhere lowers the level by less than
    /// `tau`. The knee-form rides a crest along x (height -1 on row 9,
    /// under its bottom rim) at the pushed level -1, then its top rim
    /// meets a ramp rising towards it (rows 18 on): the ramp's contacts
    /// strike, and the crest's outline points lie within the witness's
    /// `tau` (`p / 4` at the ramp's crease) of each new level down to
    /// -1.25, but their own drop over the window, `f(s - W) - h = -1 -
    /// -1`, is zero. SPEC's words (every point within `tau` takes the
    /// contact's decision) mark the crest: the angled features' decided
    /// false alarm of 82-190 mm (the diagonal ridge's top marked as the
    /// knee-form rides onto a boss 98 mm away; results/gate.md).
    #[test]
    fn a_tie_is_judged_by_its_own_value_so_the_site_being_left_is_clear() {
        let spec = GridSpec::explicit(0.0, 0.0, 60, 30, 1.0);
        let crest = |_: f64, z: f64| (-1.0 + (z - 9.0).abs()).min(0.0);
        let ramp = |x: f64, z: f64| -> f64 {
            if z >= 18.0 {
                (-1.0 + 0.2 * (x - 20.0)).clamp(-3.0, 0.0)
            } else {
                0.0
            }
        };
        let knee = KneeForm {
            triangle_side: 9.0,
            radius: 3.0,
            thickness: 120.0,
        };
        let fp = GridFootprint::new(&knee, 0.0, &spec);
        let sf = SurfaceFootprint::new(&fp);
        let rule = StrikeRule::default().with_level(Level::Surface);
        let start = (40, 15);
        let alone = HeightGrid::from_fn(spec, crest);
        let t = trace(&SurfaceGrid::new(&alone), &sf, start, &rule);
        assert_eq!(t.yr, -1.0);
        assert!(t.strikes.is_empty(), "{:?}", t.strikes);
        let both = HeightGrid::from_fn(spec, |x, z| crest(x, z).min(ramp(x, z)));
        let t = trace(&SurfaceGrid::new(&both), &sf, start, &rule);
        assert_eq!(t.yr, -1.0);
        assert!(t.strikes.iter().any(|t| t.node.1 >= 18), "{:?}", t.strikes);
        // The crest's nodes on row 9 lie within the witness's `tau` of
        // the level (the precondition of a tie) and are not marked.
        assert!(
            t.levels.iter().any(|&(_, l)| (-1.25..-1.0).contains(&l)),
            "{:?}",
            t.levels
        );
        assert!(t.strikes.iter().all(|t| t.node.1 != 9), "{:?}", t.strikes);
    }
}
