//! `summary.json`: every parameter, input identity, count and timing of a
//! run, so that a result can be audited and reproduced from it alone.

use serde::{Deserialize, Serialize};

/// The colliding area at one angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleSummary {
    /// Knee-form angle (degrees).
    pub angle_deg: f64,
    /// Starts where the knee-form touched the part.
    pub placed_starts: usize,
    /// Grid nodes in the colliding mask.
    pub colliding_nodes: usize,
    /// Their area, `colliding_nodes * pitch^2` (mm^2).
    pub colliding_area_mm2: f64,
}

/// What a `summary.json` written before bodies were counted read: the
/// first body only.
fn one_body() -> usize {
    1
}

/// One file of an assembly ([`crate::assembly`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileSummary {
    /// The file as given.
    pub path: String,
    /// SHA-256 of its bytes (hex).
    pub sha256: String,
    /// Triangles in the file.
    pub triangles: usize,
    /// Of those, skipped for zero area.
    pub degenerate_triangles: usize,
    /// Bodies read from it (an ASCII STL's `solid` blocks; 1 for binary).
    #[serde(default = "one_body")]
    pub bodies: usize,
    /// Disregarded by the regulation (`--ignore`: softer than 50 Shore
    /// A): not in the height grid, so it never collides.
    pub ignored: bool,
    /// Composite nodes whose height this file's surface set (the lowest
    /// file index where two files set the same height): the `file` column
    /// of the CSV files.
    pub colliding_nodes: usize,
    /// Their area, `colliding_nodes * pitch^2` (mm^2).
    pub colliding_area_mm2: f64,
}

/// Wall-clock time per stage (seconds).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Reading and hashing the STL.
    pub read_s: f64,
    /// Sampling the height grid.
    pub sample_s: f64,
    /// Push and slide over every angle.
    pub push_slide_s: f64,
    /// Finding the blind spots.
    #[serde(default)]
    pub blind_s: f64,
    /// The sample check against the exact oracle (0 without one).
    #[serde(default)]
    pub check_s: f64,
    /// Writing the output files.
    pub write_s: f64,
    /// Every stage above, the blind spots' and the sample check's
    /// included.
    pub total_s: f64,
}

