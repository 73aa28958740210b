//! `verify` and `converge` for the **direct approach** (`--approach
//! direct`): per knee position and angle, the grid's first contact against
//! the exact oracle's cast along -x ([`kneeform_oracle::evaluate_direct`]).
//!
//! **The definition** ([`crate::direct`], the engine). In the
//! placed part's frame the knee-form comes from far in +x and moves in -x;
//! a knee position `(y0, z0)` centres its width `W` on `y0` and puts its
//! reference point at height `z0`. The grid side works in the direct frame
//! `D: (x, y, z) -> (x', y', z') = (y, -x, z)`, where the knee moves in
//! +y' and the height grid `h(x', z') = min y' = -(max x)` (the existing
//! z-buffer of the rotated part) is the first surface it meets. With
//! `a(dz)` the footprint row's front end (the smallest x of `K_theta` at
//! height `dz` above the reference point, [`crate::kneeform::Footprint::row_interval`]),
//! the knee's front at row `dz` is `y' = Y - a(dz)`, so the grid's first
//! contact level of the position at node `(i0, j0)` is
//! `Y* = min (h[i][j] + a(z_j - z_j0))` over the nodes with
//! `|x'_i - x'_i0| <= W/2 + NODE_TOL` and `z_j - z_j0` in the footprint's
//! z-range (closed, [`crate::grid::NODE_TOL`]), and its contacted nodes are those with
//! `h + a <= Y* + e0`. A position with no finite `h` there is not placed.
//! The exact level is `X*`, the reference point's x at first contact, and
//! `Y* = -X*`.
//!
//! **Metrics**, per position and angle where both touch:
//! `level_error = |Y*_grid - Y*_exact|` (mm), and `contact_distance`, from
//! the exact contact (the cast's witness) to the nearest grid-contacted
//! node of that position, in the y-z plane (the position plane, mm). A
//! position placed on one side only is counted (`grid_only`,
//! `exact_only`), an oracle failure too; either fails the comparison.
//!
//! **Invariant:** as [`super::trace`] for the slide, this module re-runs
//! the definition on the engine's grid per position (the engine's masks
//! keep no per-position contacts), with the engine's footprint; the
//! engine's own levels ([`contact_levels`]) are checked equal to it, to
//! the bit, at every position compared (`engine_mismatch`). The
//! deflection threshold `sigma` plays no part in the direct approach (the
//! knee does not slide).

use std::time::Instant;

use kneeform_oracle::{DirectOptions, DirectStatus, DirectTrace, KneeFormDims};
use serde::{Deserialize, Serialize};

use super::approach::{
    Said, ShareKnown, Study, StudyApproach, StudyFile, StudyOptions, StudyResult,
};
use super::codec::{Reader, put_opt, put_u64};
use super::compare::{StartSelection, choose_nodes, node_at};
use super::converge::ConvergeOptions;
use super::converge::{Fit, fit_power_law};
use super::error::HarnessError;
use super::method::{Laid, Method, Pitch, Tracing, sampled_at, spec_at};
use super::metrics::{nearest_rank, sorted_abs};
use super::pairs::{NO_BAND, Pair, Pairs, PitchPart, read_each};
use super::sharded::{
    KnownSummary, StudyKind, StudyPart, StudySummary, merged_pitches, only, oracle_s, read_summary,
};
use super::trace::Fault;
use super::verify::VerifyOptions;
use crate::analysis::Progress;
use crate::direct::{DirectFootprint, contact_levels};
use crate::frame::Approach;
use crate::frame::to_direct;
use crate::grid::HeightGrid;
use crate::input::PartFile;
use crate::kneeform::KneeForm;
use crate::limits::short;
use crate::mesh::{Part, Triangle};
use crate::setup::{Sampled, Setup};
use crate::summary::Outcome;
use std::path::Path;

/// The metrics of the direct approach, in the order of `converge.csv`.
pub const DIRECT_METRICS: [&str; 2] = ["level_error", "contact_distance"];

/// The part in the direct frame ([`to_direct`]: a proper rotation, the
/// winding and the outward side kept), as the analysis samples it.
pub(crate) fn to_direct_frame(triangles: &[Triangle]) -> Part {
    Part {
        triangles: triangles.iter().map(|t| t.map(to_direct)).collect(),
        file_triangles: triangles.len(),
        degenerate: 0,
        bodies: 1,
    }
}

/// The grid's first contact of one position (direct frame).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GridDirectContact {
    /// `Y*` (mm): the level of the knee-form's reference point along y'.
    pub level: f64,
    /// The contacted nodes `(i, j)`: `h + a <= Y* + e0`.
    pub contacted: Vec<(usize, usize)>,
}

/// The grid's first contact of the position at node `(i0, j0)` of `grid`
/// (direct frame), or `None` when no node of the footprint has a finite
/// height. `e0` (mm) is SPEC's rounding tolerance, which makes ties.
pub(crate) fn grid_first_contact(
    grid: &HeightGrid,
    fp: &DirectFootprint,
    (i0, j0): (usize, usize),
    e0: f64,
) -> Option<GridDirectContact> {
    let spec = grid.spec;
    let (nx, nz) = (spec.nx as i64, spec.nz as i64);
    let half = fp.half_width as i64;
    let (first, last) = ((i0 as i64 - half).max(0), (i0 as i64 + half).min(nx - 1));
    // Every footprint node with a finite height, and its knee level there.
    let mut levels: Vec<((usize, usize), f64)> = Vec::new();
    for &(dj, a) in &fp.rows {
        let j = j0 as i64 + i64::from(dj);
        if !(0..nz).contains(&j) {
            continue;
        }
        for i in first..=last {
            let h = grid.at(i as usize, j as usize);
            if h.is_finite() {
                levels.push(((i as usize, j as usize), h + a));
            }
        }
    }
    let level = levels.iter().map(|l| l.1).fold(f64::INFINITY, f64::min);
    if !level.is_finite() {
        return None;
    }
    let contacted = levels
        .iter()
        .filter(|l| l.1 <= level + e0)
        .map(|l| l.0)
        .collect();
    Some(GridDirectContact { level, contacted })
}

