//! The grid's push and slide of one start, with the travel at which each
//! colliding node is met: what the harness compares with the oracle's
//! contact trace.
//!
//! This is SPEC's per-start definition, transcribed directly (every node in
//! front of the start, merged into distance order, tie groups judged at one
//! level), with test-only faults that the harness must catch.

use crate::grid::HeightGrid;
use crate::grid::NODE_TOL;
use crate::kneeform::GridFootprint;
use crate::strike::{Level, LevelHistory, Meeting, StrikeRule};
use crate::surface::{SurfaceFootprint, SurfaceGrid};

/// A deliberate mistake in the grid side of a comparison, for the tests
/// that show the harness catches a broken engine. Crate-private: no
/// public entry point takes one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) enum Fault {
    /// Every height offset by half a pitch away from the knee (+y).
    HeightsOffsetHalfPitch,
    /// The footprint loses its leading row (the row reaching furthest to
    /// -x, where first contacts happen).
    FootprintRowShort,
    /// The slide judges each node at its own level, ignoring tie groups.
    IgnoreTies,
}

/// A colliding node of one start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GridContact {
    /// Column and row of the node.
    pub node: (usize, usize),
    /// The node in xz (mm, analysis frame): where the strike is counted.
    pub point: [f64; 2],
    /// Distance (mm) the knee-form travelled in -x when it met the node.
    pub travel: f64,
    /// The value the strike rule judged (mm): the node's height under the
    /// node level; under the surface level the surface's value at the
    /// witness (the new level, or a tie's own value).
    pub value: f64,
    /// How far above the grid's new level `value` may lie (mm): 0, or
    /// under the surface level a tie's `tau` (SPEC v4's tie set).
    pub slack: f64,
}

/// The grid's push and slide of one start.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GridTrace {
    /// The face level after the push (mm), `+inf` when not placed.
    pub yr: f64,
    /// The colliding nodes in the order they are met.
    pub colliding: Vec<GridContact>,
    /// The footprint's rows at the push, one per row of the grid.
    pub push_rows: Vec<FootprintSpan>,
    /// `(travel, level)` after each tie group that lowered the level, by
    /// travel: the level curve, which the start one pitch to its +x joins
    /// ([`grid_trace_joining`]).
    pub levels: Vec<(f64, f64)>,
}

/// One row of a start's footprint at the push.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FootprintSpan {
    /// The grid row.
    pub j: usize,
    /// The columns under the knee-form at the push, `lo..=hi` (inclusive,
    /// not clipped to the grid; empty when `hi < lo`).
    pub lo: i64,
    /// See `lo`.
    pub hi: i64,
    /// Where the knee-form's outline crosses the row in front at the push
    /// (x, mm): the slide meets a node of the row in front, column `i <
    /// lo`, after `front - x(i)` mm of travel.
    pub front: f64,
}

impl FootprintSpan {
    /// The travel (mm) at which the slide meets column `i` of this row,
    /// whose x is `x_i`: 0 under the knee-form at the push, when its
    /// outline reaches it in front, never (`None`) behind the footprint.
    pub fn meets(&self, i: i64, x_i: f64) -> Option<f64> {
        if i > self.hi {
            None
        } else if i >= self.lo {
            Some(0.0)
        } else {
            Some((self.front - x_i).max(0.0))
        }
    }
}

/// Pushes and slides the start at node `(i0, j0)`, with an optional fault.
pub(crate) fn grid_trace(
    grid: &HeightGrid,
    fp: &GridFootprint,
    i0: usize,
    j0: usize,
    rule: &StrikeRule,
    fault: Option<Fault>,
) -> GridTrace {
    slide(grid, fp, (i0, j0), rule, fault, None)
}

