//! `verify`: the grid engine and the exact oracle on the same starts, and
//! the metrics of their difference.

use std::collections::HashSet;
use std::time::Instant;

use kneeform_oracle::{OracleOptions, StartStatus, StartTrace};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::metrics::{METRICS, StartComparison, Stats, compare};
use super::trace::{Fault, grid_trace};
use crate::grid::HeightGrid;
use crate::kneeform::{GridFootprint, KneeForm};
use crate::mesh::Triangle;

/// Which starts to compare.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StartSelection {
    /// Every grid node whose start is placed at some angle.
    All,
    /// A seeded random sample of those, without replacement.
    Sample {
        /// How many.
        count: usize,
        /// The seed.
        seed: u64,
    },
}

/// How to compare.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    /// The knee-form.
    pub knee: KneeForm,
    /// Contact tolerance (mm).
    pub eps: f64,
    /// Test-only: a deliberate mistake on the grid side.
    pub fault: Option<Fault>,
}

/// SplitMix64, for seeded start samples (same sample on every machine).
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// The starts to compare, as grid nodes `(i, j)` in row-major order: nodes
/// placed at one of `footprints` at least, all or a seeded sample.
pub fn select_starts(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    selection: StartSelection,
) -> Vec<(usize, usize)> {
    let nx = grid.spec.nx;
    let mut placed = vec![false; grid.spec.len()];
    for fp in footprints {
        for (p, y) in placed.iter_mut().zip(crate::engine::push_levels(grid, fp)) {
            *p |= y.is_finite();
        }
    }
    let mut nodes: Vec<(usize, usize)> = (0..grid.spec.len())
        .filter(|&n| placed[n])
        .map(|n| (n % nx, n / nx))
        .collect();
    if let StartSelection::Sample { count, seed } = selection {
        // A partial Fisher-Yates shuffle, then back to row-major order.
        let mut rng = SplitMix(seed);
        let count = count.min(nodes.len());
        for k in 0..count {
            let pick = k + (rng.next() % (nodes.len() - k) as u64) as usize;
            nodes.swap(k, pick);
        }
        nodes.truncate(count);
        nodes.sort_by_key(|&(i, j)| (j, i));
    }
    nodes
}

/// The exact traces of `starts` (mm, analysis frame) at `angles`, in
/// angle-major order.
pub fn exact_traces(
    triangles: &[Triangle],
    starts: &[[f64; 2]],
    angles: &[f64],
    options: &OracleOptions,
) -> anyhow::Result<Vec<StartTrace>> {
    let part = kneeform_oracle::Part::from_triangles(triangles)?;
    Ok(kneeform_oracle::evaluate(&part, starts, angles, options)?)
}

/// One row of `verify.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VerifyRow {
    /// Grid column of the start.
    pub i: usize,
    /// Grid row of the start.
    pub j: usize,
    /// Knee-form angle (degrees).
    pub angle_deg: f64,
    /// `compared`, `grid_not_placed`, `not_placed` (neither), `oracle_not_placed`
    /// or `oracle_failed`.
    pub status: String,
    /// `yr - yr*` (mm).
    pub push_error: Option<f64>,
    /// Grid minus exact travel to the first contact (mm).
    pub first_contact_error: Option<f64>,
    /// Largest distance from an exact contact to the grid's colliding
    /// points of this start (mm; empty when the grid has none: see
    /// `unmatched_deflection`).
    pub miss_distance: Option<f64>,
    /// Largest distance from a grid colliding point to the exact contacts
    /// and push contact (mm).
    pub false_alarm_distance: Option<f64>,
    /// When the grid strikes nothing but the oracle has contacts: the
    /// largest deflection of the exact knee-form below the grid's level.
    pub unmatched_deflection: Option<f64>,
    /// Exact contact points traced.
    pub exact_contacts: usize,
    /// Grid colliding points.
    pub grid_colliding: usize,
}