/// The nodes of `grid` at which the knee-form is placed at one angle of
/// `footprints` at least (a finite height under its footprint).
fn placed_nodes(grid: &HeightGrid, footprints: &[DirectFootprint]) -> Vec<bool> {
    let spec = grid.spec;
    let (nx, nz) = (spec.nx, spec.nz);
    // Counts of finite heights over [0, i) x [0, j), so that each
    // footprint's rectangle of nodes is counted in four look-ups.
    let mut sum = vec![0u32; (nx + 1) * (nz + 1)];
    for j in 0..nz {
        for i in 0..nx {
            let finite = u32::from(grid.at(i, j).is_finite());
            sum[(j + 1) * (nx + 1) + i + 1] =
                finite + sum[j * (nx + 1) + i + 1] + sum[(j + 1) * (nx + 1) + i]
                    - sum[j * (nx + 1) + i];
        }
    }
    let count = |i0: i64, i1: i64, j0: i64, j1: i64| -> u32 {
        // Nodes in [i0, i1] x [j0, j1], clipped to the grid.
        let (i0, i1) = (i0.max(0), i1.min(nx as i64 - 1));
        let (j0, j1) = (j0.max(0), j1.min(nz as i64 - 1));
        if i0 > i1 || j0 > j1 {
            return 0;
        }
        let at = |i: i64, j: i64| sum[j as usize * (nx + 1) + i as usize];
        at(i1 + 1, j1 + 1) + at(i0, j0) - at(i0, j1 + 1) - at(i1 + 1, j0)
    };
    let mut placed = vec![false; spec.len()];
    for fp in footprints {
        let (Some(first), Some(last)) = (fp.rows.first(), fp.rows.last()) else {
            continue;
        };
        for j in 0..nz as i64 {
            for i in 0..nx as i64 {
                let half = fp.half_width as i64;
                let (first, last) = (i64::from(first.0), i64::from(last.0));
                if count(i - half, i + half, j + first, j + last) > 0 {
                    placed[(j * nx as i64 + i) as usize] = true;
                }
            }
        }
    }
    placed
}

/// Max, 95th percentile, median and mean of absolute values, and their
/// count (all zero when empty).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct DirectStats {
    /// Largest value (mm).
    pub max: f64,
    /// 95th percentile, nearest rank (mm).
    pub p95: f64,
    /// Median, nearest rank (mm).
    pub median: f64,
    /// Mean (mm).
    pub mean: f64,
    /// Number of values.
    pub n: usize,
}

impl DirectStats {
    /// Statistics of the absolute values of `values`.
    pub fn of(values: &[f64]) -> DirectStats {
        let v = sorted_abs(values);
        if v.is_empty() {
            return DirectStats::default();
        }
        DirectStats {
            max: v[v.len() - 1],
            p95: nearest_rank(&v, 0.95),
            median: nearest_rank(&v, 0.5),
            mean: v.iter().sum::<f64>() / v.len() as f64,
            n: v.len(),
        }
    }
}

/// Counts of a direct comparison.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct DirectCounts {
    /// Position-angle pairs compared.
    pub compared: usize,
    /// Touched on both sides.
    pub both: usize,
    /// Placed on the grid, passed by the exact knee-form.
    pub grid_only: usize,
    /// Touched by the exact knee-form, no finite height on the grid.
    pub exact_only: usize,
    /// Oracle queries that failed.
    pub oracle_failed: usize,
    /// Positions whose level from the engine ([`contact_levels`]) is not
    /// this module's transcription's, to the bit.
    pub engine_mismatch: usize,
}

/// One grid's comparison with the exact casts.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectComparison {
    /// Per position and angle, angle-major.
    pub rows: Vec<DirectRow>,
    /// Per [`DIRECT_METRICS`] name, its statistics.
    pub stats: Vec<(String, DirectStats)>,
    /// Counts.
    pub counts: DirectCounts,
    /// Seconds for the grid's first contacts.
    pub grid_s: f64,
}

impl DirectComparison {
    /// Whether both metrics' max is within `tolerance` (mm) with no
    /// one-sided position, no oracle failure and the engine's levels
    /// equal to the transcription's.
    pub fn passes(&self, tolerance: f64) -> bool {
        let c = &self.counts;
        c.grid_only == 0
            && c.exact_only == 0
            && c.engine_mismatch == 0
            && c.oracle_failed == 0
            && self.stats.iter().all(|(_, s)| s.max <= tolerance)
    }

    /// The statistics of metric `name`.
    pub fn stat(&self, name: &str) -> DirectStats {
        self.stats
            .iter()
            .find(|(m, _)| m == name)
            .map_or_else(DirectStats::default, |(_, s)| *s)
    }
}

/// The statuses of a [`DirectRow`].
pub(crate) const DIRECT_STATUSES: [&str; 5] = [
    "both",
    "grid_only",
    "exact_only",
    "neither",
    "oracle_failed",
];