/// The whole run. Keys are snake_case; lengths mm, angles degrees, the
/// bounding box in the part's own frame (after `scale`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Version of kneeform that produced the run.
    pub kneeform_version: String,
    /// When the run finished (seconds since the Unix epoch, UTC).
    pub run_unix_time: u64,
    /// The part file as given.
    pub input_file: String,
    /// SHA-256 of the part file's bytes (hex); empty for an assembly,
    /// whose files are in `files`.
    pub sha256: String,
    /// An assembly's files (`analyze a.stl b.stl`, or any `--ignore`), in
    /// order: each one's path, SHA-256 and colliding area. Absent for one
    /// file.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<FileSummary>,
    /// Triangles in the file.
    pub triangles: usize,
    /// Triangles skipped for zero area.
    pub degenerate_triangles: usize,
    /// Bodies read: an ASCII STL's `solid ... endsolid` blocks, every one
    /// (1 for a binary STL or a scenario; over an assembly's analysed
    /// files, their sum). A summary written before bodies were counted
    /// reads 1: such runs read the first body only.
    #[serde(default = "one_body")]
    pub bodies: usize,
    /// Part bounding box, smallest x, y, z (mm, part frame).
    pub bbox_min: [f64; 3],
    /// Part bounding box, largest x, y, z (mm, part frame).
    pub bbox_max: [f64; 3],
    /// Factor from the file's units to mm.
    pub scale: f64,
    /// `left` or `right`.
    pub side: crate::Side,
    /// `--frame`: the map from the part's coordinates into vehicle
    /// coordinates, applied before the side's mirror. Absent without one
    /// (the part is in vehicle coordinates).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<crate::frame::FrameRecord>,
    /// Knee-form triangle side L (mm).
    pub triangle_side_mm: f64,
    /// True when L is the assumed default of 200 mm.
    pub triangle_side_assumed: bool,
    /// Knee-form radius R (mm).
    pub radius_mm: f64,
    /// Knee-form thickness W (mm).
    pub thickness_mm: f64,
    /// Grid pitch (mm).
    pub pitch_mm: f64,
    /// x, z of grid node (0, 0) (mm).
    pub grid_origin: [f64; 2],
    /// Nodes along x, z.
    pub grid_size: [usize; 2],
    /// Nodes with a finite height.
    pub sampled_nodes: usize,
    /// Angles analysed (degrees).
    pub angles_deg: Vec<f64>,
    /// Deflection threshold delta (degrees): a contact is a strike when
    /// the surface turns the knee-form aside by more than this.
    pub deflection_deg: f64,
    /// The same threshold as a rate, `sigma = tan(delta)`.
    pub sigma: f64,
    /// Rounding tolerance e0 (mm): a point is a contact when it sticks out
    /// past the face level by more than this.
    pub e0_mm: f64,
    /// How a contact's deflection is measured: `window` (the default,
    /// SPEC's rule: the level's drop over the last `window_mm` of travel)
    /// or `x-slope` (the rise from the node one pitch behind it).
    pub rate: String,
    /// The level the knee-form's face follows: `node` or `surface`
    /// (SPEC v4). `node` in runs of earlier versions.
    #[serde(default)]
    pub level: crate::strike::Level,
    /// The deflection window `W` (mm) of the `window` rule; absent under
    /// `x-slope` and in runs of earlier versions (which had no window).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_mm: Option<f64>,
    /// `fast` or `paper`.
    pub algorithm: crate::Algorithm,
    /// `slide` (push-and-slide, SPEC) or `direct` (the direct approach,
    /// [`crate::direct`]: the grid, its origin and the heights are then in
    /// the direct frame, and the deflection threshold, `sigma` and `rate`
    /// are recorded but not used). Absent in runs of earlier versions
    /// (slide).
    #[serde(default)]
    pub approach: crate::frame::Approach,
    /// Worker threads.
    pub threads: usize,
    /// Per angle, in the order of `angles_deg`.
    pub per_angle: Vec<AngleSummary>,
    /// Nodes colliding at some angle.
    pub composite_nodes: usize,
    /// Their area (mm^2).
    pub composite_area_mm2: f64,
    /// The depth threshold of a blind spot (mm). Absent in runs of
    /// earlier versions.
    #[serde(default)]
    pub blind_depth_mm: f64,
    /// Grid cells where the part sticks out between the nodes by more
    /// than `blind_depth_mm`: `blind_spots.csv`.
    #[serde(default)]
    pub blind_spots: usize,
    /// Those the knee-form's face meets at some angle at a level they
    /// stick out past: contacts the grid cannot see (said in `warnings`).
    #[serde(default)]
    pub blind_spots_met: usize,
    /// With `--pitch auto`: the pitch study, its tolerance and why it
    /// chose `pitch_mm`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_study: Option<PitchChoice>,
    /// The sample check: the exact oracle on a few seeded starts of this
    /// analysis, compared with its grid as `verify` does, so the result
    /// carries its measured accuracy; or why it was not run. Absent in
    /// runs of earlier versions; a merge of shards holds the shards'
    /// checks merged ([`SampleCheck::merged`]), or none when a shard has
    /// none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_check: Option<SampleCheck>,
    /// The working memory estimated before the run (MiB,
    /// [`crate::memory::MemoryEstimate`]). Absent in runs of earlier
    /// versions.
    #[serde(default)]
    pub memory_estimate_mib: f64,
    /// The process's peak resident memory when the summary was written
    /// (MiB), where the system says: what the estimate is held to. A
    /// measurement, like `timings`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_rss_mib: Option<f64>,
    /// Time per stage.
    pub timings: Timings,
    /// The sanity checks' warnings (one line each), as printed on stderr:
    /// a part in the wrong units or facing the wrong way, angles beyond the
    /// regulation's, nothing struck. Absent in runs of earlier versions.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// The composite's struck zones ([`crate::zones`]), largest first, as
    /// `zones.csv` lists them. Absent in runs of earlier versions.
    #[serde(default)]
    pub zones: Vec<crate::zones::Zone>,
}

/// Why a `summary.json` cannot be used: it does not parse as a summary, or
/// a field is outside what any run writes (a tampered or corrupt file).
#[derive(Debug, thiserror::Error)]
pub enum SummaryError {
    /// Not JSON, or not the summary's schema.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A field is out of bounds or contradicts another.
    #[error("`{field}` {reason}")]
    Field {
        /// The key at fault.
        field: &'static str,
        /// What is wrong with it, in words.
        reason: String,
    },
}

impl Summary {
    /// Parses a `summary.json` and checks every field a reader sizes or
    /// indexes anything by against [`crate::limits`] and the other
    /// fields, so that a tampered file is refused before any allocation it
    /// would drive: the grid's size, pitch and origin, the angles and their
    /// per-angle rows, the node counts, the part's identity and the
    /// knee-form's dimensions.
    pub fn from_json(text: &str) -> Result<Summary, SummaryError> {
        let summary: Summary = serde_json::from_str(text)?;
        summary.check()?;
        Ok(summary)
    }

