//! Why the grid and the exact knee-form disagree, as SPEC names the causes
//! ("Blind spots", "What the window does not fix: the level error"), and
//! the failing figures of a comparison with their mechanism.
//!
//! * **Blind.** The exact knee-form touched a flagged blind spot (a cell
//!   whose mesh sticks out past its sampled corners by more than the
//!   blind-spot depth, [`crate::blind`]) at or before the disagreement, in
//!   the same slide: the grid cannot see what deflected it.
//! * **Level error.** The grid's level is too deep (it follows the surface
//!   only at the nodes it met), so a node poking through it by a little is
//!   a grid strike the exact knee-form never touches: a false alarm, on the
//!   safe side. A grid strike is explained by it when its node lies within
//!   the stated bound of the grid's level error of the exact knee-form at
//!   that travel ([`super::metrics::compare`]). Under the surface level
//!   (SPEC v4) the bound is the surface's own error measured against the
//!   mesh near the exact contacts ([`Cells::surface_error_near`]): its
//!   level lies too deep where `S` cuts a convex crease or vertex between
//!   nodes, by `S` less the mesh at the touched point, at the strike and
//!   `W` back ([`super::metrics::LevelErrorBound::explains`]).
//! * **Undecided.** The disagreement is on a contact in the tie band:
//!   either answer is right at this pitch.
//! * **Oracle failure.** No exact answer for the pair: never counted
//!   clear.
//! * **Rim.** A missed exact strike the grid samples late: no node of
//!   the part within `sqrt 2` pitches of the touched point is met by the
//!   slide within `sqrt 2` pitches more of travel (a sliver of the part
//!   between the knee-form's outline and the footprint's outermost row;
//!   under the window rule such a strike is undecided, the grid's drop
//!   error there being unbounded), or the nearest one is met only later
//!   (the outline crossing the grid's rows at a shallow angle, a rounded
//!   corner's side over a crease: on the console at 0.5 mm, the node 0.02
//!   mm from the touched point met 1.3 mm of travel later, the one 0.11 mm
//!   away 3 mm later). It fails the verdict.
//! * **Sampling.** An unexplained residual within `sqrt 2` pitches: the
//!   grid's first-order error at this pitch; or a start's miss inside the
//!   footprint beyond that which, slid again with the grid sampled at half
//!   the pitch against the same exact trace, falls to at most half, or,
//!   where it falls but not to half, at a quarter of the pitch to at most
//!   a quarter (shown by refinement: on trimesh's teapot and the console, exact
//!   strikes along a crease of the mesh between two node rows, which the
//!   grid's strikes meet later); or a brief strike, lasting less than
//!   `sqrt 2` pitches of travel before the knee-form touches elsewhere,
//!   whose nodes the grid meets after it (its miss falls once the pitch
//!   is finer than the touch). It fails the verdict (the pitch is too
//!   coarse for the tolerance).
//! * **Unexplained.** None of the above: a real disagreement.

use serde::{Deserialize, Serialize};

use crate::blind::{BlindSpot, blind_spots, reference_height};
use crate::grid::{GridSpec, HeightGrid};
use crate::mesh::Triangle;

use super::trace::FootprintSpan;

/// How far outside a cell's closed square a point may lie and still be in
/// it (mm): witnesses on a cell's edge belong to both cells.
const CELL_TOL: f64 = 1e-6;

/// How far from a touched mesh point (in pitches, xz) the grid's nearest
/// node under the knee-form may lie ([`Cells::rise_near`]).
pub(crate) const RISE_REACH: f64 = std::f64::consts::SQRT_2;

/// What the harness knows of a grid's cells: which are flagged blind spots
/// (the mesh sticks out past their sampled corners by more than the
/// analysis's `--blind-depth`), and the grid's heights.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cells {
    spec: GridSpec,
    /// The blind spots' cells `(i, j)`, sorted, each with its reference
    /// height (the lowest sampled corner, mm).
    blind: Vec<((usize, usize), f64)>,
    /// The grid's heights (mm), row-major.
    heights: Vec<f64>,
    /// Under the surface level: per cell `(i, j)` (row-major, `nx - 1`
    /// cells a row), the largest `S - y` and `y - S` measured between the
    /// grid's surface `S` and the mesh ([`Cells::with_surface_error`]).
    surface_error: Option<Vec<SurfaceError>>,
}

/// How far the grid's surface `S` lies from the mesh on a cell, each way
/// (mm, `>= 0`): `above` the largest `S - y` (the surface deeper than the
/// part: cutting a convex crease between nodes, the grid's level too
/// deep), `below` the largest `y - S` (the surface standing proud of the
/// part, the grid's level too shallow).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct SurfaceError {
    /// The largest `S - y` (mm).
    pub above: f64,
    /// The largest `y - S` (mm).
    pub below: f64,
}

impl SurfaceError {
    /// Both sides' largest of `self` and `other`.
    pub fn max(self, other: SurfaceError) -> SurfaceError {
        SurfaceError {
            above: self.above.max(other.above),
            below: self.below.max(other.below),
        }
    }

    /// Unbounded both ways.
    pub const UNBOUNDED: SurfaceError = SurfaceError {
        above: f64::INFINITY,
        below: f64::INFINITY,
    };
}