/// The grid's first contacts at `positions` (mm; `(y0, z0)`, nodes of
/// `grid`, which is in the direct frame) against `traces` (angle-major, one
/// per position and angle of `footprints`): the pairs, angle-major, not yet
/// assembled ([`assemble_direct`]), and the seconds they took.
pub(crate) fn direct_pairs(
    grid: &HeightGrid,
    footprints: &[DirectFootprint],
    positions: &[[f64; 2]],
    traces: &[DirectTrace],
    e0: f64,
) -> Result<(Vec<DirectPair>, f64), HarnessError> {
    let spec = grid.spec;
    if traces.len() != positions.len() * footprints.len() {
        return Err(HarnessError::TraceCount {
            traces: traces.len(),
            expected: positions.len() * footprints.len(),
        });
    }
    let nodes = positions
        .iter()
        .map(|&[y, z]| {
            node_at(&spec, y, z).ok_or(HarnessError::StartNotANode {
                x: y,
                z,
                pitch: spec.pitch,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let t = Instant::now();
    let mut pairs = Vec::with_capacity(traces.len());
    for (fp, traces) in footprints.iter().zip(traces.chunks(positions.len().max(1))) {
        let levels = contact_levels(grid, fp);
        for ((&node, &[y, z]), trace) in nodes.iter().zip(positions).zip(traces) {
            let grid_contact = grid_first_contact(grid, fp, node, e0);
            // The engine's fast form must give this transcription's level
            // to the bit (its erosion takes the same minima of the same
            // sums): a difference is counted and fails the comparison.
            let engine = levels[node.1 * spec.nx + node.0];
            let mine = grid_contact.as_ref().map_or(f64::INFINITY, |g| g.level);
            let mut row = DirectRow {
                y,
                z,
                angle_deg: fp.angle_deg,
                status: String::new(),
                grid_level: grid_contact.as_ref().map(|g| -g.level),
                exact_level: None,
                level_error: None,
                exact_y: None,
                exact_z: None,
                contact_distance: None,
                grid_contacted: grid_contact.as_ref().map_or(0, |g| g.contacted.len()),
                exact_ties: 0,
            };
            row.status = match (&trace.status, &grid_contact) {
                (DirectStatus::Failed(_), _) => "oracle_failed",
                (DirectStatus::Clear, None) => "neither",
                (DirectStatus::Clear, Some(_)) => "grid_only",
                (DirectStatus::Contact(c), g) => {
                    row.exact_level = Some(c.level);
                    row.exact_y = Some(c.witness[1]);
                    row.exact_z = Some(c.witness[2]);
                    row.exact_ties = c.ties.len();
                    match g {
                        None => "exact_only",
                        Some(g) => {
                            row.level_error = Some((g.level + c.level).abs());
                            row.contact_distance = g
                                .contacted
                                .iter()
                                .map(|&(i, j)| {
                                    (spec.x(i) - c.witness[1]).hypot(spec.z(j) - c.witness[2])
                                })
                                .min_by(f64::total_cmp);
                            "both"
                        }
                    }
                }
            }
            .into();
            pairs.push(DirectPair {
                row,
                engine_mismatch: engine.to_bits() != mine.to_bits(),
            });
        }
    }
    Ok((pairs, t.elapsed().as_secs_f64()))
}

/// The comparison of `pairs` (angle-major): their rows, counts and
/// statistics, in their order; `grid_s` the seconds they took. A merge of
/// shards assembles the pairs in the unsharded order with this function,
/// as the unsharded study does.
pub(crate) fn assemble_direct(pairs: Vec<DirectPair>, grid_s: f64) -> DirectComparison {
    let mut counts = DirectCounts {
        compared: pairs.len(),
        ..DirectCounts::default()
    };
    let mut rows = Vec::with_capacity(pairs.len());
    for pair in pairs {
        counts.engine_mismatch += usize::from(pair.engine_mismatch);
        match pair.row.status.as_str() {
            "both" => counts.both += 1,
            "grid_only" => counts.grid_only += 1,
            "exact_only" => counts.exact_only += 1,
            "oracle_failed" => counts.oracle_failed += 1,
            _ => {}
        }
        rows.push(pair.row);
    }
    let collect =
        |f: fn(&DirectRow) -> Option<f64>| -> Vec<f64> { rows.iter().filter_map(f).collect() };
    let stats = vec![
        (
            DIRECT_METRICS[0].to_string(),
            DirectStats::of(&collect(|r| r.level_error)),
        ),
        (
            DIRECT_METRICS[1].to_string(),
            DirectStats::of(&collect(|r| r.contact_distance)),
        ),
    ];
    DirectComparison {
        rows,
        stats,
        counts,
        grid_s,
    }
}

/// The oracle's options for `knee` and rounding tolerance `e0` (mm).
pub(crate) fn direct_oracle_options(knee: &KneeForm, e0: f64) -> DirectOptions {
    DirectOptions {
        knee_form: KneeFormDims {
            length: knee.triangle_side,
            radius: knee.radius,
            width: knee.thickness,
        },
        tie_tolerance: e0,
    }
}

/// The direct approach's [`Method`] of every study: the part rotated into
/// the direct frame, its coarsest grid and positions, and the exact casts
/// of a share of them.
pub(super) struct DirectMethod<'a> {
    input: &'a PartFile,
    /// The part in the direct frame.
    part: Part,
    /// The study's setup at the coarsest pitch, of the direct approach.
    setup: Setup,
    /// The coarsest grid, every position of the study on it.
    laid: Laid,
    /// The coarsest grid, kept until its pitch is measured.
    coarse_grid: Option<Sampled>,
    /// The positions cast: a shard's share of `positions`, or all.
    share: Vec<[f64; 2]>,
    traces: Vec<DirectTrace>,
}

impl<'a> DirectMethod<'a> {
    /// The rotated part's coarsest grid (`setup`'s pitch; the direct
    /// approach's own default extent, whatever approach `setup` names) and
    /// the positions of `selection` on it (mm), not yet cast.
    pub(super) fn lay(
        input: &'a PartFile,
        setup: &Setup,
        selection: &StartSelection,
    ) -> Result<DirectMethod<'a>, HarnessError> {
        let part = to_direct_frame(&input.part.triangles);
        let setup = Setup {
            approach: Approach::Direct,
            ..setup.clone()
        };
        let (spec, _) = setup.lay(&part)?;
        let sampled = setup.sample_on(spec, &part.triangles, None);
        let grid = &sampled.grid;
        let (positions, placed) = match selection {
            StartSelection::At(given) => (given.clone(), given.len()),
            _ => {
                let on_part = placed_nodes(grid, &footprints(&setup, spec.pitch));
                let nodes: Vec<(usize, usize)> = (0..spec.len())
                    .filter(|&n| on_part[n])
                    .map(|n| (n % spec.nx, n / spec.nx))
                    .collect();
                let placed = nodes.len();
                let chosen = choose_nodes(&spec, nodes, selection)
                    .iter()
                    .map(|&(i, j)| [spec.x(i), spec.z(j)])
                    .collect();
                (chosen, placed)
            }
        };
        if positions.is_empty() {
            return Err(super::compare::none_chosen(selection, placed));
        }
        Ok(DirectMethod {
            input,
            part,
            setup,
            laid: Laid {
                coarse: spec,
                starts: positions,
                // The direct approach's summaries report no sampling time.
                sample_s: 0.0,
            },
            coarse_grid: Some(sampled),
            share: Vec::new(),
            traces: Vec::new(),
        })
    }
}

impl Method for DirectMethod<'_> {
    fn laid(&self) -> &Laid {
        &self.laid
    }

    /// One exact cast per position and angle: no bisection to resolve a
    /// pitch, and no budget (nothing predicts it: `--shard` fans it out).
    fn trace(&mut self, what: Tracing, progress: &dyn Progress) -> Result<f64, HarnessError> {
        if what.refuse_beyond_s.is_some() {
            // One cast per position: no sample predicts the casts' time.
            progress.note(
                "warning: --budget-s is not applied with --approach direct (one cast per knee position; --shard fans it out)",
            );
        }
        let share = what.share;
        let angles = &self.setup.angles;
        let stage = format!(
            "exact oracle (direct): {} positions x {} angles",
            share.len(),
            angles.len()
        );
        let t = Instant::now();
        // An angle at a time (the same traces, angle-major), so that the
        // stage counts its pairs and tells the time left.
        let pairs = (share.len() * angles.len()) as u64;
        let traces = super::stage::in_stage(progress, &stage, Some(pairs), || {
            let part = kneeform_oracle::Part::from_triangles(&self.input.part.triangles)?;
            let options = direct_oracle_options(&self.setup.knee, self.setup.rule.e0);
            let mut traces = Vec::with_capacity(share.len() * angles.len());
            for &angle in angles {
                traces.extend(kneeform_oracle::evaluate_direct(
                    &part,
                    &share,
                    &[angle],
                    &options,
                )?);
                for _ in &share {
                    progress.step();
                }
            }
            Ok::<_, kneeform_oracle::OracleError>(traces)
        })?;
        self.share = share;
        self.traces = traces;
        Ok(t.elapsed().as_secs_f64())
    }

    fn pitch(&mut self, at: Pitch, progress: &dyn Progress) -> Result<PitchPart, HarnessError> {
        let p = at.p;
        let spec = spec_at(&self.laid.coarse, p);
        let stage = at.stage(&spec, self.traces.len(), " (direct)");
        let (pairs, grid_s) = super::stage::in_stage(progress, &stage, None, || {
            let grid = sampled_at(
                &mut self.coarse_grid,
                &self.setup,
                &self.part.triangles,
                spec,
            )
            .grid;
            direct_pairs(
                &grid,
                &footprints(&self.setup, p),
                &self.share,
                &self.traces,
                self.setup.rule.e0,
            )
        })?;
        Ok(PitchPart {
            pitch: p,
            pairs: Pairs::of(pairs),
            band: NO_BAND,
            grid_s,
            seconds: 0.0,
            nodes: spec.len(),
            covering: Vec::new(),
        })
    }
}

fn footprints(setup: &Setup, pitch: f64) -> Vec<DirectFootprint> {
    setup
        .angles
        .iter()
        .map(|&a| DirectFootprint::new(&setup.knee, a, pitch))
        .collect()
}

/// `verify.json` of the direct approach.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DirectVerifySummary {
    /// Always `direct`.
    pub approach: String,
    /// Which part, read how, by which kneeform: the same record, in the
    /// same order, in every study's JSON.
    #[serde(flatten)]
    pub run: super::identity::RunIdentity,
    /// Grid pitch (mm).
    pub pitch_mm: f64,
    /// The tolerance both metrics' max is held to (mm).
    pub tolerance_mm: f64,
    /// Whether both are within it, with no one-sided position or failure.
    pub pass: bool,
    /// Angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Knee-form L, R, W (mm).
    pub knee_form_mm: [f64; 3],
    /// Rounding tolerance e0 (mm): the ties of both sides.
    pub e0_mm: f64,
    /// The deflection threshold plays no part in the direct approach.
    pub note: String,
    /// `all`, the sample size, a strip or the number given.
    pub starts: String,
    /// The sample's seed.
    pub seed: u64,
    /// Per metric: max, p95, median, mean (mm) and count.
    pub metrics: std::collections::BTreeMap<String, DirectStats>,
    /// Counts.
    pub counts: DirectCounts,
    /// Seconds: the grid's first contacts, the oracle's casts.
    pub grid_s: f64,
    /// See `grid_s`.
    pub oracle_s: f64,
}