/// [`grid_trace`] of the start at node `(i0, j0)`, given `neighbour`, the
/// trace of the start `shift` nodes to its -x (node `(i0 - shift, j0)`,
/// `shift >= 1`) at the same footprint: the same trace, for a few hundred
/// nodes where the start alone walks every node in front of it (10^5 on
/// the console).
///
/// Why it is the same. Call the start A and its neighbour B, `p` the
/// pitch, `d = shift * p`. A's footprint after `s` mm of travel covers
/// B's after `s - d`, so for `s >= d` the nodes A has met are those it met
/// by `d` (B's push footprint among them) and those B met by `s - d`, and
/// A's level is `f_A(s) = min(f_A(d), f_B(s - d))`. Once B's level has
/// come down to A's (at B's travel `J`), the two curves are the same,
/// shifted by `d`; from `W` mm later on, so are the windows' earlier
/// levels, and each node is met at the same level with the same earlier
/// level: A strikes exactly the nodes B strikes from there, each `d`
/// further along. So A slides on its own until it reaches `J + d + W`
/// plus a pitch to spare (the levels A has reached bound `J` from above:
/// a lower level only moves `J` later), and takes B's strikes and level
/// curve from there, with each strike's travel computed as A's own slide
/// computes it. A test compares every start of whole rows with its trace
/// alone, to the bit, joined to the start one, two and four nodes before
/// it.
pub(crate) fn grid_trace_joining(
    grid: &HeightGrid,
    fp: &GridFootprint,
    (i0, j0): (usize, usize),
    rule: &StrikeRule,
    (neighbour, shift): (&GridTrace, usize),
) -> GridTrace {
    assert!(shift >= 1, "a neighbour to the -x");
    slide(grid, fp, (i0, j0), rule, None, Some((neighbour, shift)))
}

/// The layers of nodes in front that [`grid_trace_joining`] lays first
/// beyond the window and two pitches, doubled while its own slide needs
/// more.
const JOIN_SPARE_LAYERS: i64 = 4;

/// How far (mm) below a front's last complete layer a tie group must start
/// to be judged from it: far above rounding, far below a pitch.
const FRONT_SLACK: f64 = 1e-6;

/// [`grid_trace`], joining the trace of the start one pitch to its -x
/// where given ([`grid_trace_joining`]).
fn slide(
    grid: &HeightGrid,
    fp: &GridFootprint,
    (i0, j0): (usize, usize),
    rule: &StrikeRule,
    fault: Option<Fault>,
    neighbour: Option<(&GridTrace, usize)>,
) -> GridTrace {
    crate::engine::assert_same_pitch(grid, std::slice::from_ref(fp));
    let spec = grid.spec;
    let p = spec.pitch;
    let offset = if fault == Some(Fault::HeightsOffsetHalfPitch) {
        p / 2.0
    } else {
        0.0
    };
    let h = |i: usize, j: usize| grid.at(i, j) + offset;
    let leading = fp.rows.iter().min_by_key(|r| (r.kf, r.dj)).map(|r| r.dj);
    let on_grid = |r: &crate::kneeform::FootprintRow| {
        let j = j0 as i64 + i64::from(r.dj);
        (0..spec.nz as i64).contains(&j).then_some((*r, j as usize))
    };
    // The footprint as SPEC has it, whatever fault the slide below
    // injects: what the harness judges the grid by comes from here, never
    // from the slide under test.
    let push_rows = fp
        .rows
        .iter()
        .filter_map(on_grid)
        .map(|(row, j)| FootprintSpan {
            j,
            lo: i0 as i64 + i64::from(row.klo),
            hi: i0 as i64 + i64::from(row.khi),
            front: spec.x(i0) + f64::from(row.kf) * p + row.d0,
        })
        .collect();
    if rule.level == Level::Surface {
        return surface_slide(grid, fp, (i0, j0), rule, push_rows);
    }
    let short = |r: &crate::kneeform::FootprintRow| {
        fault == Some(Fault::FootprintRowShort) && Some(r.dj) == leading
    };
    let mut yr = f64::INFINITY;
    // The rows in the footprint's slide order (by `d0`, then `j`), each
    // with the column of its first node in front.
    let mut in_order: Vec<(f64, i64, usize)> = Vec::with_capacity(fp.rows.len());
    for &r in &fp.slide_order {
        let row = &fp.rows[r as usize];
        let Some((row, j)) = on_grid(row).filter(|_| !short(row)) else {
            continue;
        };
        for k in row.klo..=row.khi {
            let i = i0 as i64 + i64::from(k);
            if (0..spec.nx as i64).contains(&i) {
                yr = yr.min(h(i as usize, j));
            }
        }
        in_order.push((row.d0, i0 as i64 + i64::from(row.kf), j));
    }
    let mut trace = GridTrace {
        yr,
        colliding: Vec::new(),
        push_rows,
        levels: Vec::new(),
    };
    if yr == f64::INFINITY {
        return trace;
    }
    // Every node in front when alone; when joining, the first layers, more
    // as the slide needs them: all nodes nearer than `layers * p` are laid
    // (a row's first node in front lies in `(0, p]`, up to rounding), and
    // the front's order up to there is the whole front's.
    let neighbour = neighbour.filter(|b| b.0.yr.is_finite());
    let all_layers = in_order.iter().map(|r| r.1).max().unwrap_or(-1) + 1;
    let mut layers = match neighbour {
        Some((_, shift)) => {
            ((rule.window / p).ceil() as i64 + 1 + shift as i64 + JOIN_SPARE_LAYERS).min(all_layers)
        }
        None => all_layers,
    };
    let laid_up_to = |layers: i64| {
        if layers >= all_layers {
            f64::INFINITY
        } else {
            layers as f64 * p - FRONT_SLACK
        }
    };
    let mut front = front_in_distance_order(&in_order, p, spec.nx, layers);
    // Where the neighbour's level curve has come down to `f`: the first of
    // its levels at or below it.
    let mut joined = 0;
    let mut f = yr;
    let mut history = LevelHistory::new(yr);
    let mut k = 0;
    loop {
        if k == front.len() && layers == all_layers {
            break;
        }
        if k == front.len() || front[k].0 >= laid_up_to(layers) {
            layers = (2 * layers).min(all_layers);
            front = front_in_distance_order(&in_order, p, spec.nx, layers);
            continue;
        }
        let s = front[k].0;
        if let Some((b, shift)) = neighbour {
            while joined < b.levels.len() && b.levels[joined].1 > f {
                joined += 1;
            }
            let meets = if b.yr <= f {
                0.0
            } else {
                b.levels.get(joined).map_or(f64::INFINITY, |l| l.0)
            };
            // The shift and a pitch to spare.
            if s >= meets + rule.window + (shift + 1) as f64 * p {
                join(&mut trace, b, s, f, &in_order, (p, shift as f64 * p));
                return trace;
            }
        }
        let mut end = k + 1;
        if fault != Some(Fault::IgnoreTies) {
            while end < front.len() && front[end].0 - front[end - 1].0 <= NODE_TOL {
                end += 1;
            }
        }
        // The group's travel is its smallest distance.
        let s = front[k].0;
        let earlier = history.earlier(s, rule.window);
        let mut gmin = f64::INFINITY;
        for &(d, i, j) in &front[k..end] {
            let hv = h(i, j);
            let behind = if i + 1 < spec.nx {
                h(i + 1, j)
            } else {
                f64::INFINITY
            };
            let met = Meeting {
                h: hv,
                behind,
                level: f,
                earlier,
                pitch: p,
            };
            if rule.strikes(met) {
                trace.colliding.push(GridContact {
                    node: (i, j),
                    point: [spec.x(i), spec.z(j)],
                    travel: d,
                    value: hv,
                    slack: 0.0,
                });
            }
            gmin = gmin.min(hv);
        }
        if gmin < f {
            f = gmin;
            trace.levels.push((s, f));
        }
        history.push(s, f);
        k = end;
    }
    trace
}