/// The grid's surface `S` on cell `(i, j)` of the heights `h` (row-major,
/// `nx` a row) at `(fx, fz)` in it (`0..=1` each): SPEC v4's two triangles
/// split along the diagonal from `(i, j)` to `(i+1, j+1)`, as
/// [`crate::surface::SurfaceGrid`] has them, read on the cell's own
/// corners (a point on its edge too); `None` where a corner is off the
/// part.
fn cell_surface(h: &[f64], nx: usize, (i, j): (usize, usize), (fx, fz): (f64, f64)) -> Option<f64> {
    let n = j * nx + i;
    let (h00, h10, h01, h11) = (h[n], h[n + 1], h[n + nx], h[n + nx + 1]);
    if !(h00.is_finite() && h10.is_finite() && h01.is_finite() && h11.is_finite()) {
        return None;
    }
    Some(if fx >= fz {
        h00 + fx * (h10 - h00) + fz * (h11 - h10)
    } else {
        h00 + fz * (h01 - h00) + fx * (h11 - h01)
    })
}

/// Mesh samples per pitch (along x and z) that measure the surface's
/// error in a cell ([`Cells::with_surface_error`]).
pub(crate) const SURFACE_SAMPLES: usize = 8;

/// Cell rows whose finer samples [`Cells::with_surface_error`] holds at
/// once.
const SURFACE_BAND_ROWS: usize = 16;

impl Cells {
    /// The cells of `grid` (sampled from `triangles`), blind spots being
    /// those deeper than `threshold` mm (the analysis's `--blind-depth`).
    pub fn of(triangles: &[Triangle], grid: &HeightGrid, threshold: f64) -> Cells {
        Cells::of_blind_spots(grid, &blind_spots(triangles, grid, threshold))
    }

    /// The cells of `grid` whose blind spots are `spots` (an analysis's:
    /// found by [`blind_spots`] on the same grid, at its threshold),
    /// without finding them again.
    pub fn of_blind_spots(grid: &HeightGrid, spots: &[BlindSpot]) -> Cells {
        let mut blind: Vec<((usize, usize), f64)> = spots
            .iter()
            .map(|s| {
                (
                    (s.i, s.j),
                    reference_height(grid, s.i, s.j).unwrap_or(f64::NAN),
                )
            })
            .collect();
        blind.sort_unstable_by_key(|&(cell, _)| cell);
        Cells {
            spec: grid.spec,
            blind,
            heights: grid.h.clone(),
            surface_error: None,
        }
    }