const NOTE: &str = "direct approach: the knee-form moves in -x until it first touches the part; the deflection threshold sigma plays no part";

/// A direct verification: the comparison and `verify.json`.
#[derive(Debug, Clone)]
pub struct DirectVerification {
    /// Per-position rows and statistics.
    pub comparison: DirectComparison,
    /// `verify.json`.
    pub summary: DirectVerifySummary,
}

impl DirectVerifySummary {
    /// `verify.json` of `input`, `setup` and `options` before any
    /// comparison: no pass, no statistics, no counts, no seconds
    /// ([`DirectVerifySummary::set_comparison`] sets them).
    pub(super) fn new(
        input: &PartFile,
        setup: &Setup,
        options: &VerifyOptions,
    ) -> DirectVerifySummary {
        let (starts, seed) = super::verify::selection_words(&options.selection);
        DirectVerifySummary {
            approach: "direct".into(),
            run: super::identity::RunIdentity::of(input),
            pitch_mm: setup.pitch,
            tolerance_mm: options.tolerance,
            pass: false,
            angles_deg: setup.angles.clone(),
            knee_form_mm: [
                setup.knee.triangle_side,
                setup.knee.radius,
                setup.knee.thickness,
            ],
            e0_mm: setup.rule.e0,
            note: NOTE.into(),
            starts,
            seed,
            metrics: std::collections::BTreeMap::new(),
            counts: DirectCounts::default(),
            grid_s: 0.0,
            oracle_s: 0.0,
        }
    }