/// [`slide`] under the surface level (SPEC v4): [`crate::surface::trace`]
/// alone, with no fault and no neighbour joined (its bisections follow the
/// start's own contacts, so two starts' curves need not agree once they
/// meet), each strike at the node nearest its witness with the value the
/// rule judged there. A node struck again at the same travel (several
/// outline points of one tie set nearest it) is kept once, with the
/// lowest of its values less their slack: the strike the level error
/// explains most readily stands for them all (the mask is the same).
fn surface_slide(
    grid: &HeightGrid,
    fp: &GridFootprint,
    (i0, j0): (usize, usize),
    rule: &StrikeRule,
    push_rows: Vec<FootprintSpan>,
) -> GridTrace {
    let spec = grid.spec;
    let surface = SurfaceGrid::new(grid);
    let trace = crate::surface::trace(&surface, &SurfaceFootprint::new(fp), (i0, j0), rule);
    let mut colliding: Vec<GridContact> = trace
        .strikes
        .iter()
        .map(|t| GridContact {
            node: t.node,
            point: [spec.x(t.node.0), spec.z(t.node.1)],
            travel: t.travel,
            value: t.value,
            slack: t.slack,
        })
        .collect();
    // By travel (the order they came in), then by node, each kept once.
    let floor = |c: &GridContact| c.value - c.slack;
    colliding.sort_by(|a, b| {
        (a.travel.total_cmp(&b.travel))
            .then(a.node.1.cmp(&b.node.1))
            .then(a.node.0.cmp(&b.node.0))
            .then(floor(a).total_cmp(&floor(b)))
    });
    colliding.dedup_by(|later, kept| later.travel == kept.travel && later.node == kept.node);
    GridTrace {
        yr: trace.yr,
        colliding,
        push_rows,
        levels: trace.levels,
    }
}

