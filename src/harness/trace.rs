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
use crate::strike::{LevelHistory, Meeting, StrikeRule};

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
    /// The node as a point: `(x, h, z)` in mm, analysis frame.
    pub point: [f64; 3],
    /// Distance (mm) the knee-form travelled in -x when it met the node.
    pub travel: f64,
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
    let front = front_in_distance_order(&in_order, p, spec.nx);
    let mut trace = GridTrace {
        yr,
        colliding: Vec::new(),
        push_rows,
    };
    if yr == f64::INFINITY {
        return trace;
    }
    let mut f = yr;
    let mut history = LevelHistory::new(yr);
    let mut k = 0;
    while k < front.len() {
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
                    point: [spec.x(i), hv, spec.z(j)],
                    travel: d,
                });
            }
            gmin = gmin.min(hv);
        }
        f = f.min(gmin);
        history.push(s, f);
        k = end;
    }
    trace
}

/// Every node in front of a start, `(distance, i, j)`, in the order the
/// slide meets them: by distance, ties by row. `rows` holds each row's
/// `d0` (in `(0, p]`, up to rounding), the column of its first node in
/// front and its grid row, in the order of `d0` then row; the row meets
/// its columns `first, first - 1, ... 0` at `d0, d0 + p, ...`.
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
) -> Vec<(f64, usize, usize)> {
    let deepest = rows.iter().map(|r| r.1).max().unwrap_or(-1);
    let mut front: Vec<(f64, usize, usize)> = Vec::new();
    for m in 0..=deepest {
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
                let layered = front_in_distance_order(&rows, pitch, spec.nx);
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
        let h: Vec<f64> = (0..spec.len())
            .map(|n| {
                let (x, z) = (spec.x(n % spec.nx), spec.z(n / spec.nx));
                0.15 * x + 4.0 * (0.11 * x).sin() * (0.07 * z).cos()
            })
            .collect();
        let grid = HeightGrid { spec, h };
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
}