    /// Sets what `comparison` decides (pass, statistics, counts, its grid
    /// seconds) and the oracle's seconds: for the unsharded verification
    /// and a merge of its shards alike.
    pub fn set_comparison(&mut self, comparison: &DirectComparison, oracle_s: f64) {
        self.pass = comparison.passes(self.tolerance_mm);
        self.metrics = comparison.stats.iter().cloned().collect();
        self.counts = comparison.counts;
        self.grid_s = comparison.grid_s;
        self.oracle_s = oracle_s;
    }
}

/// One pitch of a direct convergence study.
#[derive(Debug, Clone)]
pub struct DirectPitchResult {
    /// The pitch (mm).
    pub pitch: f64,
    /// The comparison there.
    pub comparison: DirectComparison,
    /// Grid nodes.
    pub nodes: usize,
}

/// `converge.json` of the direct approach.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DirectConvergeSummary {
    /// Always `direct`.
    pub approach: String,
    /// Which part, read how, by which kneeform: the same record, in the
    /// same order, in every study's JSON.
    #[serde(flatten)]
    pub run: super::identity::RunIdentity,
    /// Knee-form L, R, W (mm).
    pub knee_form_mm: [f64; 3],
    /// The pitches, coarsest first (mm).
    pub pitches_mm: Vec<f64>,
    /// Per metric, the fit of its max error, where it has one.
    pub fits: std::collections::BTreeMap<String, Fit>,
    /// Per metric, the fit of its median error, where it has one.
    pub fits_median: std::collections::BTreeMap<String, Fit>,
    /// The tolerance asked for (mm).
    pub tolerance_mm: Option<f64>,
    /// The coarsest pitch meeting it (mm).
    pub recommended_pitch_mm: Option<f64>,
    /// Angles of the study (degrees).
    pub angles_deg: Vec<f64>,
    /// Rounding tolerance e0 (mm).
    pub e0_mm: f64,
    /// The deflection threshold plays no part in the direct approach.
    pub note: String,
    /// Positions compared per angle.
    pub starts: usize,
    /// The sample's seed.
    pub seed: u64,
    /// Seconds of the oracle's casts.
    pub oracle_s: f64,
}

/// A direct convergence study.
#[derive(Debug, Clone)]
pub struct DirectConvergence {
    /// Every pitch, coarsest first.
    pub results: Vec<DirectPitchResult>,
    /// `converge.json`.
    pub summary: DirectConvergeSummary,
}

impl DirectConvergeSummary {
    /// `converge.json` of `input`, `setup` and `options` with `starts`
    /// positions before any comparison: no fits, no recommended pitch
    /// ([`DirectConvergeSummary::set_results`] sets them).
    pub(super) fn new(
        input: &PartFile,
        setup: &Setup,
        options: &ConvergeOptions,
        starts: usize,
        oracle_s: f64,
    ) -> DirectConvergeSummary {
        let (_, seed) = super::verify::selection_words(&options.selection);
        DirectConvergeSummary {
            approach: "direct".into(),
            run: super::identity::RunIdentity::of(input),
            knee_form_mm: [
                setup.knee.triangle_side,
                setup.knee.radius,
                setup.knee.thickness,
            ],
            pitches_mm: options.pitches.clone(),
            fits: std::collections::BTreeMap::new(),
            fits_median: std::collections::BTreeMap::new(),
            tolerance_mm: options.tolerance,
            recommended_pitch_mm: None,
            angles_deg: setup.angles.clone(),
            e0_mm: setup.rule.e0,
            note: NOTE.into(),
            starts,
            seed,
            oracle_s,
        }
    }

    /// Sets what `results` decide (the fits of the max and median errors,
    /// the coarsest pitch within the tolerance): for the unsharded study
    /// and a merge of its shards alike.
    pub fn set_results(&mut self, results: &[DirectPitchResult]) {
        let fit = |pick: fn(&DirectStats) -> f64| -> std::collections::BTreeMap<String, Fit> {
            DIRECT_METRICS
                .iter()
                .filter_map(|m| {
                    let points: Vec<(f64, f64)> = results
                        .iter()
                        .map(|r| (r.pitch, pick(&r.comparison.stat(m))))
                        .collect();
                    fit_power_law(&points).map(|f| (m.to_string(), f))
                })
                .collect()
        };
        self.fits = fit(|s| s.max);
        self.fits_median = fit(|s| s.median);
        self.recommended_pitch_mm = self.tolerance_mm.and_then(|t| {
            results
                .iter()
                .filter(|r| r.comparison.passes(t))
                .map(|r| r.pitch)
                .max_by(f64::total_cmp)
        });
    }
}