/// Completes `trace`, slid on its own up to the tie group at travel `s`
/// (exclusive) and level `f`, with the strikes and the level curve of
/// `neighbour`, `d` mm to its -x, from there ([`grid_trace_joining`]).
/// `rows` are the trace's rows in front, `(d0, first column in front,
/// row)`, the pitch `p` apart.
fn join(
    trace: &mut GridTrace,
    neighbour: &GridTrace,
    s: f64,
    f: f64,
    rows: &[(f64, i64, usize)],
    (p, d): (f64, f64),
) {
    // A node's distance as this start's own slide computes it.
    let distance = |(i, j): (usize, usize)| {
        let &(d0, first, _) = rows.iter().find(|r| r.2 == j)?;
        Some(d0 + (first - i as i64) as f64 * p)
    };
    let start = trace.colliding.len();
    trace
        .colliding
        .extend(neighbour.colliding.iter().filter_map(|c| {
            let travel = distance(c.node).filter(|&d| d >= s)?;
            Some(GridContact { travel, ..*c })
        }));
    // In this start's order: by distance, ties by row.
    trace.colliding[start..]
        .sort_by(|a, b| a.travel.total_cmp(&b.travel).then(a.node.1.cmp(&b.node.1)));
    trace.levels.extend(
        neighbour
            .levels
            .iter()
            .filter(|l| l.1 < f)
            .map(|&(t, level)| (t + d, level)),
    );
}