/// Counts of a comparison.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Counts {
    /// Start-angle pairs looked at.
    pub pairs: usize,
    /// Pairs placed by both.
    pub compared: usize,
    /// Placed by the oracle only (mesh in the footprint between nodes).
    pub grid_not_placed: usize,
    /// Placed by the grid only: a contradiction (a grid sample is a mesh
    /// point), counted as a failure.
    pub oracle_not_placed: usize,
    /// Placed by neither.
    pub not_placed: usize,
    /// Oracle queries that failed.
    pub oracle_failed: usize,
    /// Exact contacts in starts where the grid strikes nothing (their
    /// size is the `unmatched_deflection` metric).
    pub unmatched_exact: usize,
    /// Grid colliding points in starts where the oracle has neither a
    /// contact nor a push contact (a contradiction, counted as a failure).
    pub unmatched_grid: usize,
}

/// The metrics of one grid against the exact traces.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// One row per start and angle.
    pub rows: Vec<VerifyRow>,
    /// Statistics per metric, in [`METRICS`] order (finite values only;
    /// infinite ones are the `unmatched` counts).
    pub stats: Vec<(String, Stats)>,
    /// Grid colliding (angle, node) pairs against exact contacts snapped
    /// to grid nodes, over the compared starts: intersection over union.
    pub area_iou: f64,
    /// Counts.
    pub counts: Counts,
    /// Seconds spent on the grid side.
    pub grid_s: f64,
}

/// One start-angle pair: its row, its comparison, the grid's colliding
/// nodes and the exact contacts snapped to nodes.
type PairResult = (
    VerifyRow,
    StartComparison,
    Vec<(usize, usize)>,
    Vec<(usize, usize)>,
);