/// One position at one angle: both sides' first contacts and the errors.
/// Positions and points in mm, in the placed part's frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DirectRow {
    /// The position's y (the centre of the knee-form's width).
    pub y: f64,
    /// The position's z (the reference point's height).
    pub z: f64,
    /// Angle (degrees).
    pub angle_deg: f64,
    /// `both`, `grid_only`, `exact_only`, `neither` or `oracle_failed`.
    pub status: String,
    /// The grid's `X* = -Y*` (the reference point's x at first contact).
    pub grid_level: Option<f64>,
    /// The exact `X*`.
    pub exact_level: Option<f64>,
    /// `|Y*_grid - Y*_exact|`.
    pub level_error: Option<f64>,
    /// The exact contact point's y and z.
    pub exact_y: Option<f64>,
    /// See `exact_y`.
    pub exact_z: Option<f64>,
    /// From the exact contact to the nearest grid-contacted node, in y-z.
    pub contact_distance: Option<f64>,
    /// Grid-contacted nodes (ties within `e0`).
    pub grid_contacted: usize,
    /// Exact contact points (ties within `e0` of travel).
    pub exact_ties: usize,
}

/// One position at one angle as a shard keeps it: its row, and whether
/// the engine's level there is not the transcription's (which the row
/// does not say). A comparison is [`assemble_direct`]d from these alone.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectPair {
    /// The row.
    pub row: DirectRow,
    /// The engine's level differs from the transcription's, to the bit.
    pub engine_mismatch: bool,
}

/// A direct pair in `shard.bin`: its row's status, levels, contact and
/// counts, and whether the engine's level differed; the position and
/// angle are the shard's ([`read_direct_pair`] is given them).
impl Pair for DirectPair {
    fn put(&self, out: &mut Vec<u8>) {
        let pair = self;
        let r = &pair.row;
        let status = DIRECT_STATUSES
            .iter()
            .position(|s| *s == r.status)
            .unwrap_or(DIRECT_STATUSES.len());
        out.push(status as u8);
        for v in [
            r.grid_level,
            r.exact_level,
            r.level_error,
            r.exact_y,
            r.exact_z,
            r.contact_distance,
        ] {
            put_opt(out, v);
        }
        put_u64(out, r.grid_contacted as u64);
        put_u64(out, r.exact_ties as u64);
        out.push(u8::from(pair.engine_mismatch));
    }
}

/// A direct pair as [`DirectPair`]'s [`Pair::put`] wrote it, of the
/// position `[y, z]` at `angle_deg`.
fn read_direct_pair(
    r: &mut Reader,
    [y, z]: [f64; 2],
    angle_deg: f64,
) -> Result<DirectPair, String> {
    let status = r.u8()?;
    let status = DIRECT_STATUSES
        .get(usize::from(status))
        .ok_or(format!("a direct status {status}"))?;
    let mut row = DirectRow {
        y,
        z,
        angle_deg,
        status: (*status).into(),
        grid_level: r.opt()?,
        exact_level: r.opt()?,
        level_error: r.opt()?,
        exact_y: r.opt()?,
        exact_z: r.opt()?,
        contact_distance: r.opt()?,
        grid_contacted: 0,
        exact_ties: 0,
    };
    row.grid_contacted = r.len()?;
    row.exact_ties = r.len()?;
    let engine_mismatch = match r.u8()? {
        0 => false,
        1 => true,
        b => return Err(format!("an engine mismatch flag {b}")),
    };
    Ok(DirectPair {
        row,
        engine_mismatch,
    })
}

/// The direct approach's studies: what the one study path
/// ([`super::study`]) asks of it.
pub(crate) struct Direct;

impl StudyApproach for Direct {
    fn approach(&self) -> Approach {
        Approach::Direct
    }

    fn kind_word(&self, kind: StudyKind) -> &'static str {
        match kind {
            StudyKind::Verify => "verify-direct",
            StudyKind::Converge => "converge-direct",
        }
    }

    fn shard_words(&self, kind: StudyKind) -> &'static str {
        match kind {
            StudyKind::Verify => {
                "a direct-approach verification (verify --approach direct --shard)"
            }
            StudyKind::Converge => {
                "a direct-approach convergence study (converge --approach direct --shard)"
            }
        }
    }

    fn lay<'a>(
        &self,
        input: &'a PartFile,
        coarse: &Setup,
        options: StudyOptions,
        _fault: Option<Fault>,
    ) -> Result<Box<dyn Method + 'a>, HarnessError> {
        Ok(Box::new(DirectMethod::lay(
            input,
            coarse,
            options.selection(),
        )?))
    }

    fn summary_as_known(&self, share: ShareKnown) -> StudySummary {
        let ShareKnown {
            input,
            setup,
            options,
            starts,
            parts,
            oracle_s,
            ..
        } = share;
        match options {
            StudyOptions::Verify(o) => {
                let mut s = DirectVerifySummary::new(input, setup, o);
                s.grid_s = parts.first().map_or(0.0, |p| p.grid_s);
                s.oracle_s = oracle_s;
                StudySummary::new(self.named(StudyKind::Verify), s)
            }
            StudyOptions::Converge(o) => {
                let s = DirectConvergeSummary::new(input, setup, o, starts, oracle_s);
                StudySummary::new(self.named(StudyKind::Converge), s)
            }
        }
    }

    fn summary_from_json(
        &self,
        kind: StudyKind,
        json: serde_json::Value,
    ) -> Result<Box<dyn KnownSummary>, String> {
        match kind {
            StudyKind::Verify => read_summary::<DirectVerifySummary>(json),
            StudyKind::Converge => read_summary::<DirectConvergeSummary>(json),
        }
    }

    fn merged_fields(&self, kind: StudyKind) -> serde_json::Value {
        match kind {
            StudyKind::Verify => serde_json::json!({
                "pass": false,
                "metrics": {},
                "counts": DirectCounts::default(),
            }),
            StudyKind::Converge => serde_json::json!({
                "fits": {},
                "fits_median": {},
                "recommended_pitch_mm": null,
            }),
        }
    }

    fn clock_fields(&self, kind: StudyKind) -> &'static [&'static str] {
        match kind {
            StudyKind::Verify => &["grid_s", "oracle_s"],
            StudyKind::Converge => &["oracle_s"],
        }
    }

    fn read_pairs(
        &self,
        r: &mut Reader,
        count: usize,
        at: &dyn Fn(usize) -> ([f64; 2], f64),
    ) -> Result<Pairs, String> {
        read_each(count, |k| {
            let (position, angle) = at(k);
            read_direct_pair(r, position, angle)
        })
    }

    fn merge(&self, summary: StudySummary, parts: &mut [StudyPart]) -> Option<Study> {
        let oracle_s = oracle_s(parts);
        let results = merged_pitches(parts, |clocks, pairs| DirectPitchResult {
            pitch: clocks.pitch,
            comparison: assemble_direct(pairs, clocks.grid_s),
            nodes: clocks.nodes,
        })?;
        Some(match summary.kind {
            StudyKind::Verify => {
                let mut summary = summary.take::<DirectVerifySummary>()?;
                let result = only(results)?;
                summary.set_comparison(&result.comparison, oracle_s);
                Study::of(DirectVerification {
                    comparison: result.comparison,
                    summary,
                })
            }
            StudyKind::Converge => {
                let mut summary = summary.take::<DirectConvergeSummary>()?;
                summary.oracle_s = oracle_s;
                summary.set_results(&results);
                Study::of(DirectConvergence { results, summary })
            }
        })
    }
}