    /// These cells with the surface level's error measured against the
    /// mesh (`triangles`, from which `grid`, these cells' grid, was
    /// sampled): per cell, the largest `S - y` and `y - S` over the mesh sampled at
    /// [`SURFACE_SAMPLES`] points per pitch along x and z on the cell's
    /// closed square (`y` the mesh's lowest height there, as the grid's
    /// nodes sample it; `S` the grid's piecewise-linear surface, SPEC v4).
    /// Where one of them has no height and the other has (a cell with a
    /// node off the part over mesh, the part's edge between the last node
    /// and the true edge; or a hole under a surface), `+inf`: the grid
    /// cannot see what the exact knee-form rests on there. A sample on the
    /// cell's edge reads the surface of either cell that has one there, as
    /// [`Cells::surface_at`] does: a part whose edge lies on a node row has
    /// mesh only on that row in the cell beyond it, and the grid's surface
    /// covers it (the wave's edge rows, z = -150 on the lattice at 2 and
    /// 1 mm).
    ///
    /// It is second order in the pitch on a smooth part (`p^2 |h''| / 8`),
    /// first order across a crease (`p |delta g| / 4`) and at a riser; it
    /// is measured, not assumed: a crease between two samples is seen at
    /// most `p / 16` from its peak.
    pub fn with_surface_error(mut self, triangles: &[Triangle], grid: &HeightGrid) -> Cells {
        use rayon::prelude::*;
        let spec = grid.spec;
        let (nx, nz) = (spec.nx, spec.nz);
        if nx < 2 || nz < 2 {
            self.surface_error = Some(Vec::new());
            return self;
        }
        let (cx, cz) = (nx - 1, nz - 1);
        let k = SURFACE_SAMPLES;
        let cells = &self;
        let bands: Vec<Vec<SurfaceError>> = (0..cz)
            .step_by(SURFACE_BAND_ROWS)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|j0| {
                let j1 = (j0 + SURFACE_BAND_ROWS).min(cz);
                let fine = GridSpec {
                    pitch: spec.pitch / k as f64,
                    i_origin: k as i64 * spec.i_origin,
                    j_origin: k as i64 * (spec.j_origin + j0 as i64),
                    nx: k * cx + 1,
                    nz: k * (j1 - j0) + 1,
                };
                let mesh = HeightGrid::sample(triangles, fine);
                let mut errors = vec![SurfaceError::default(); cx * (j1 - j0)];
                for (b, row) in (j0..j1).enumerate() {
                    for i in 0..cx {
                        let mut worst = SurfaceError::default();
                        for fb in 0..=k {
                            for fa in 0..=k {
                                let y = mesh.at(k * i + fa, k * b + fb);
                                let (fx, fz) = (fa as f64 / k as f64, fb as f64 / k as f64);
                                let s = cell_surface(&grid.h, nx, (i, row), (fx, fz))
                                    .or_else(|| {
                                        // A corner off the part: on the
                                        // cell's edge, a neighbour's
                                        // surface may cover the mesh.
                                        let (x, z) =
                                            (mesh.spec.x(k * i + fa), mesh.spec.z(k * b + fb));
                                        y.is_finite().then(|| cells.surface_at(x, z)).flatten()
                                    })
                                    .unwrap_or(f64::INFINITY);
                                let e = match (s.is_finite(), y.is_finite()) {
                                    (true, true) => SurfaceError {
                                        above: (s - y).max(0.0),
                                        below: (y - s).max(0.0),
                                    },
                                    (false, false) => SurfaceError::default(),
                                    _ => SurfaceError::UNBOUNDED,
                                };
                                worst = worst.max(e);
                            }
                        }
                        errors[b * cx + i] = worst;
                    }
                }
                errors
            })
            .collect();
        self.surface_error = Some(bands.concat());
        self
    }

    /// Whether the surface level's error is measured here
    /// ([`Cells::with_surface_error`]).
    pub fn has_surface_error(&self) -> bool {
        self.surface_error.is_some()
    }

    /// Under the surface level ([`Cells::with_surface_error`]), how far
    /// the grid's surface lies from the mesh near the mesh point `p`
    /// (`[x, y, z]`, mm) each way; `None` where it was not measured.
    /// `above` is `S - y` at `p` itself (at least 0; `+inf` where the grid
    /// has no surface there): the grid's level, the surface's minimum over
    /// what the footprint swept, is at most that much deeper than the exact
    /// knee-form's resting on `p`. `below` is the largest `y - S` measured
    /// on the cells within half a pitch of `p` in xz (`+inf` where one of
    /// them cannot see the mesh, or `p` lies off the grid): the grid's
    /// minimum may lie beside `p`, where the surface stands proud of the
    /// part.
    pub fn surface_error_near(&self, p: [f64; 3]) -> Option<SurfaceError> {
        let errors = self.surface_error.as_ref()?;
        let spec = self.spec;
        if spec.nx < 2 || spec.nz < 2 {
            return Some(SurfaceError::UNBOUNDED);
        }
        let (cx, cz) = (spec.nx - 1, spec.nz - 1);
        let reach = spec.pitch / 2.0 + CELL_TOL;
        let span = |v: f64, origin: f64, cells: usize| {
            let lo = ((v - reach - origin) / spec.pitch).floor().max(0.0);
            let hi = ((v + reach - origin) / spec.pitch)
                .floor()
                .min(cells as f64 - 1.0);
            (lo.is_finite() && hi.is_finite() && lo <= hi).then_some(lo as usize..=hi as usize)
        };
        let (Some(columns), Some(rows)) = (span(p[0], spec.x(0), cx), span(p[2], spec.z(0), cz))
        else {
            return Some(SurfaceError::UNBOUNDED);
        };
        let mut below = 0.0f64;
        for j in rows {
            for i in columns.clone() {
                below = below.max(errors[j * cx + i].below);
            }
        }
        let above = match self.surface_at(p[0], p[2]) {
            Some(s) => (s - p[1]).max(0.0),
            None => f64::INFINITY,
        };
        Some(SurfaceError { above, below })
    }

    /// The grid's surface `S` at `(x, z)` (mm; SPEC v4: each cell split
    /// along its diagonal from `(i, j)` to `(i+1, j+1)`, as
    /// [`crate::surface::SurfaceGrid`] has it), `None` off the grid or on a
    /// cell with a node off the part.
    fn surface_at(&self, x: f64, z: f64) -> Option<f64> {
        let spec = self.spec;
        let u = (x - spec.x(0)) / spec.pitch;
        let w = (z - spec.z(0)) / spec.pitch;
        let (nx, nz) = (spec.nx, spec.nz);
        let tol = CELL_TOL / spec.pitch;
        if !(u >= -tol && w >= -tol && u <= (nx - 1) as f64 + tol && w <= (nz - 1) as f64 + tol) {
            return None;
        }
        // The cells whose closed square holds the point (within
        // `CELL_TOL`): on an edge, the surface of either that has one.
        let span = |v: f64, cells: usize| {
            let lo = ((v - tol).floor().max(0.0) as usize).min(cells - 1);
            let hi = ((v + tol).floor().max(0.0) as usize).min(cells - 1);
            lo..=hi
        };
        let (columns, rows) = (span(u, nx - 1), span(w, nz - 1));
        rows.flat_map(|j| columns.clone().map(move |i| (i, j)))
            .find_map(|(i, j)| {
                let (fx, fz) = (
                    (u - i as f64).clamp(0.0, 1.0),
                    (w - j as f64).clamp(0.0, 1.0),
                );
                cell_surface(&self.heights, nx, (i, j), (fx, fz))
            })
    }

    /// The grid's pitch (mm).
    pub fn pitch(&self) -> f64 {
        self.spec.pitch
    }

    /// The cells whose closed square holds `(x, z)` (mm), within
    /// [`CELL_TOL`].
    fn around(&self, x: f64, z: f64) -> impl Iterator<Item = (usize, usize)> + '_ {
        let spec = self.spec;
        let span = |v: f64, origin: f64, cells: usize| {
            let lo = ((v - origin - CELL_TOL) / spec.pitch).floor().max(0.0);
            let hi = ((v - origin + CELL_TOL) / spec.pitch).floor();
            let hi = hi.min(cells as f64 - 1.0);
            if hi < lo || !lo.is_finite() || !hi.is_finite() {
                0..0
            } else {
                lo as usize..hi as usize + 1
            }
        };
        let (cx, cz) = if spec.nx >= 2 && spec.nz >= 2 {
            (spec.nx - 1, spec.nz - 1)
        } else {
            (0, 0)
        };
        let columns = span(x, spec.x(0), cx);
        span(z, spec.z(0), cz).flat_map(move |j| columns.clone().map(move |i| (i, j)))
    }

    /// Whether the mesh point `p` (`[x, y, z]`, mm, analysis frame) lies in
    /// a flagged blind spot, proud of every sampled corner of its cell: the
    /// exact knee-form touching it touches what the grid cannot see (the
    /// feature itself or its foot, anywhere the mesh stands out past the
    /// grid's samples).
    pub fn touches_blind_spot(&self, p: [f64; 3]) -> bool {
        if self.blind.is_empty() {
            return false;
        }
        self.around(p[0], p[2]).any(|(i, j)| {
            self.blind
                .binary_search_by(|(cell, _)| cell.cmp(&(i, j)))
                .is_ok_and(|k| p[1] < self.blind[k].1 - CELL_TOL)
        })
    }

    /// Whether a node on the part that the slide has met by `travel` mm
    /// (the start's footprint rows at the push being `rows`) lies within
    /// [`RISE_REACH`] pitches of `p` in xz: whether the grid samples the
    /// part under the knee-form near the point the exact knee-form touches.
    pub fn samples_near(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> bool {
        self.rises_near(p, Some((rows, travel, false))).is_some()
    }

    /// As [`Cells::samples_near`], counting only the nodes met during the
    /// slide (not those under the knee-form at the push, which set the
    /// pushed level and are never struck, SPEC): whether the grid may
    /// strike near `p` by `travel` mm.
    pub fn strikes_near(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> bool {
        self.rises_near(p, Some((rows, travel, true))).is_some()
    }

    /// How much higher than the mesh point `p` (`[x, y, z]`, mm) the grid
    /// may be wherever the knee-form touches `p`: the largest `h - y` over
    /// the nodes within [`RISE_REACH`] pitches of `p` in xz (mm, `>= 0`).
    ///
    /// A knee-form touching `p` on the rim of its outline covers no corner
    /// of `p`'s cell, perhaps, but covers a node within `sqrt 2` pitches of it
    /// (the outline is far wider than a pitch), and that node lies at most
    /// this much above `p`: the grid's level there is at most this much
    /// deeper than the exact one. About the local slope times `sqrt 2` times the
    /// pitch: it shrinks with the pitch.
    pub fn rise_near(&self, p: [f64; 3]) -> f64 {
        self.rises_near(p, None).map_or(0.0, |(_, highest)| highest)
    }

    /// How much higher than the mesh point `p` the *lowest* node within
    /// [`RISE_REACH`] pitches of it and met by the slide by `travel` mm
    /// (the start's footprint rows at the push `rows`) lies (mm, `>= 0`;
    /// `+inf` where the slide met no node of the part that near): the least
    /// by which the grid's best node near a touched point can misjudge it.
    /// Only the nodes the grid meets in the slide count: those under the
    /// knee-form at the push are never struck (SPEC).
    #[cfg(test)]
    pub fn rise_of_lowest_near(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> f64 {
        self.rises_near(p, Some((rows, travel, true)))
            .map_or(f64::INFINITY, |(lowest, _)| lowest.max(0.0))
    }

    /// [`Cells::samples_near`] then [`Cells::rise_near`] (`+inf` where
    /// not sampled), and [`Cells::rise_of_lowest_near`], of one point in
    /// one walk over the nodes near it: what the level-error bound asks of
    /// every exact contact. The same figures to the bit: each is folded
    /// over the same nodes in the same order.
    pub fn rises_at(&self, p: [f64; 3], rows: &[FootprintSpan], travel: f64) -> (f64, f64) {
        let (mut sampled, mut highest, mut lowest) = (false, None::<f64>, None::<f64>);
        for (i, j, _, h) in self.nodes_near(p) {
            let r = h - p[1];
            highest = Some(highest.map_or(r, |hi| hi.max(r)));
            let met = met_at(rows, i, j, self.spec.x(i)).filter(|&m| m <= travel + CELL_TOL);
            sampled |= met.is_some();
            if met.is_some_and(|m| m > CELL_TOL) {
                lowest = Some(lowest.map_or(r, |lo| lo.min(r)));
            }
        }
        let rise = match (sampled, highest) {
            (true, Some(hi)) => hi.max(0.0),
            _ => f64::INFINITY,
        };
        (rise, lowest.map_or(f64::INFINITY, |lo| lo.max(0.0)))
    }

    /// When the slide meets the node of the part nearest `p` in xz (within
    /// [`RISE_REACH`] pitches), the start's footprint rows at the push
    /// being `rows` (mm of travel: 0 for one under the knee-form at the
    /// push; `+inf` where it never does, or no node of the part is that
    /// near).
    pub fn nearest_node_met_at(&self, p: [f64; 3], rows: &[FootprintSpan]) -> f64 {
        self.nodes_near(p)
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .and_then(|(i, j, _, _)| met_at(rows, i, j, self.spec.x(i)))
            .unwrap_or(f64::INFINITY)
    }

    /// The nodes of the part within [`RISE_REACH`] pitches of `p` in xz:
    /// `(i, j, distance, height)`.
    fn nodes_near(&self, p: [f64; 3]) -> impl Iterator<Item = (usize, usize, f64, f64)> + '_ {
        let spec = self.spec;
        let reach = RISE_REACH * spec.pitch;
        let index = move |v: f64, origin: f64, n: usize| {
            let lo = ((v - reach - origin) / spec.pitch).ceil().max(0.0);
            let hi = ((v + reach - origin) / spec.pitch)
                .floor()
                .min(n as f64 - 1.0);
            if hi < lo || !lo.is_finite() || !hi.is_finite() {
                0..0
            } else {
                lo as usize..hi as usize + 1
            }
        };
        let columns = index(p[0], spec.x(0), spec.nx);
        index(p[2], spec.z(0), spec.nz)
            .flat_map(move |j| columns.clone().map(move |i| (i, j)))
            .filter_map(move |(i, j)| {
                let d = (spec.x(i) - p[0]).hypot(spec.z(j) - p[2]);
                let h = self.heights[j * spec.nx + i];
                (d <= reach + CELL_TOL && h.is_finite()).then_some((i, j, d, h))
            })
    }

    /// The least and the largest `h - y` over the nodes of the part within
    /// [`RISE_REACH`] pitches of `p` in xz (and, given `(rows, travel,
    /// slide_only)`, met by the slide of the footprint whose rows at the
    /// push are `rows` by `travel` mm: under it at the push too unless
    /// `slide_only`); `None` where there is none.
    fn rises_near(
        &self,
        p: [f64; 3],
        footprint: Option<(&[FootprintSpan], f64, bool)>,
    ) -> Option<(f64, f64)> {
        let covered = |i: usize, j: usize| {
            footprint.is_none_or(|(rows, travel, slide_only)| {
                met_at(rows, i, j, self.spec.x(i))
                    .is_some_and(|m| m <= travel + CELL_TOL && !(slide_only && m <= CELL_TOL))
            })
        };
        self.nodes_near(p)
            .filter(|&(i, j, _, _)| covered(i, j))
            .map(|(_, _, _, h)| h - p[1])
            .fold(None, |found: Option<(f64, f64)>, r| {
                Some(found.map_or((r, r), |(lo, hi)| (lo.min(r), hi.max(r))))
            })
            .map(|(lo, hi)| (lo, hi.max(0.0)))
    }
}

/// When the slide meets node `(i, j)` (its x `x_i`), by the start's
/// footprint rows at the push `rows` ([`FootprintSpan::meets`]; sorted by
/// row, as [`super::trace::GridTrace::push_rows`] are); `None` where it
/// never does.
fn met_at(rows: &[FootprintSpan], i: usize, j: usize, x_i: f64) -> Option<f64> {
    debug_assert!(rows.is_sorted_by_key(|r| r.j), "push rows by row");
    rows[rows.partition_point(|r| r.j < j)..]
        .iter()
        .take_while(|r| r.j == j)
        .find_map(|r| r.meets(i as i64, x_i))
}

/// Why a figure fails its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mechanism {
    /// Downstream of a flagged blind spot the exact knee-form touched.
    Blind,
    /// The grid's level error: false alarms on the safe side, within the
    /// stated bound.
    LevelError,
    /// Contacts in the tie band.
    Undecided,
    /// Pairs the oracle failed on.
    OracleFailure,
    /// Exact strikes in the knee-form's rim, which the grid samples late:
    /// no node of the part within `sqrt 2` pitches of the touched point,
    /// or not the nearest one, is met by the slide within `sqrt 2` pitches
    /// more of travel (a sliver between the outline and the footprint's
    /// outermost row, an outline crossing the rows at a shallow angle).
    /// Misses, on the unsafe side: they fail the verdict.
    Rim,
    /// A residual no mechanism above explains, within `sqrt 2` pitches:
    /// the size of error the grid makes at this pitch, which a finer pitch
    /// shrinks where the figure converges (`results/`); beyond it, a
    /// start's miss that falls with the pitch against the same exact
    /// trace (to half at half the pitch, or to a quarter at a quarter:
    /// `StartComparison::falls_with_the_pitch`), or a brief strike. It fails the verdict: the pitch is too coarse for the
    /// tolerance.
    Sampling,
    /// A real disagreement.
    Unexplained,
}