/// Compares `grid` with `traces` (angle-major over `starts`, positions in
/// mm that must be nodes of `grid`).
pub fn compare_grid(
    grid: &HeightGrid,
    footprints: &[GridFootprint],
    starts: &[[f64; 2]],
    traces: &[StartTrace],
    options: &CompareOptions,
) -> anyhow::Result<Comparison> {
    let spec = grid.spec;
    let node_of = |x: f64, z: f64| -> Option<(usize, usize)> {
        let i = ((x - spec.x(0)) / spec.pitch).round();
        let j = ((z - spec.z(0)) / spec.pitch).round();
        let inside = i >= 0.0 && j >= 0.0 && (i as usize) < spec.nx && (j as usize) < spec.nz;
        inside.then_some((i as usize, j as usize))
    };
    let mut nodes = Vec::with_capacity(starts.len());
    for &[x, z] in starts {
        let (i, j) = node_of(x, z).ok_or_else(|| {
            anyhow::anyhow!("start ({x}, {z}) mm is outside the {} mm grid", spec.pitch)
        })?;
        anyhow::ensure!(
            (spec.x(i) - x).abs() < 1e-6 && (spec.z(j) - z).abs() < 1e-6,
            "start ({x}, {z}) mm is not a node of the {} mm grid: the pitches must nest",
            spec.pitch
        );
        nodes.push((i, j));
    }
    let t = Instant::now();
    let pairs: Vec<(usize, usize)> = (0..footprints.len())
        .flat_map(|a| (0..nodes.len()).map(move |s| (a, s)))
        .collect();
    let results: Vec<PairResult> = pairs
        .par_iter()
        .map(|&(a, s)| {
            let (i, j) = nodes[s];
            let fp = &footprints[a];
            let trace = &traces[a * nodes.len() + s];
            let g = grid_trace(grid, fp, i, j, options.eps, options.fault);
            let cmp = compare(&g, trace, options.eps);
            let grid_placed = g.yr.is_finite();
            let status = match (trace.status, grid_placed) {
                (StartStatus::Failed { .. }, _) => "oracle_failed",
                (StartStatus::Placed, true) => "compared",
                (StartStatus::Placed, false) => "grid_not_placed",
                (StartStatus::NotPlaced, true) => "oracle_not_placed",
                (StartStatus::NotPlaced, false) => "not_placed",
            };
            let worst = |v: &[f64]| v.iter().copied().reduce(f64::max);
            let snapped: Vec<(usize, usize)> = if trace.status == StartStatus::Placed {
                trace
                    .contacts
                    .iter()
                    .filter_map(|c| node_of(c.witness[0], c.witness[2]))
                    .collect()
            } else {
                Vec::new()
            };
            let row = VerifyRow {
                i,
                j,
                angle_deg: fp.angle_deg,
                status: status.into(),
                push_error: cmp.push_error,
                first_contact_error: cmp.first_contact_error,
                miss_distance: worst(&cmp.miss).filter(|v| v.is_finite()),
                false_alarm_distance: worst(&cmp.false_alarm).filter(|v| v.is_finite()),
                unmatched_deflection: worst(&cmp.unmatched_deflection),
                exact_contacts: cmp.miss.len(),
                grid_colliding: cmp.false_alarm.len(),
            };
            let grid_nodes = g.colliding.iter().map(|c| c.node).collect();
            (row, cmp, grid_nodes, snapped)
        })
        .collect();
    let grid_s = t.elapsed().as_secs_f64();

    let mut counts = Counts {
        pairs: results.len(),
        ..Counts::default()
    };
    let mut values: Vec<Vec<f64>> = vec![Vec::new(); METRICS.len()];
    let (mut grid_set, mut exact_set) = (HashSet::new(), HashSet::new());
    for ((row, cmp, grid_nodes, snapped), &(a, _)) in results.iter().zip(&pairs) {
        match row.status.as_str() {
            "compared" => counts.compared += 1,
            "grid_not_placed" => counts.grid_not_placed += 1,
            "oracle_not_placed" => counts.oracle_not_placed += 1,
            "not_placed" => counts.not_placed += 1,
            _ => counts.oracle_failed += 1,
        }
        values[0].extend(cmp.push_error);
        values[1].extend(cmp.first_contact_error);
        for (k, v) in [(2, &cmp.miss), (3, &cmp.false_alarm)] {
            let (finite, infinite): (Vec<f64>, Vec<f64>) = v.iter().partition(|x| x.is_finite());
            values[k].extend(finite);
            match k {
                2 => counts.unmatched_exact += infinite.len(),
                _ => counts.unmatched_grid += infinite.len(),
            }
        }
        values[4].extend(&cmp.unmatched_deflection);
        if row.status == "compared" || row.status == "grid_not_placed" {
            grid_set.extend(grid_nodes.iter().map(|&n| (a, n)));
            exact_set.extend(snapped.iter().map(|&n| (a, n)));
        }
    }
    let union = grid_set.union(&exact_set).count();
    let area_iou = if union == 0 {
        1.0
    } else {
        grid_set.intersection(&exact_set).count() as f64 / union as f64
    };
    Ok(Comparison {
        rows: results.into_iter().map(|r| r.0).collect(),
        stats: METRICS
            .iter()
            .zip(&values)
            .map(|(m, v)| (m.to_string(), Stats::of(v)))
            .collect(),
        area_iou,
        counts,
        grid_s,
    })
}

impl Comparison {
    /// Whether every metric is within `tolerance` (mm) and nothing is
    /// contradictory or failed.
    pub fn passes(&self, tolerance: f64) -> bool {
        let c = &self.counts;
        self.stats.iter().all(|(_, s)| s.max <= tolerance)
            && c.oracle_not_placed == 0
            && c.oracle_failed == 0
            && c.unmatched_grid == 0
    }

    /// The worst start-angle pairs by their largest metric, at most `n`.
    pub fn worst(&self, n: usize) -> Vec<(VerifyRow, String, f64)> {
        let mut scored: Vec<(VerifyRow, String, f64)> = self
            .rows
            .iter()
            .filter_map(|r| {
                let candidates = [
                    ("push_error", r.push_error),
                    ("first_contact_error", r.first_contact_error),
                    ("miss_distance", r.miss_distance),
                    ("false_alarm_distance", r.false_alarm_distance),
                    ("unmatched_deflection", r.unmatched_deflection),
                ];
                let (name, v) = candidates
                    .into_iter()
                    .filter_map(|(m, v)| v.map(|v| (m, v.abs())))
                    .max_by(|a, b| a.1.total_cmp(&b.1))?;
                Some((r.clone(), name.to_string(), v))
            })
            .collect();
        scored.sort_by(|a, b| b.2.total_cmp(&a.2));
        scored.truncate(n);
        scored
    }
}