    fn check(&self) -> Result<(), SummaryError> {
        use crate::limits::{self, short};
        let bad = |field: &'static str, reason: String| Err(SummaryError::Field { field, reason });
        let within = |field: &'static str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                bad(
                    field,
                    format!("is {}, outside [{}, {}]", short(v), short(lo), short(hi)),
                )
            }
        };
        within(
            "pitch_mm",
            self.pitch_mm,
            limits::MIN_PITCH_MM,
            limits::MAX_PITCH_MM,
        )?;
        within(
            "scale",
            self.scale,
            1.0 / limits::MAX_SCALE,
            limits::MAX_SCALE,
        )?;
        for (field, v) in [
            ("triangle_side_mm", self.triangle_side_mm),
            ("radius_mm", self.radius_mm),
            ("thickness_mm", self.thickness_mm),
        ] {
            within(field, v, f64::MIN_POSITIVE, limits::MAX_LENGTH_MM)?;
        }
        within(
            "blind_depth_mm",
            self.blind_depth_mm,
            0.0,
            limits::MAX_LENGTH_MM,
        )?;
        let m = limits::MAX_COORD_MM;
        for c in self.grid_origin {
            within("grid_origin", c, -m, m)?;
        }
        for (min, max) in self.bbox_min.iter().zip(&self.bbox_max) {
            within("bbox_min", *min, -m, m)?;
            within("bbox_max", *max, *min, m)?;
        }
        let [nx, nz] = self.grid_size;
        let nodes = nx
            .checked_mul(nz)
            .filter(|n| (1..=limits::MAX_GRID_NODES).contains(n));
        let Some(nodes) = nodes else {
            return bad(
                "grid_size",
                format!(
                    "is {nx} x {nz}, not between 1 and {} nodes",
                    limits::MAX_GRID_NODES
                ),
            );
        };
        for (field, count) in [
            ("sampled_nodes", self.sampled_nodes),
            ("composite_nodes", self.composite_nodes),
            ("blind_spots", self.blind_spots),
        ] {
            if count > nodes {
                return bad(
                    field,
                    format!("is {count}, more than the grid's {nodes} nodes"),
                );
            }
        }
        let angles = self.angles_deg.len();
        if !(1..=limits::MAX_ANGLES).contains(&angles) {
            return bad(
                "angles_deg",
                format!("holds {angles} angles, not 1 to {}", limits::MAX_ANGLES),
            );
        }
        for &a in &self.angles_deg {
            within("angles_deg", a, -90.0, 90.0)?;
        }
        if self.per_angle.len() != angles {
            return bad(
                "per_angle",
                format!("holds {} rows for {angles} angles", self.per_angle.len()),
            );
        }
        for (row, &a) in self.per_angle.iter().zip(&self.angles_deg) {
            if row.angle_deg.to_bits() != a.to_bits() || row.colliding_nodes > nodes {
                return bad(
                    "per_angle",
                    format!(
                        "row of angle {} does not match angle {} of a {nodes}-node grid",
                        short(row.angle_deg),
                        short(a)
                    ),
                );
            }
        }
        let hex = |s: &str| s.len() == 64 && s.bytes().all(|b| b.is_ascii_hexdigit());
        if !(self.sha256.is_empty() || hex(&self.sha256)) {
            return bad("sha256", "is not a SHA-256 (64 hex digits)".into());
        }
        if self.threads == 0 || self.threads > limits::MAX_THREADS {
            return bad(
                "threads",
                format!("is {}, not 1 to {}", self.threads, limits::MAX_THREADS),
            );
        }
        Ok(())
    }
}

/// The metrics a user's guarantee is made of (and `verify` passes or fails
/// on): the push error and the decided strike metrics, away from blind
/// spots, and the decided area distance. The others are shown beside them,
/// never hidden. Named here, below the harness that measures them, for
/// the report, which reads a study's files without the harness.
pub const DECIDED_METRICS: [&str; 6] = [
    "push_error_decided",
    "first_contact_error_decided",
    "miss_distance_decided",
    "false_alarm_distance_decided",
    "unmatched_deflection_decided",
    "area_distance_decided",
];

/// What a verification can claim (SPEC, "The verdict"): it judges the
/// area the user gets, the decided, non-blind area miss distance at the
/// worst angle, and claims nothing where its sample cannot support a claim.
/// Named here, below the harness that judges it, for the analysis's sample
/// check and the report, which reads a study's files without the harness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Outcome {
    /// Every decided exact strike away from blind spots lies within the
    /// tolerance of the grid's colliding area, on enough evidence.
    Pass,
    /// One lies further.
    Fail,
    /// The sample cannot support a claim: an oracle failure among its
    /// pairs, too few decided exact strikes (none at all: "nothing to miss"
    /// is not evidence), or sampled places too small to measure an area.
    Inconclusive,
}