impl KnownSummary for DirectVerifySummary {
    fn angles_and_pitches(&self) -> (&[f64], Vec<f64>) {
        (&self.angles_deg, vec![self.pitch_mm])
    }
}

impl KnownSummary for DirectConvergeSummary {
    fn angles_and_pitches(&self) -> (&[f64], Vec<f64>) {
        (&self.angles_deg, self.pitches_mm.clone())
    }
}

/// A direct verification's files: `verify.csv` (one row per position and
/// angle) and `verify.json` (`"approach": "direct"`).
impl StudyResult for DirectVerification {
    fn files(&self) -> Vec<StudyFile<'_>> {
        StudyFile::verification(&self.comparison.rows, &self.summary)
    }

    fn said(&self, out: &Path) -> Said {
        verification_said(self, out)
    }
}

/// A direct convergence study's files: `converge.csv` (both metrics at
/// every pitch), `verify_<pitch>mm.csv` (each pitch's rows) and
/// `converge.json` (`"approach": "direct"`).
impl StudyResult for DirectConvergence {
    fn files(&self) -> Vec<StudyFile<'_>> {
        let tolerance = self.summary.tolerance_mm;
        let results = &self.results;
        let table = move |csv: &mut csv::Writer<&mut dyn std::io::Write>| {
            csv.write_record([
                "approach",
                "pitch_mm",
                "metric",
                "max",
                "p95",
                "median",
                "mean",
                "n",
                "both",
                "grid_only",
                "exact_only",
                "oracle_failed",
                "engine_mismatch",
                "pass",
            ])?;
            for r in results {
                let c = &r.comparison.counts;
                let pass = tolerance.map_or(String::new(), |t| r.comparison.passes(t).to_string());
                for (metric, s) in &r.comparison.stats {
                    csv.write_record([
                        "direct".to_string(),
                        r.pitch.to_string(),
                        metric.clone(),
                        s.max.to_string(),
                        s.p95.to_string(),
                        s.median.to_string(),
                        s.mean.to_string(),
                        s.n.to_string(),
                        c.both.to_string(),
                        c.grid_only.to_string(),
                        c.exact_only.to_string(),
                        c.oracle_failed.to_string(),
                        c.engine_mismatch.to_string(),
                        pass.clone(),
                    ])?;
                }
            }
            Ok(())
        };
        let pitches = results.iter().map(|r| (r.pitch, &r.comparison.rows[..]));
        StudyFile::convergence(table, pitches, &self.summary)
    }

    fn said(&self, out: &Path) -> Said {
        convergence_said(self, out)
    }

    fn oracle_line(&self, angles: usize) -> Option<String> {
        Some(format!(
            "exact oracle (direct): {} positions x {} angles in {:.1} s",
            self.summary.starts, angles, self.summary.oracle_s
        ))
    }
}

/// What a direct verification says: its statistics, counts and verdict
/// (its results are in `out`); it passes as its summary does.
fn verification_said(result: &DirectVerification, out: &Path) -> Said {
    let s = &result.summary;
    let mut lines = Vec::new();
    for name in DIRECT_METRICS {
        let stats = &s.metrics[name];
        lines.push(format!(
            "{name:>16}: max {:.4}  p95 {:.4}  median {:.4} mm  (n = {})",
            stats.max, stats.p95, stats.median, stats.n
        ));
    }
    let c = &s.counts;
    lines.push(format!(
        "{:>16}: {} position-angle pairs, {} touched on both sides, {} on the grid only, {} exactly only, {} oracle failures, {} engine levels unlike the harness's",
        "positions",
        c.compared,
        c.both,
        c.grid_only,
        c.exact_only,
        c.oracle_failed,
        c.engine_mismatch
    ));
    let verdict = if c.oracle_failed > 0 {
        "INCONCLUSIVE"
    } else if s.pass {
        "PASS"
    } else {
        "FAIL"
    };
    lines.push(format!(
        "kneeform: {verdict} (direct approach) at tolerance {} mm; results in {}",
        crate::limits::short(s.tolerance_mm),
        out.display()
    ));
    // The direct approach's verdict is its own (no area is judged here):
    // its pass or fail, or no claim where the oracle failed.
    let outcome = if c.oracle_failed > 0 {
        Outcome::Inconclusive
    } else if s.pass {
        Outcome::Pass
    } else {
        Outcome::Fail
    };
    Said {
        lines,
        outcome: Some(outcome),
    }
}