impl Mechanism {
    /// The name `verify.json` writes.
    pub fn name(self) -> &'static str {
        match self {
            Mechanism::Blind => "blind",
            Mechanism::LevelError => "level-error",
            Mechanism::Undecided => "undecided",
            Mechanism::OracleFailure => "oracle-failure",
            Mechanism::Rim => "rim",
            Mechanism::Sampling => "sampling",
            Mechanism::Unexplained => "unexplained",
        }
    }

    /// Whether a figure failing by this mechanism fails the verdict: blind
    /// disagreements are reported apart, the level error's false alarms
    /// against their bound and undecided contacts beside the decided ones
    /// (SPEC); an oracle failure or an unexplained figure fails.
    pub fn fails_verdict(self) -> bool {
        matches!(
            self,
            Mechanism::OracleFailure
                | Mechanism::Rim
                | Mechanism::Sampling
                | Mechanism::Unexplained
        )
    }
}

/// Which side of the guarantee a figure speaks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Side {
    /// Exact strikes the grid misses: safety.
    Miss,
    /// Grid strikes with no exact one near: cost (design freedom).
    FalseAlarm,
    /// The push level or the travel to the first strike.
    Level,
    /// Pairs without an answer to compare.
    Coverage,
}

/// One failing figure of a comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The metric (a row of `verify.csv`'s statistics) or count.
    pub metric: String,
    /// Its value: mm for a metric (`null` when infinite), a count for a
    /// count.
    pub value: Option<f64>,
    /// Why it fails.
    pub mechanism: Mechanism,
    /// Which side of the guarantee it speaks for.
    pub side: Side,
    /// Whether it fails the verdict ([`Mechanism::fails_verdict`]).
    pub fails_verdict: bool,
    /// Whether the value (a distance) is within `sqrt 2` pitches: a
    /// sampling error of the size the grid makes at this pitch, which a
    /// finer pitch shrinks where the figure converges (`results/`).
    #[serde(default)]
    pub within_pitch: bool,
}