/// The fewest decided exact strikes (away from blind spots, over every
/// angle) a verification claims anything on. An area distance is a
/// maximum over points: on a few dozen it says where those few lie, not
/// where the area's boundary is (the README's three-angle verification of
/// six starts had 17 pairs and a few dozen decided strikes, and passed
/// while the default verification of the same part failed). One hundred is
/// met by every default verification of the bundled and held-out parts in
/// `results/README.md` with a margin of an order of magnitude.
pub const MIN_DECIDED_STRIKES: usize = 100;

/// The fewest adjacent starts (one pitch apart in x or z, diagonals
/// included) each sampled place must hold: a start's miss of a touch
/// briefer than a pitch of travel is struck by its neighbours' (SPEC, "The
/// verdict"), so a place measures an area only where a start has a
/// neighbour on each side. Three is the smallest run with a middle start.
pub const MIN_NEIGHBOURHOOD_STARTS: usize = 3;

/// What an [`Outcome`] is judged on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evidence {
    /// Start-angle pairs whose exact query failed.
    pub oracle_failed: usize,
    /// Decided exact strikes away from blind spots.
    pub decided_strikes: usize,
    /// The fewest starts in one sampled place: a group of starts each
    /// adjacent to another of it.
    pub smallest_place: usize,
    /// The decided, non-blind area miss distance at the worst angle (mm;
    /// infinite where the grid strikes nothing near a decided strike).
    pub area_miss_decided: f64,
}

impl Outcome {
    /// The outcome of `evidence` at `tolerance` (mm), and why, in words,
    /// when the evidence cannot support a claim.
    pub fn judge(evidence: &Evidence, tolerance: f64) -> (Outcome, Option<String>) {
        let Evidence {
            oracle_failed,
            decided_strikes,
            smallest_place,
            area_miss_decided,
        } = *evidence;
        let inconclusive = if oracle_failed > 0 {
            Some(format!(
                "the exact oracle failed on {oracle_failed} start-angle pairs (a failed pair is never counted clear)"
            ))
        } else if decided_strikes == 0 {
            Some("no decided exact strike on these starts: nothing to miss is not evidence".into())
        } else if decided_strikes < MIN_DECIDED_STRIKES {
            Some(format!(
                "{decided_strikes} decided exact strikes, fewer than the {MIN_DECIDED_STRIKES} an area distance is claimed on"
            ))
        } else if smallest_place < MIN_NEIGHBOURHOOD_STARTS {
            Some(format!(
                "a sampled place of {smallest_place} start(s), fewer than the {MIN_NEIGHBOURHOOD_STARTS} adjacent starts that measure an area there (use the default --starts, or runs, patches or a strip)"
            ))
        } else {
            None
        };
        match inconclusive {
            Some(why) => (Outcome::Inconclusive, Some(why)),
            None if area_miss_decided > tolerance => (Outcome::Fail, None),
            None => (Outcome::Pass, None),
        }
    }

    /// `PASS`, `FAIL` or `INCONCLUSIVE`.
    pub fn word(self) -> &'static str {
        match self {
            Outcome::Pass => "PASS",
            Outcome::Fail => "FAIL",
            Outcome::Inconclusive => "INCONCLUSIVE",
        }
    }

    /// The exit status of a command that ends in it: 0, 1 or 3 (2 is an
    /// error's).
    pub fn exit_code(self) -> u8 {
        match self {
            Outcome::Pass => 0,
            Outcome::Fail => 1,
            Outcome::Inconclusive => 3,
        }
    }
}

// The pitch study of `--pitch auto` ([`crate::harness::choose_pitch`]),
// as `summary.json` records it.

/// Whether an analysis's sample check ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckStatus {
    /// Run: its figures are in the record.
    Checked,
    /// Skipped by the user (`--no-check`).
    Skipped,
    /// Not run: the record's `note` says why.
    NotRun,
}