/// The nodes in front of a start, `(distance, i, j)`, in the order the
/// slide meets them: by distance, ties by row. `rows` holds each row's
/// `d0` (in `(0, p]`, up to rounding), the column of its first node in
/// front and its grid row, in the order of `d0` then row; the row meets
/// its columns `first, first - 1, ... 0` at `d0, d0 + p, ...`. Only the
/// first `layers` nodes of each row: every node nearer than `layers * p`
/// (all of them from the deepest row's `first + 1` on).
///
/// Generated layer by layer (the `m`-th node in front of every row, rows
/// in `d0` order), which is that order up to rounding at the layers'
/// borders; an insertion sort settles those, so the result is the sorted
/// order exactly, in time linear in the nodes instead of a sort's
/// `n log n` (the per-start trace met 10^5 nodes on the console).
fn front_in_distance_order(
    rows: &[(f64, i64, usize)],
    p: f64,
    nx: usize,
    layers: i64,
) -> Vec<(f64, usize, usize)> {
    let mut front: Vec<(f64, usize, usize)> = Vec::new();
    for m in 0..layers {
        for &(d0, first, j) in rows {
            let i = first - m;
            if (0..nx as i64).contains(&i) {
                front.push((d0 + m as f64 * p, i as usize, j));
            }
        }
    }
    let before = |a: &(f64, usize, usize), b: &(f64, usize, usize)| {
        a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)).is_lt()
    };
    for k in 1..front.len() {
        let mut n = k;
        while n > 0 && before(&front[n], &front[n - 1]) {
            front.swap(n, n - 1);
            n -= 1;
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{EngineOptions, colliding_masks};
    use crate::grid::GridSpec;
    use crate::kneeform::KneeForm;

    /// The layered order is the sorted order exactly, rounding ties at
    /// the layers' borders included.
    #[test]
    fn nodes_in_front_come_in_sorted_order() {
        for (pitch, angle) in [(3.0, -30.0), (1.24, 7.0), (0.7, 30.0), (2.0, 0.0)] {
            let spec = GridSpec {
                pitch,
                i_origin: -3,
                j_origin: 0,
                nx: 90,
                nz: 60,
            };
            let knee = KneeForm {
                triangle_side: 50.0,
                radius: 15.0,
                thickness: 100.0,
            };
            let fp = GridFootprint::new(&knee, angle, &spec);
            let mut met = 0;
            for (i0, j0) in [(0, 30), (40, 30), (89, 5), (70, 59)] {
                let rows: Vec<(f64, i64, usize)> = fp
                    .slide_order
                    .iter()
                    .map(|&r| &fp.rows[r as usize])
                    .filter_map(|r| {
                        let j = j0 as i64 + i64::from(r.dj);
                        (0..spec.nz as i64).contains(&j).then_some((
                            r.d0,
                            i0 as i64 + i64::from(r.kf),
                            j as usize,
                        ))
                    })
                    .collect();
                let mut sorted = Vec::new();
                for &(d0, first, j) in &rows {
                    for m in 0..=first.max(-1) {
                        let i = first - m;
                        if i < spec.nx as i64 {
                            sorted.push((d0 + m as f64 * pitch, i as usize, j));
                        }
                    }
                }
                sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
                let all = rows.iter().map(|r| r.1).max().unwrap_or(-1) + 1;
                let layered = front_in_distance_order(&rows, pitch, spec.nx, all);
                met += layered.len();
                assert_eq!(
                    layered, sorted,
                    "pitch {pitch}, angle {angle}, start {i0} {j0}"
                );
            }
            assert!(met > 1000, "{met}");
        }
    }

    /// The union of the per-start traces is the engine's mask.
    #[test]
    fn union_of_start_traces_is_the_engine_mask() {
        let spec = GridSpec {
            pitch: 3.0,
            i_origin: -10,
            j_origin: -5,
            nx: 70,
            nz: 30,
        };
        let grid = HeightGrid::from_fn(spec, |x, z| {
            0.15 * x + 4.0 * (0.11 * x).sin() * (0.07 * z).cos()
        });
        let knee = KneeForm {
            triangle_side: 50.0,
            radius: 15.0,
            thickness: 100.0,
        };
        for angle in [-30.0, 0.0, 12.0] {
            let fp = GridFootprint::new(&knee, angle, &spec);
            let mut union = vec![0u8; spec.len()];
            for j0 in 0..spec.nz {
                for i0 in 0..spec.nx {
                    for c in grid_trace(&grid, &fp, i0, j0, &StrikeRule::default(), None).colliding
                    {
                        union[c.node.1 * spec.nx + c.node.0] = 1;
                    }
                }
            }
            let masks = colliding_masks(
                &grid,
                std::slice::from_ref(&fp),
                &EngineOptions::default(),
                &|| {},
            );
            assert_eq!(masks[0].mask, union, "angle {angle}");
            assert!(masks[0].colliding > 0);
        }
    }

    /// A wavy slope at 2 mm and a small knee-form: the surface level's
    /// traces strike, tie and differ from the node level's on it.
    fn wavy_surface_case() -> (GridSpec, HeightGrid, KneeForm) {
        let spec = GridSpec {
            pitch: 2.0,
            i_origin: -10,
            j_origin: -5,
            nx: 50,
            nz: 24,
        };
        let grid = HeightGrid::from_fn(spec, |x, z| {
            0.15 * x + 4.0 * (0.11 * x).sin() * (0.07 * z).cos()
        });
        let knee = KneeForm {
            triangle_side: 20.0,
            radius: 6.0,
            thickness: 100.0,
        };
        (spec, grid, knee)
    }

    /// Under the surface level too, the union of the per-start traces is
    /// the engine's mask, and it is not the node level's.
    #[test]
    fn union_of_surface_start_traces_is_the_engine_mask() {
        let (spec, grid, knee) = wavy_surface_case();
        let rule = StrikeRule::default().with_level(Level::Surface);
        for angle in [-30.0, 12.0] {
            let fp = GridFootprint::new(&knee, angle, &spec);
            let mut union = vec![0u8; spec.len()];
            for j0 in 0..spec.nz {
                for i0 in 0..spec.nx {
                    for c in grid_trace(&grid, &fp, i0, j0, &rule, None).colliding {
                        union[c.node.1 * spec.nx + c.node.0] = 1;
                    }
                }
            }
            let options = EngineOptions {
                rule,
                ..EngineOptions::default()
            };
            let masks = colliding_masks(&grid, std::slice::from_ref(&fp), &options, &|| {});
            assert_eq!(masks[0].mask, union, "angle {angle}");
            assert!(masks[0].colliding > 0);
            let node = colliding_masks(
                &grid,
                std::slice::from_ref(&fp),
                &EngineOptions::default(),
                &|| {},
            );
            assert_ne!(node[0].mask, union, "angle {angle}");
        }
    }

    /// Under the surface level each strike carries the value the window
    /// rule judged: the new level at the contact's own witness, a tie's
    /// value at most its slack above it; never the node's own height
    /// where the surface between nodes set it. Each node is struck once
    /// per travel.
    #[test]
    fn surface_strikes_carry_the_judged_value_once_per_node_and_travel() {
        let (spec, grid, knee) = wavy_surface_case();
        let rule = StrikeRule::default().with_level(Level::Surface);
        let (mut strikes, mut ties, mut off_node) = (0, 0, 0);
        for angle in [-30.0, 12.0] {
            let fp = GridFootprint::new(&knee, angle, &spec);
            for j0 in 0..spec.nz {
                for i0 in 0..spec.nx {
                    let t = grid_trace(&grid, &fp, i0, j0, &rule, None);
                    for (k, c) in t.colliding.iter().enumerate() {
                        // The level after the evaluation at the strike's travel.
                        let level = t
                            .levels
                            .iter()
                            .rev()
                            .find(|l| l.0 <= c.travel)
                            .map(|l| l.1)
                            .unwrap();
                        assert!(
                            level <= c.value && c.value <= level + c.slack,
                            "start ({i0}, {j0}) angle {angle}: {c:?} at level {level}"
                        );
                        assert!(
                            !t.colliding[..k]
                                .iter()
                                .any(|e| e.travel == c.travel && e.node == c.node),
                            "{c:?} twice"
                        );
                        strikes += 1;
                        ties += usize::from(c.slack > 0.0);
                        off_node +=
                            usize::from((c.value - grid.at(c.node.0, c.node.1)).abs() > 1e-9);
                    }
                }
            }
        }
        assert!(
            strikes > 100 && ties > 0 && off_node > 0,
            "{strikes} {ties} {off_node}"
        );
    }

    /// A start's trace joined to its -x neighbour's is its trace alone, to
    /// the bit: every start of every row, at angles and pitches where the
    /// level curves join at once, late and never, both rate rules.
    #[test]
    fn a_trace_joined_to_its_neighbours_is_its_trace_alone() {
        let knee = KneeForm {
            triangle_side: 50.0,
            radius: 15.0,
            thickness: 100.0,
        };
        let mut joined = 0;
        for (pitch, amplitude, slope) in [(3.0, 4.0, 0.15), (1.24, 9.0, -0.2), (2.0, 0.0, -0.05)] {
            let spec = GridSpec {
                pitch,
                i_origin: -10,
                j_origin: -5,
                nx: (160.0 / pitch) as usize,
                nz: (90.0 / pitch) as usize,
            };
            // A slope (down towards -x, where the level joins the
            // neighbour's at once, or towards +x, where it joins late),
            // waves, and a step down towards -x.
            let grid = HeightGrid::from_fn(spec, |x, z| {
                let step = if x < 60.0 { -6.0 } else { 0.0 };
                slope * x
                    + amplitude * (0.11 * x).sin() * (0.07 * z).cos()
                    + step
                    + 0.5 * (1.3 * x).sin()
            });
            let rules = [
                StrikeRule::default(),
                StrikeRule {
                    rate: crate::strike::RateEstimate::XSlope,
                    ..StrikeRule::default()
                },
            ];
            for rule in &rules {
                for angle in [-30.0, -7.0, 12.0, 30.0] {
                    let fp = GridFootprint::new(&knee, angle, &spec);
                    for j0 in (0..spec.nz).step_by(4) {
                        let mut before: Vec<GridTrace> = Vec::new();
                        for i0 in 0..spec.nx {
                            let alone = grid_trace(&grid, &fp, i0, j0, rule, None);
                            // Joined to the start one, two and four
                            // nodes to the -x (a pitch's, and the
                            // refinements' at half and a quarter).
                            for shift in [1, 2, 4] {
                                let Some(b) = before.len().checked_sub(shift).map(|n| &before[n])
                                else {
                                    continue;
                                };
                                let chained =
                                    grid_trace_joining(&grid, &fp, (i0, j0), rule, (b, shift));
                                let at = format!(
                                    "pitch {pitch}, angle {angle}, start {i0} {j0}, shift {shift}"
                                );
                                assert_eq!(chained.yr, alone.yr, "{at}");
                                assert_eq!(chained.colliding, alone.colliding, "{at}");
                                assert_eq!(chained.push_rows, alone.push_rows, "{at}");
                                // The level curve: the same levels, at
                                // travels the neighbour's plus the shift.
                                assert_eq!(chained.levels.len(), alone.levels.len(), "{at}");
                                for (c, a) in chained.levels.iter().zip(&alone.levels) {
                                    assert_eq!(c.1, a.1, "{at}");
                                    assert!((c.0 - a.0).abs() < 1e-9, "{at}");
                                }
                                joined += usize::from(!alone.colliding.is_empty());
                            }
                            before.push(alone);
                        }
                    }
                }
            }
        }
        assert!(joined > 3000, "{joined}");
    }
}