impl Failure {
    /// A failing figure `metric` of `value` by `mechanism`.
    pub fn new(metric: &str, value: f64, mechanism: Mechanism, side: Side) -> Failure {
        Failure {
            metric: metric.into(),
            value: Some(value).filter(|v| v.is_finite()),
            mechanism,
            side,
            fails_verdict: mechanism.fails_verdict(),
            within_pitch: false,
        }
    }

    /// This failure, marked within `sqrt 2` pitches of `pitch` (mm) where
    /// its value (a distance, not a count) is; an unexplained one that is
    /// is the pitch's sampling error ([`Mechanism::Sampling`]).
    pub fn at_pitch(mut self, pitch: f64) -> Failure {
        self.within_pitch = self.side != Side::Coverage
            && self
                .value
                .is_some_and(|v| v <= std::f64::consts::SQRT_2 * pitch + 1e-9);
        if self.within_pitch && self.mechanism == Mechanism::Unexplained {
            self.mechanism = Mechanism::Sampling;
        }
        self
    }

    /// The figure in words, for a console line.
    pub fn phrase(&self) -> String {
        let value = match self.value {
            Some(v) if self.side == Side::Coverage => format!("{v}"),
            Some(v) => format!("{v:.3} mm"),
            None => "infinite".into(),
        };
        let pitch = if self.within_pitch {
            ", within sqrt 2 pitches"
        } else {
            ""
        };
        format!("{} {value} ({}{pitch})", self.metric, self.mechanism.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::tessellate;

    /// A plane `y = slope * x` at pitch 2 mm over [0, 40] x [0, 20], with a
    /// rib 0.4 mm wide and 3 mm proud (towards the knee, -y) along z at
    /// x = 21 (between node columns 20 and 22).
    fn ribbed(slope: f64) -> (Vec<Triangle>, HeightGrid) {
        let xs = [0.0, 10.0, 20.0, 20.8, 21.0, 21.2, 22.0, 30.0, 40.0];
        let zs = [0.0, 10.0, 20.0];
        let y = |x: f64| {
            let rib = if (20.8..=21.2).contains(&x) { 3.0 } else { 0.0 };
            slope * x - rib
        };
        let triangles = tessellate(&xs, &zs, |i, _| y(xs[i]));
        let grid = at_pitch_two(&triangles);
        (triangles, grid)
    }

    #[test]
    fn a_point_on_a_flagged_rib_or_its_foot_touches_a_blind_spot_and_the_plane_does_not() {
        let (triangles, grid) = ribbed(0.0);
        let cells = Cells::of(&triangles, &grid, 0.5);
        assert!(cells.touches_blind_spot([21.0, -3.0, 7.0]), "the rib's top");
        assert!(cells.touches_blind_spot([20.9, -1.0, 7.0]), "its flank");
        assert!(
            !cells.touches_blind_spot([21.0, -3.0, 30.0]),
            "off the grid"
        );
        assert!(!cells.touches_blind_spot([15.0, 0.0, 7.0]), "the plane");
        // In the rib's cell but on the plane at the sampled corners' height.
        assert!(!cells.touches_blind_spot([20.2, 0.0, 7.0]));
        // A deeper threshold flags nothing.
        let deep = Cells::of(&triangles, &grid, 3.5);
        assert!(!deep.touches_blind_spot([21.0, -3.0, 7.0]));
    }

    /// `triangles` sampled at pitch 2 mm over [0, 40] x [0, 20].
    fn at_pitch_two(triangles: &[Triangle]) -> HeightGrid {
        let spec = GridSpec {
            pitch: 2.0,
            i_origin: 0,
            j_origin: 0,
            nx: 21,
            nz: 11,
        };
        HeightGrid::sample(triangles, spec)
    }

    /// A V-shaped ridge along z, `y = g |x - x_c|` (its crease the part's
    /// point nearest the knee), at pitch 2 mm over [0, 40] x [0, 20].
    fn ridge(g: f64, x_c: f64) -> (Vec<Triangle>, HeightGrid) {
        let xs = [0.0, x_c, 40.0];
        let zs = [0.0, 10.0, 20.0];
        let triangles = tessellate(&xs, &zs, |i, _| g * (xs[i] - x_c).abs());
        let grid = at_pitch_two(&triangles);
        (triangles, grid)
    }

    #[test]
    fn the_surface_lies_on_a_plane_and_cuts_a_crease_between_nodes_by_p_delta_g_over_4() {
        // A plane: the surface is the part, no error either way.
        let (plane, grid) = ridge(0.25, 0.0);
        let cells = Cells::of(&plane, &grid, 10.0).with_surface_error(&plane, &grid);
        let e = cells.surface_error_near([9.0, 0.25 * 9.0, 7.0]).unwrap();
        assert!(e.above < 1e-9 && e.below < 1e-9, "{e:?}");
        // Not measured: none.
        assert_eq!(
            Cells::of(&plane, &grid, 10.0).surface_error_near([9.0, 2.25, 7.0]),
            None
        );
        // A ridge whose crease runs mid-cell (x = 21, between nodes at 20
        // and 22): the nodes sit g p / 2 above the crease, the surface
        // between them too (SPEC's `p |delta g| / 4` with delta g = 2 g).
        let g = 0.3;
        let (triangles, grid) = ridge(g, 21.0);
        let cells = Cells::of(&triangles, &grid, 10.0).with_surface_error(&triangles, &grid);
        let on_crease = cells.surface_error_near([21.0, 0.0, 7.0]).unwrap();
        assert!(
            (on_crease.above - g * 2.0 / 2.0).abs() < 1e-9,
            "{on_crease:?}"
        );
        // The surface never stands proud of a convex ridge.
        assert!(on_crease.below < 1e-9, "{on_crease:?}");
        // Beside the crease, the same cell's surface is measured: `above`
        // is read at the point itself, `S - y` there.
        let beside = cells.surface_error_near([20.5, g * 0.5, 7.0]).unwrap();
        // The nodes at 20 and 22 both lie g above the crease: S = g there.
        let s_at = g;
        assert!((beside.above - (s_at - g * 0.5)).abs() < 1e-9, "{beside:?}");
        // Far from the crease, on a plane of the ridge: no error.
        let far = cells.surface_error_near([9.0, g * 12.0, 7.0]).unwrap();
        assert!(far.above < 1e-9 && far.below < 1e-9, "{far:?}");
        // A crease on a node column: the nodes sample it, no error.
        let (triangles, grid) = ridge(g, 20.0);
        let cells = Cells::of(&triangles, &grid, 10.0).with_surface_error(&triangles, &grid);
        let on_node = cells.surface_error_near([20.0, 0.0, 7.0]).unwrap();
        assert!(on_node.above < 1e-9 && on_node.below < 1e-9, "{on_node:?}");
    }

    /// A flat plate at y = 0 over x in [0, x_end], z in [0, 20], on the
    /// 2 mm grid, with its cells' surface error measured.
    fn flat_plate_ending_at(x_end: f64) -> (HeightGrid, Cells) {
        let triangles = tessellate(&[0.0, 10.0, x_end], &[0.0, 10.0, 20.0], |_, _| 0.0);
        let grid = at_pitch_two(&triangles);
        let cells = Cells::of(&triangles, &grid, 10.0).with_surface_error(&triangles, &grid);
        (grid, cells)
    }

    #[test]
    fn the_surface_error_is_unbounded_where_the_grid_has_no_surface_over_the_mesh() {
        // The part ends at x = 21, between node columns 20 and 22: the
        // cell [20, 22] has a node off the part over mesh.
        let (_, cells) = flat_plate_ending_at(21.0);
        let edge = cells.surface_error_near([20.8, 0.0, 7.0]).unwrap();
        assert_eq!(edge.above, f64::INFINITY);
        assert_eq!(edge.below, f64::INFINITY);
        // On the last node column on the part, the surface of the cell
        // before it reads the part there: `above` is none, though the cell
        // after it has no surface (its `below`, measured within half a
        // pitch, is unbounded).
        let column = cells.surface_error_near([20.0, 0.0, 7.0]).unwrap();
        assert_eq!(column.above, 0.0);
        assert_eq!(column.below, f64::INFINITY);
        // Inside, more than half a pitch from that cell: measured, none.
        let inside = cells.surface_error_near([18.5, 0.0, 7.0]).unwrap();
        assert!(inside.above < 1e-9 && inside.below < 1e-9, "{inside:?}");
    }

    #[test]
    fn a_part_edge_on_a_node_column_is_within_the_surface_of_the_cell_before_it() {
        // The part ends at x = 20, on node column 10: the cell [20, 22]
        // has nodes off the part, and mesh only on its edge x = 20, which
        // the surface of the cell [18, 20] covers (the wave's edge rows at
        // z = -150 on the lattice of every pitch that divides it).
        let (grid, cells) = flat_plate_ending_at(20.0);
        assert!(grid.h[10].is_finite() && grid.h[11].is_infinite());
        // On the edge and within half a pitch of the cell beyond it: the
        // plane is read exactly, no error either way.
        for p in [[20.0, 0.0, 7.0], [19.5, 0.0, 7.0], [20.0, 0.0, 20.0]] {
            let e = cells.surface_error_near(p).unwrap();
            assert!(e.above < 1e-9 && e.below < 1e-9, "{p:?}: {e:?}");
        }
    }

    #[test]
    fn the_cells_surface_is_the_surface_levels() {
        let (_, grid) = ribbed(0.25);
        let grid = HeightGrid {
            h: grid
                .h
                .iter()
                .enumerate()
                .map(|(n, h)| h + 0.01 * ((n * 7919) % 13) as f64)
                .collect(),
            ..grid
        };
        let cells = Cells::of_blind_spots(&grid, &[]);
        let surface = crate::surface::SurfaceGrid::new(&grid);
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..500 {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            let u = (rng % 20_000) as f64 / 1000.0;
            let w = ((rng >> 20) % 10_000) as f64 / 1000.0;
            let expected = surface.at(u, w);
            let got = cells.surface_at(2.0 * u, 2.0 * w).unwrap();
            assert!(
                (got - expected).abs() < 1e-9,
                "({u}, {w}): {got} against {expected}"
            );
        }
    }

    #[test]
    fn the_rise_near_a_point_is_the_slope_times_sqrt_2_pitches_up_to_the_nodes() {
        let (triangles, grid) = ribbed(0.25);
        let cells = Cells::of(&triangles, &grid, 10.0);
        // On the plane at x = 9: the highest node within 2.83 mm lies at
        // x = 10 (x = 12 is 3 mm away), 1 mm uphill.
        let p = [9.0, 0.25 * 9.0, 7.0];
        let rise = cells.rise_near(p);
        let reach = RISE_REACH * 2.0;
        let highest_x = (0..=20)
            .map(|i| 2.0 * f64::from(i))
            .filter(|&x| {
                (0..=10).any(|j| (x - 9.0).hypot(2.0 * f64::from(j) - 7.0) <= reach + 1e-9)
            })
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(highest_x, 10.0);
        assert!((rise - 0.25 * (highest_x - 9.0)).abs() < 1e-12, "{rise}");
        // A point above every node near it rises by nothing.
        assert_eq!(cells.rise_near([9.0, 100.0, 7.0]), 0.0);
    }

    #[test]
    fn a_point_is_sampled_where_a_node_the_slide_met_lies_within_sqrt_2_pitches() {
        let (triangles, grid) = ribbed(0.0);
        let cells = Cells::of(&triangles, &grid, 0.5);
        // Rows z = 4, 6, 8, columns x = 6..12 at the push (pitch 2); the
        // outline crosses each row 1 mm in front of its first node.
        let row = |j, front| FootprintSpan {
            j,
            lo: 3,
            hi: 6,
            front,
        };
        let rows = [row(2, 5.0), row(3, 5.0), row(4, 5.0)];
        assert!(
            cells.samples_near([5.0, 0.0, 5.0], &rows, 0.0),
            "node (6, 4) is 1.41 away"
        );
        assert!(
            !cells.samples_near([2.0, 0.0, 5.0], &rows, 0.0),
            "the nearest node is 4.1 away"
        );
        // After 1 mm of slide the outline reaches x = 4 (met); after 3 mm,
        // x = 2: the point at x = 1 is sampled from then on, and x = 13
        // still is (a met node stays met).
        assert!(!cells.samples_near([1.0, 0.0, 5.0], &rows, 1.0));
        assert!(cells.samples_near([1.0, 0.0, 5.0], &rows, 3.0));
        assert!(cells.samples_near([13.0, 0.0, 5.0], &rows, 3.0));
        // Beyond the rows in z, or behind them in x: never met.
        assert!(!cells.samples_near([8.0, 0.0, 11.0], &rows, 0.0));
        assert!(!cells.samples_near([15.0, 0.0, 5.0], &rows, 30.0));
        // The lowest met node's rise: on this flat part, 0 where sampled,
        // +inf where not.
        // Only nodes met in the slide judge: none by travel 0 (those under
        // the knee-form at the push are never struck), x = 4 from 1 mm.
        assert_eq!(
            cells.rise_of_lowest_near([5.0, 0.0, 5.0], &rows, 0.0),
            f64::INFINITY
        );
        assert_eq!(cells.rise_of_lowest_near([5.0, 0.0, 5.0], &rows, 1.0), 0.0);
        assert!(!cells.strikes_near([5.0, 0.0, 5.0], &rows, 0.0));
        assert!(cells.strikes_near([5.0, 0.0, 5.0], &rows, 1.0));
        assert_eq!(
            cells.rise_of_lowest_near([2.0, 0.0, 5.0], &rows, 0.0),
            f64::INFINITY
        );
        // At travel 2 the point at x = 1 has only x = 2 near, met at 3 mm.
        assert_eq!(
            cells.rise_of_lowest_near([1.0, 0.0, 5.0], &rows, 2.0),
            f64::INFINITY
        );
        assert_eq!(cells.rise_of_lowest_near([1.0, 0.0, 5.0], &rows, 3.0), 0.0);
        // The nearest node's meeting: x = 4 is met after 1 mm, x = 12 at
        // the push, x = 30 (behind the footprint) never.
        assert_eq!(cells.nearest_node_met_at([3.9, 0.0, 4.1], &rows), 1.0);
        assert_eq!(cells.nearest_node_met_at([12.2, 0.0, 6.1], &rows), 0.0);
        assert_eq!(
            cells.nearest_node_met_at([30.0, 0.0, 5.0], &rows),
            f64::INFINITY
        );
        assert_eq!(
            cells.nearest_node_met_at([500.0, 0.0, 5.0], &rows),
            f64::INFINITY
        );
    }

    #[test]
    fn one_walk_gives_the_three_rises_of_the_separate_queries_to_the_bit() {
        // A sloped part with a rib (rises of both signs and zero), points
        // on and off the nodes, travels from the push to past every row.
        let (triangles, grid) = ribbed(0.3);
        let cells = Cells::of(&triangles, &grid, 0.5);
        let row = |j, lo, hi, front| FootprintSpan { j, lo, hi, front };
        let rows = [row(2, 3, 6, 5.0), row(3, 4, 7, 7.5), row(4, 3, 5, 4.2)];
        let mut checked = [0; 3];
        for k in 0..40 {
            for m in 0..30 {
                let (x, z) = (0.55 * f64::from(k) - 1.0, 0.37 * f64::from(m));
                for y in [-5.0, 0.0, 4.0] {
                    for travel in [0.0, 0.5, 1.0, 3.0, 7.7, 40.0] {
                        let p = [x, y, z];
                        let sampled = cells.samples_near(p, &rows, travel);
                        let rise = if sampled {
                            cells.rise_near(p)
                        } else {
                            f64::INFINITY
                        };
                        let lowest = cells.rise_of_lowest_near(p, &rows, travel);
                        let (a, b) = cells.rises_at(p, &rows, travel);
                        assert_eq!(a.to_bits(), rise.to_bits(), "{p:?} {travel}");
                        assert_eq!(b.to_bits(), lowest.to_bits(), "{p:?} {travel}");
                        checked[0] += usize::from(sampled);
                        checked[1] += usize::from(lowest.is_finite());
                        checked[2] += usize::from(rise > 0.0 && rise.is_finite());
                    }
                }
            }
        }
        assert!(checked.iter().all(|&n| n > 100), "{checked:?}");
    }

    #[test]
    fn only_unexplained_figures_rim_misses_and_oracle_failures_fail_the_verdict() {
        for (m, fails) in [
            (Mechanism::Blind, false),
            (Mechanism::LevelError, false),
            (Mechanism::Undecided, false),
            (Mechanism::OracleFailure, true),
            (Mechanism::Rim, true),
            (Mechanism::Sampling, true),
            (Mechanism::Unexplained, true),
        ] {
            assert_eq!(m.fails_verdict(), fails, "{m:?}");
            let f = Failure::new("miss_distance_decided", 2.5, m, Side::Miss);
            assert_eq!(f.fails_verdict, fails);
            assert!(f.phrase().contains(m.name()));
        }
        let json = serde_json::to_string(&Failure::new(
            "area_miss_distance_decided",
            f64::INFINITY,
            Mechanism::LevelError,
            Side::FalseAlarm,
        ))
        .unwrap();
        assert!(json.contains(r#""mechanism":"level-error""#), "{json}");
        assert!(json.contains(r#""value":null"#), "{json}");
        assert!(json.contains(r#""side":"false-alarm""#), "{json}");
    }
}