/// The sample check of an analysis (`summary.json`'s `sample_check`): the
/// exact oracle on a seeded sample of the analysis's own starts at three
/// of its angles, compared with its grid as `kneeform verify` does. A
/// sample, not the evidence: `verify` gives that.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SampleCheck {
    /// Run, skipped or not run.
    pub status: CheckStatus,
    /// What was checked, or why not, in one sentence.
    pub note: String,
    /// Starts in the sample: grid nodes on the part (each placed at every
    /// angle).
    pub starts: usize,
    /// Their positions `[x, z]` (mm, the analysis grid's frame), so that
    /// `verify` can be run on the same pairs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub start_positions: Vec<[f64; 2]>,
    /// The angles checked (degrees): the first, middle and last analysed.
    pub angles_deg: Vec<f64>,
    /// The sample's seed.
    pub seed: u64,
    /// Start-angle pairs placed by both the grid and the oracle.
    pub compared_pairs: usize,
    /// Pairs whose exact query failed (the check then fails).
    pub oracle_failed: usize,
    /// The largest distance from a decided exact strike to the grid's
    /// strikes of the same start (mm, xz); `null` with no decided exact
    /// strike, or none matched.
    pub miss_distance_decided_mm: Option<f64>,
    /// The largest distance from a grid strike to the exact contacts that
    /// may strike (mm, xz); `null` with no grid strike.
    pub false_alarm_distance_decided_mm: Option<f64>,
    /// The same, over grid strikes beyond the bound of the grid's level
    /// error (those within it are false alarms on the safe side); `null`
    /// with none.
    pub false_alarm_unexplained_mm: Option<f64>,
    /// Exact strikes with no grid strike in their start, decided.
    pub unmatched_exact_decided: usize,
    /// Grid strikes beyond the level error's bound with no possible exact
    /// strike in their start.
    #[serde(default)]
    pub unmatched_grid_decided: usize,
    /// The tolerance the figures are held to (mm): `verify`'s default,
    /// sqrt 2 pitches (a point of the part lies up to that far from its
    /// nearest node).
    pub tolerance_mm: f64,
    /// Whether a decided miss or a false alarm beyond the level error's
    /// bound exceeds `tolerance_mm`, or a decided exact strike has no grid
    /// strike in its start, or an exact query failed: the analysis is
    /// then warned about.
    pub exceeds_tolerance: bool,
    /// Decided exact strikes away from blind spots on the sample's pairs.
    #[serde(default)]
    pub decided_strikes: usize,
    /// The check's outcome, as `verify` would judge its pairs: its starts
    /// are scattered, each a place of one start, too small to measure an
    /// area ([`MIN_NEIGHBOURHOOD_STARTS`]), so it is `INCONCLUSIVE`: a
    /// sample, not the evidence. Absent where it did not run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<Outcome>,
}

impl SampleCheck {
    /// A check that did not run, and why.
    pub fn not_run(status: CheckStatus, note: impl Into<String>) -> SampleCheck {
        SampleCheck {
            status,
            note: note.into(),
            starts: 0,
            start_positions: Vec::new(),
            angles_deg: Vec::new(),
            seed: 0,
            compared_pairs: 0,
            oracle_failed: 0,
            miss_distance_decided_mm: None,
            false_alarm_distance_decided_mm: None,
            false_alarm_unexplained_mm: None,
            unmatched_exact_decided: 0,
            unmatched_grid_decided: 0,
            tolerance_mm: 0.0,
            exceeds_tolerance: false,
            decided_strikes: 0,
            outcome: None,
        }
    }

    /// This check with `exceeds_tolerance` decided from its figures: a
    /// decided miss, or a false alarm the level error does not explain,
    /// further than `tolerance_mm`, or any disagreement no distance
    /// measures (a decided strike on one side only, a failed exact query).
    pub fn judged(mut self) -> SampleCheck {
        let tolerance = self.tolerance_mm;
        let far = |v: Option<f64>| v.is_some_and(|v| v > tolerance);
        self.exceeds_tolerance = far(self.miss_distance_decided_mm)
            || far(self.false_alarm_unexplained_mm)
            || self.unmatched_exact_decided + self.unmatched_grid_decided + self.oracle_failed > 0;
        self.outcome = (self.status == CheckStatus::Checked).then(|| {
            let evidence = Evidence {
                oracle_failed: self.oracle_failed,
                decided_strikes: self.decided_strikes,
                // Seeded scattered starts: each its own place.
                smallest_place: 1,
                area_miss_decided: self.miss_distance_decided_mm.unwrap_or(0.0),
            };
            Outcome::judge(&evidence, tolerance).0
        });
        self
    }