/// What a direct convergence study says: its errors per pitch, fitted
/// orders and the pitch it recommends (its results are in `out`).
fn convergence_said(study: &DirectConvergence, out: &Path) -> Said {
    let mut lines = Vec::new();
    for r in &study.results {
        let c = &r.comparison;
        let stats: Vec<String> = c
            .stats
            .iter()
            .map(|(m, s)| format!("{m} max {:.4} median {:.4}", s.max, s.median))
            .collect();
        lines.push(format!(
            "p = {:>6} mm: {} | {} both, {} grid only, {} exact only, {} failed, {} engine mismatches",
            r.pitch,
            stats.join(", "),
            c.counts.both,
            c.counts.grid_only,
            c.counts.exact_only,
            c.counts.oracle_failed,
            c.counts.engine_mismatch
        ));
    }
    for (m, f) in &study.summary.fits {
        lines.push(format!("{m:>16}: max error ~ {:.3} p^{:.2}", f.c, f.alpha));
    }
    match (
        study.summary.tolerance_mm,
        study.summary.recommended_pitch_mm,
    ) {
        (Some(t), Some(p)) => lines.push(format!(
            "kneeform: the coarsest pitch within {} mm is {} mm",
            short(t),
            short(p)
        )),
        (Some(t), None) => lines.push(format!(
            "kneeform: no pitch tried is within {} mm",
            short(t)
        )),
        _ => {}
    }
    lines.push(format!("kneeform: results in {}", out.display()));
    Said {
        lines,
        outcome: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridSpec;

    #[test]
    fn placed_nodes_are_the_positions_with_a_first_contact() {
        // A grid with a finite height at one node in 800 (a footprint
        // covers about 600 at 8 mm), so that about half the positions see
        // none under their footprint and many only at its edges;
        // splitmix64 from a fixed seed.
        let spec = GridSpec::explicit(-400.0, -480.0, 150, 120, 8.0);
        let mut state = 7u64;
        let mut next = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let h = (0..spec.len())
            .map(|_| {
                let r = next();
                if r % 800 == 0 {
                    (r % 1000) as f64 / 100.0
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        let grid = HeightGrid { spec, h };
        let knee = KneeForm::default();
        let fronts: Vec<DirectFootprint> = [-30.0, 0.0, 30.0]
            .iter()
            .map(|&a| DirectFootprint::new(&knee, a, spec.pitch))
            .collect();
        let placed = placed_nodes(&grid, &fronts);
        let (mut some, mut none) = (0, 0);
        for j in 0..spec.nz {
            for i in 0..spec.nx {
                let want = fronts
                    .iter()
                    .any(|fp| grid_first_contact(&grid, fp, (i, j), 1e-6).is_some());
                assert_eq!(placed[j * spec.nx + i], want, "node ({i}, {j})");
                if want { some += 1 } else { none += 1 }
            }
        }
        assert!(some > 100 && none > 100, "{some} placed, {none} not");
    }

    #[test]
    fn stats_give_the_nearest_rank_median_and_p95() {
        let s = DirectStats::of(&[3.0, -1.0, 2.0, 4.0]);
        assert_eq!(
            (s.max, s.p95, s.median, s.mean, s.n),
            (4.0, 4.0, 2.0, 2.5, 4)
        );
        assert_eq!(DirectStats::of(&[]), DirectStats::default());
    }
}

#[cfg(test)]
mod pair_tests {
    use super::*;
    use crate::harness::codec::Reader;

    #[test]
    fn a_direct_pair_reads_back_bit_for_bit_and_a_cut_one_is_an_error() {
        let p = DirectPair {
            row: DirectRow {
                y: 12.0,
                z: -4.0,
                angle_deg: 30.0,
                status: "both".into(),
                grid_level: Some(-0.0),
                exact_level: Some(0.1 + 0.2),
                level_error: Some(f64::MIN_POSITIVE),
                exact_y: Some(11.5),
                exact_z: None,
                contact_distance: Some(f64::INFINITY),
                grid_contacted: 7,
                exact_ties: 2,
            },
            engine_mismatch: true,
        };
        let mut bin = Vec::new();
        p.put(&mut bin);
        let mut r = Reader::new(&bin);
        let back = read_direct_pair(&mut r, [12.0, -4.0], 30.0).unwrap();
        assert_eq!(r.at, bin.len());
        assert_eq!(back, p);
        // PartialEq on f64 would take -0.0 for 0.0: compare the bits too.
        assert_eq!(
            back.row.grid_level.map(f64::to_bits),
            Some((-0.0f64).to_bits())
        );
        for end in 0..bin.len() {
            let mut r = Reader::new(&bin[..end]);
            assert!(
                read_direct_pair(&mut r, [0.0, 0.0], 0.0).is_err(),
                "cut at {end}"
            );
        }
        // An unknown status, an unknown flag.
        let mut bad = bin.clone();
        bad[0] = DIRECT_STATUSES.len() as u8;
        assert!(read_direct_pair(&mut Reader::new(&bad), [0.0, 0.0], 0.0).is_err());
        let mut bad = bin.clone();
        *bad.last_mut().unwrap() = 2;
        assert!(read_direct_pair(&mut Reader::new(&bad), [0.0, 0.0], 0.0).is_err());
    }
}