    /// The shards' checks of one run (each at its own angles) as the whole
    /// run's: the figures' largest, the counts' sums, the angles in the
    /// run's order (`angles_deg`, the run's). `None` without any.
    pub fn merged(parts: &[SampleCheck], angles_deg: &[f64]) -> Option<SampleCheck> {
        let first = parts.first()?;
        if first.status != CheckStatus::Checked {
            return Some(first.clone());
        }
        let max = |f: fn(&SampleCheck) -> Option<f64>| parts.iter().filter_map(f).reduce(f64::max);
        let sum = |f: fn(&SampleCheck) -> usize| parts.iter().map(f).sum();
        let mut angles: Vec<f64> = parts.iter().flat_map(|p| p.angles_deg.clone()).collect();
        let rank = |a: &f64| angles_deg.iter().position(|b| b.to_bits() == a.to_bits());
        angles.sort_by_key(rank);
        Some(
            SampleCheck {
                angles_deg: angles,
                compared_pairs: sum(|p| p.compared_pairs),
                oracle_failed: sum(|p| p.oracle_failed),
                miss_distance_decided_mm: max(|p| p.miss_distance_decided_mm),
                false_alarm_distance_decided_mm: max(|p| p.false_alarm_distance_decided_mm),
                false_alarm_unexplained_mm: max(|p| p.false_alarm_unexplained_mm),
                unmatched_exact_decided: sum(|p| p.unmatched_exact_decided),
                unmatched_grid_decided: sum(|p| p.unmatched_grid_decided),
                decided_strikes: sum(|p| p.decided_strikes),
                ..first.clone()
            }
            .judged(),
        )
    }

    /// The check in one line, as the console and the report say it.
    pub fn line(&self) -> String {
        let mm = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3} mm"));
        let head = format!(
            "sample check against the exact oracle ({} starts x {} angles, seed {}, {} pairs compared{})",
            self.starts,
            self.angles_deg.len(),
            self.seed,
            self.compared_pairs,
            if self.oracle_failed > 0 {
                format!(", {} oracle failures", self.oracle_failed)
            } else {
                String::new()
            },
        );
        match self.status {
            CheckStatus::Checked
                if self.miss_distance_decided_mm.is_none()
                    && self.false_alarm_distance_decided_mm.is_none() =>
            {
                format!(
                    "{head}: neither side strikes anything decided on these pairs, so it measured nothing here; `kneeform verify` measures the part"
                )
            }
            CheckStatus::Checked => format!(
                "{head}: {}per-start decided misses up to {}; per-start decided false alarms up to {}, {}{}; on this sample alone its decided misses, and the false alarms the level error does not explain, are {} the tolerance of {} mm (sqrt 2 pitches; the explained false alarms are the cost side, not judged)",
                self.outcome.map_or(String::new(), |o| format!(
                    "{} ({} scattered starts and {} decided exact strikes measure no area: a sample, not the evidence); ",
                    o.word(),
                    self.starts,
                    self.decided_strikes
                )),
                mm(self.miss_distance_decided_mm),
                mm(self.false_alarm_distance_decided_mm),
                match self.false_alarm_unexplained_mm {
                    Some(v) if v > 0.0 => format!(
                        "{} among the false alarms beyond the bound of the grid's level error",
                        mm(Some(v))
                    ),
                    _ => "every false alarm within the bound of the grid's level error (the safe side)"
                        .into(),
                },
                if self.unmatched_exact_decided > 0 {
                    format!(
                        "; {} decided exact strikes in starts where the grid strikes nothing",
                        self.unmatched_exact_decided
                    )
                } else {
                    String::new()
                },
                if self.exceeds_tolerance {
                    "BEYOND"
                } else {
                    "within"
                },
                crate::limits::short(self.tolerance_mm),
            ),
            CheckStatus::Skipped | CheckStatus::NotRun => format!("sample check: {}", self.note),
        }
    }
}

/// One pitch of the study (`summary.json`'s `pitch_study`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PitchStudyRow {
    /// The pitch (mm).
    pub pitch_mm: f64,
    /// The area miss distance judged against the exact oracle on the
    /// sample (mm; `null` where infinite): from the decided exact strikes
    /// not downstream of a flagged blind spot to the grid's, at the worst
    /// angle (what `verify` fails on).
    pub exact_area_distance_mm: Option<f64>,
    /// The false-alarm side over every decided grid strike, the level
    /// error's included (mm; shown, not judged: the grid's level error
    /// strikes more, on the safe side, at half order).
    #[serde(default)]
    pub level_error_area_mm: Option<f64>,
    /// Area distance to the previous, coarser pitch's colliding area over
    /// the whole part (mm; `null` for the first pitch or where one side
    /// strikes nothing).
    pub grid_change_mm: Option<f64>,
    /// Predicted time of the full analysis at this pitch (s).
    pub predicted_s: f64,
    /// Estimated working memory (GiB).
    pub memory_gib: f64,
    /// Whether this pitch meets the tolerance: its outcome is `PASS`.
    pub meets: bool,
    /// Its outcome, as `verify` and `converge` judge it.
    #[serde(default = "inconclusive")]
    pub outcome: Outcome,
}

/// What a record written before outcomes were recorded is read as.
fn inconclusive() -> Outcome {
    Outcome::Inconclusive
}

/// The study and its choice.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PitchChoice {
    /// The chosen pitch (mm).
    pub pitch_mm: f64,
    /// The tolerance (mm).
    pub tolerance_mm: f64,
    /// The study, coarsest first.
    pub study: Vec<PitchStudyRow>,
    /// The predicted time of the analysis at the chosen pitch (s).
    pub predicted_s: f64,
    /// Seconds the study took.
    pub study_s: f64,
    /// Why this pitch, in one sentence.
    pub reason: String,
}

/// How far, in units of the last place (relative: `v * f64::EPSILON`),
/// a figure of a result's JSON may move to a shorter decimal
/// ([`json_text`]).
pub const JSON_NOISE_ULPS: f64 = 4.0;

/// `value` as the pretty JSON of a result file (`summary.json`,
/// `verify.json`, `converge.json`, `diff.json`), with a final newline:
/// every fractional number written as the shortest decimal within
/// [`JSON_NOISE_ULPS`] units in the last place of it ([`rounded_figure`]),
/// so that a computed `-234.36` (`i * p`) is `-234.36`, not its double's
/// `-234.35999999999999`, and `nodes * p^2` is `337680.024`, not
/// `337680.02400000003`. Arithmetic leaves its noise in a double's last
/// few places, and only there: a figure moves by at most 9e-16 of itself
/// (1e-12 mm on a metre), far within the 1e-12 relative tolerance with
/// which a reader places a grid coordinate on its node (the report's
/// `ORIGIN_TOL`), and every digit a figure means is kept (an irrational
/// `sqrt 2 * 1.24` keeps its 15 or 16). Integers are written as they are.
pub fn json_text(value: &impl serde::Serialize) -> serde_json::Result<String> {
    let mut value = serde_json::to_value(value)?;
    round_figures(&mut value);
    Ok(serde_json::to_string_pretty(&value)? + "\n")
}

/// Rounds every floating-point number in `value` ([`json_text`]).
fn round_figures(value: &mut serde_json::Value) {
    use serde_json::Value;
    match value {
        Value::Number(n) if n.is_f64() => {
            if let Some(rounded) = n
                .as_f64()
                .map(rounded_figure)
                .and_then(serde_json::Number::from_f64)
            {
                *n = rounded;
            }
        }
        Value::Array(items) => items.iter_mut().for_each(round_figures),
        Value::Object(fields) => fields.values_mut().for_each(round_figures),
        _ => {}
    }
}

/// The shortest decimal within [`JSON_NOISE_ULPS`] units in the last
/// place of `v` (as a relative `v * f64::EPSILON`), as the double that
/// reads back from it: `v` without its float noise (`-0` as `0`; a
/// non-finite value as it is).
pub fn rounded_figure(v: f64) -> f64 {
    if !v.is_finite() || v == 0.0 {
        return if v == 0.0 { 0.0 } else { v };
    }
    let within = JSON_NOISE_ULPS * f64::EPSILON * v.abs();
    for digits in 1..=17 {
        let text = format!("{v:.*e}", digits - 1);
        if let Ok(r) = text.parse::<f64>()
            && (r - v).abs() <= within
        {
            return if r == 0.0 { 0.0 } else { r };
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn valid() -> serde_json::Value {
        serde_json::json!({
            "kneeform_version": "0", "run_unix_time": 0, "input_file": "p.stl",
            "sha256": "ab".repeat(32), "triangles": 1, "degenerate_triangles": 0,
            "bbox_min": [0.0, 0.0, 0.0], "bbox_max": [1.0, 1.0, 1.0], "scale": 1.0,
            "side": "left", "triangle_side_mm": 200.0, "triangle_side_assumed": true,
            "radius_mm": 60.0, "thickness_mm": 120.0, "pitch_mm": 1.24,
            "grid_origin": [-12.4, 2.48], "grid_size": [3, 4], "sampled_nodes": 12,
            "angles_deg": [-1.0, 0.0], "deflection_deg": 0.5, "sigma": 0.0087,
            "e0_mm": 1e-6, "rate": "x-slope", "algorithm": "fast", "threads": 2,
            "per_angle": [
                {"angle_deg": -1.0, "placed_starts": 1, "colliding_nodes": 2, "colliding_area_mm2": 3.0},
                {"angle_deg": 0.0, "placed_starts": 1, "colliding_nodes": 12, "colliding_area_mm2": 3.0}
            ],
            "composite_nodes": 2, "composite_area_mm2": 3.0,
            "timings": {"read_s": 0.0, "sample_s": 0.0, "push_slide_s": 0.0,
                        "write_s": 0.0, "total_s": 0.0}
        })
    }

    fn with(key: &str, value: serde_json::Value) -> Result<Summary, SummaryError> {
        let mut v = valid();
        v[key] = value;
        Summary::from_json(&v.to_string())
    }

    #[test]
    fn a_written_summary_reads_back() {
        let s = Summary::from_json(&valid().to_string()).unwrap();
        assert_eq!(s.grid_size, [3, 4]);
        // Runs of earlier versions were push-and-slide.
        assert_eq!(s.approach, crate::Approach::Slide);
        let s = with("approach", serde_json::json!("direct")).unwrap();
        assert_eq!(s.approach, crate::Approach::Direct);
        assert!(with("approach", serde_json::json!("sideways")).is_err());
    }

    #[test]
    fn every_field_a_reader_sizes_by_is_bounded() {
        use serde_json::json;
        let refused = [
            ("grid_size", json!([4_000_000_000u64, 4_000_000_000u64])),
            ("grid_size", json!([usize::MAX, 2])),
            ("grid_size", json!([0, 4])),
            ("pitch_mm", json!(1e300)),
            ("pitch_mm", json!(-1.0)),
            ("pitch_mm", json!(1e-300)),
            ("grid_origin", json!([1e300, 0.0])),
            ("angles_deg", json!([])),
            ("angles_deg", json!([0.0, 91.0])),
            ("per_angle", json!([])),
            ("sampled_nodes", json!(13)),
            ("composite_nodes", json!(1_000_000)),
            ("sha256", json!("not a hash")),
            ("threads", json!(0)),
            ("scale", json!(0.0)),
            ("radius_mm", json!(1e300)),
            ("bbox_max", json!([-1.0, 1.0, 1.0])),
        ];
        for (key, value) in refused {
            let err = with(key, value.clone()).expect_err(&format!("{key} = {value}"));
            assert!(
                matches!(err, SummaryError::Field { .. } | SummaryError::Json(_)),
                "{key}: {err}"
            );
        }
        // A message names the key, with short numbers.
        let err = with("pitch_mm", json!(1e-300)).unwrap_err().to_string();
        assert!(err.starts_with("`pitch_mm` is 1e-300, outside"), "{err}");
    }
}

#[cfg(test)]
mod json_tests {
    use super::*;

    #[test]
    fn json_figures_lose_their_float_noise_and_nothing_else() {
        // A computed grid origin (-189 * 1.24) and an area (nodes * p^2).
        let origin = -189.0 * 1.24;
        let area = 219_615.0 * (1.24 * 1.24);
        assert_ne!(origin.to_string(), "-234.36", "the double carries noise");
        assert_ne!(area.to_string(), "337680.024", "the double carries noise");
        let text = json_text(&serde_json::json!({
            "origin": origin,
            "area": area,
            "tenth": 0.1 + 0.2,
            "sum": 0.1 + 0.2 + 0.3,
            "tolerance": 2f64.sqrt() * 1.24,
            "root": std::f64::consts::FRAC_1_SQRT_2,
            "small": 1e-6,
            "tiny": 3.2e-15,
            "count": 219_615,
            "whole": 30.0,
            "negative_zero": -0.0,
            "nested": [[0.1 + 0.2]],
        }))
        .unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["origin"].to_string(), "-234.36");
        assert_eq!(v["area"].to_string(), "337680.024");
        assert_eq!(v["tenth"].to_string(), "0.3");
        assert_eq!(v["sum"].to_string(), "0.6");
        assert_eq!(v["nested"][0][0].to_string(), "0.3");
        // A figure that means all its digits keeps them, to within 1e-15.
        for (key, exact) in [
            ("tolerance", 2f64.sqrt() * 1.24),
            ("root", std::f64::consts::FRAC_1_SQRT_2),
        ] {
            let written = v[key].as_f64().unwrap();
            assert!((written - exact).abs() <= 1e-15 * exact, "{key}: {written}");
            assert!(v[key].to_string().len() >= 16, "{key}: {}", v[key]);
        }
        assert_eq!(v["small"].as_f64(), Some(1e-6));
        assert_eq!(v["tiny"].as_f64(), Some(3.2e-15));
        assert_eq!(v["count"].to_string(), "219615");
        assert_eq!(v["whole"].to_string(), "30.0");
        assert_eq!(v["negative_zero"].to_string(), "0.0");
        assert!(text.ends_with("}\n"));
        // Within 1e-15 of itself: far within the 1e-12 relative tolerance
        // a reader places a grid coordinate with.
        for x in [
            origin,
            area,
            1.0 + 4.9e-13,
            9.999_999_999_999_5,
            -1e300,
            5e-324,
        ] {
            let r = rounded_figure(x);
            assert!((r - x).abs() <= 1e-15 * x.abs(), "{x} -> {r}");
        }
        assert!(rounded_figure(f64::NAN).is_nan());
        assert_eq!(rounded_figure(f64::INFINITY), f64::INFINITY);
    }
}
