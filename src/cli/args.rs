//! Command-line flags, parsed by clap into raw structs, then validated into
//! typed configurations before any work starts (ripgrep's lowargs/hiargs).

use std::path::PathBuf;

use anyhow::{Context, ensure};
use clap::{Args, Parser, Subcommand};
use kneeform::strike::{Level, RateEstimate};
use kneeform::{
    Algorithm, Approach, Frame, GridPlacement, KneeForm, PartSource, Placement, Setup, SetupError,
    Side, StrikeRule,
};

/// UN Regulation No. 21 knee-form inspection: which areas of an interior
/// part a sliding knee-form strikes (push-and-slide on a height grid, after
/// Inui, Gunji and Umezu). Lengths in mm, angles in degrees. What is
/// computed, exactly, and what each figure means: docs/method.md in the
/// repository.
#[derive(Debug, Parser)]
#[command(
    name = "kneeform",
    version,
    about,
    long_about = None,
    after_help = "What is computed, exactly, and what every figure and verdict means: docs/method.md in kneeform's repository."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// What to do.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Analyse a part: colliding area per knee-form angle and their composite.
    Analyze(AnalyzeArgs),
    /// Write a synthetic height-field part as STL (for tests and examples).
    Scenario(ScenarioArgs),
    /// Time the engine on a paper-sized console (369,408+ triangles, a
    /// 1538 x 801 grid at 1.24 mm, 61 angles) against the paper algorithm.
    Bench(BenchArgs),
    /// Compare the grid engine with the exact oracle on the same starts and
    /// judge the colliding area: PASS (exit 0) when every decided exact
    /// strike away from blind spots lies within --tolerance of the grid's
    /// colliding area at every angle, FAIL (exit 1) when one lies further,
    /// INCONCLUSIVE (exit 3) when the evidence cannot support a claim (an
    /// oracle failure, fewer than 100 decided exact strikes, or a sampled
    /// place of fewer than 3 adjacent starts); 2 on error. Per-start
    /// figures and false alarms are reported beside it as diagnostics.
    Verify(VerifyArgs),
    /// Compare grid and oracle at several pitches: errors, fitted orders of
    /// convergence, and the coarsest pitch meeting --tolerance.
    Converge(ConvergeArgs),
    /// Merge the shards of one analysis, verification or convergence study
    /// (`analyze`, `verify` or `converge --shard K/N`, one directory each)
    /// into its results, byte for byte those of the unsharded command
    /// (clock readings aside). A verification's merge exits as `verify`
    /// does: 0 PASS, 1 FAIL, 3 INCONCLUSIVE, 2 on error.
    Merge(MergeArgs),
    /// Run the analyses a manifest lists (parts, variants), one after the
    /// other, skipping those whose output directory holds a complete run
    /// of the same item: a killed batch started again resumes where it
    /// was, losing only the item it was running.
    Batch(BatchArgs),
    /// Write the evidence report of a run: one self-contained HTML file
    /// with views of the part, the colliding area per angle, and the
    /// verification results of any VERIFY_DIR given.
    Report(ReportArgs),
    /// Compare two revisions of a part (two `analyze` runs with the same
    /// knee-form, strike rule, side, frame and angles): the nodes struck
    /// only in A, only in B and in both, on A's grid, and the struck zones
    /// that appeared, vanished, grew or shrank.
    Diff(DiffArgs),
}

/// How to read the part's files: units, frame and side.
#[derive(Debug, Args)]
pub struct PartArgs {
    /// Factor taking the file's units to mm (e.g. 1000 for metres).
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "FACTOR",
        allow_hyphen_values = true
    )]
    pub scale: f64,
    /// Side of the vehicle the analysed surface is on: `left` faces -y (the
    /// knee is pushed in +y); `right` faces +y and is mirrored y -> -y for
    /// the analysis, results are mirrored back. With --frame, the side is
    /// applied after the frame, in vehicle coordinates.
    #[arg(long, default_value = "left", value_parser = one_of(&Side::ALL, Side::name))]
    pub side: Side,
    /// The part's axes in vehicle coordinates (front -x, z up), for a part
    /// not modelled in them: three signed part axes, one per vehicle axis
    /// x, y, z (`x,-z,y`: vehicle x is the part's x, vehicle y its -z,
    /// vehicle z its y), or @FILE holding a 4x4 or 3x4 rigid transform
    /// (one row a line; part coordinates in mm, after --scale, to vehicle
    /// coordinates). A proper rotation only (orthonormal, determinant +1,
    /// within 1e-6; one off by more than 1e-9, as a matrix written to 8
    /// decimals is, is made its nearest rotation and the change recorded
    /// in summary.json): a mirror is --side right, a scaling is refused. The part is mapped by the
    /// frame first, then mirrored by --side; every result (CSV, STL, PLY,
    /// summary's bounding box) is mapped back to the part's own
    /// coordinates; the images and the report are drawn in vehicle
    /// coordinates.
    #[arg(long, value_name = "AXES|@FILE", allow_hyphen_values = true)]
    pub frame: Option<String>,
}

/// `--pitch`: a length, or `auto`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PitchArg {
    /// This pitch (mm).
    Mm(f64),
    /// Chosen by a pitch study (`analyze --pitch auto --tolerance MM`).
    Auto,
}

impl std::str::FromStr for PitchArg {
    type Err = String;

    fn from_str(s: &str) -> Result<PitchArg, String> {
        if s == "auto" {
            return Ok(PitchArg::Auto);
        }
        s.parse()
            .map(PitchArg::Mm)
            .map_err(|_| format!("expected a pitch in mm or `auto`, got {s:?}"))
    }
}

/// The knee-form angles.
#[derive(Debug, Args)]
pub struct AnglesArg {
    /// Knee-form angles (degrees, positive raises its back): FROM:TO:STEP,
    /// or a comma-separated list (e.g. --angles=-30,-13,0,7,30).
    #[arg(
        long,
        default_value = "-30:30:1",
        allow_hyphen_values = true,
        value_name = "ANGLES"
    )]
    pub angles: String,
}

/// The knee-form and the grid.
#[derive(Debug, Args)]
pub struct SetupArgs {
    /// Grid pitch (mm): node spacing in x and z. The paper used 1.24 mm.
    /// `analyze` also takes `auto` (with --tolerance): a quick convergence
    /// study on the part chooses the coarsest pitch meeting the tolerance.
    #[arg(long, default_value = "1.24", value_name = "MM|auto")]
    pub pitch: PitchArg,
    /// Side L of the knee-form's equilateral triangle (mm). The default 200
    /// is an ASSUMPTION (the regulation's figure was not at hand): set it
    /// from the regulation for a type-approval run.
    #[arg(long, default_value_t = 200.0, value_name = "MM")]
    pub triangle_side: f64,
    /// Rounding radius R of the knee-form (mm).
    #[arg(long, default_value_t = 60.0, value_name = "MM")]
    pub radius: f64,
    /// Thickness W of the knee-form along y (mm).
    #[arg(long, default_value_t = 120.0, value_name = "MM")]
    pub thickness: f64,
    #[command(flatten)]
    pub angles: AnglesArg,
    /// Deflection threshold delta (degrees, 0 <= delta < 45): a point the
    /// knee-form meets is a strike (a colliding point) only when the surface
    /// turns the knee-form aside by more than this angle (measured as
    /// --rate says: by default its drop over the last --window mm of
    /// travel). A surface it merely
    /// brushes, nearly parallel to the slide, is not a strike. 0 is the
    /// paper's literal rule (any point sticking out); larger values report
    /// only steeper contacts.
    #[arg(long, default_value_t = StrikeRule::DEFAULT_DEFLECTION_DEG, value_name = "DEG")]
    pub deflection: f64,
    /// Rounding tolerance e0 (mm, >= 0, at most 0.01): a point is a contact
    /// only when it sticks out past the knee-form's face by more than this.
    /// It only absorbs floating-point rounding (a flat wall); it is not an
    /// engineering tolerance.
    #[arg(long, default_value_t = StrikeRule::DEFAULT_E0, value_name = "MM")]
    pub e0: f64,
    /// How the deflection of a contact is measured: `window` (default,
    /// docs/method.md's rule): the knee-form's own level dropped by more than
    /// tan(--deflection) x --window over the last --window mm of its travel
    /// (on the grid and in the exact oracle alike); `x-slope` (the method's former
    /// baseline, for node-for-node comparison with other implementations):
    /// the surface's rise over one pitch from the point behind it.
    #[arg(
        long,
        default_value = "window",
        value_name = "RATE",
        value_parser = one_of(&RateEstimate::ALL, RateEstimate::name)
    )]
    pub rate: RateEstimate,
    /// The deflection window W (mm, > 0, at most 100 and 1024 pitches) of
    /// `--rate window`: how far back along its travel the knee-form's drop
    /// is measured. A fixed length, independent of the pitch.
    #[arg(long, default_value_t = StrikeRule::DEFAULT_WINDOW_MM, value_name = "MM")]
    pub window: f64,
    /// Which level the knee-form's face follows as it slides (SPEC v4):
    /// `node` (default: the level drops only at the grid's nodes, so
    /// between them it rides too deep) or `surface` (the grid's
    /// piecewise-linear surface between the nodes; each strike at the node
    /// nearest where it touched). `surface` takes `--rate window`,
    /// `--algorithm fast` and `--approach slide` only, and is slow: about
    /// 100 to 140 times the node level's time (over a minute per angle on
    /// the bundled console at 1.24 mm on 2 cores; `results/ab.md`).
    /// `verify` and `converge` run the whole analysis at each angle too
    /// (the area their misses are measured to), so under `surface` they
    /// take at least as long as that analysis
    #[arg(
        long,
        default_value = "node",
        value_name = "LEVEL",
        value_parser = one_of(&Level::ALL, Level::name)
    )]
    pub level: Level,
    /// Grid origin X,Z (mm), snapped to multiples of the pitch. Default: the
    /// part's xz bounding box grown by the knee-form's extent.
    #[arg(
        long,
        value_name = "X,Z",
        allow_hyphen_values = true,
        requires = "grid_size"
    )]
    pub grid_origin: Option<String>,
    /// Grid size NX,NZ (nodes), with --grid-origin.
    #[arg(long, value_name = "NX,NZ", requires = "grid_origin")]
    pub grid_size: Option<String>,
    /// Push-and-slide implementation: `fast` (sliding-window push,
    /// streaming slide) or `paper` (the paper's sections 3-4, literally;
    /// slow). Both give identical results.
    #[arg(long, default_value = "fast", value_parser = one_of(&Algorithm::ALL, Algorithm::name))]
    pub algorithm: Algorithm,
    /// Which knee motion: `slide` (default; the paper's push-and-slide:
    /// the knee-form pushed in +y against a surface facing -y, then slid
    /// in -x, striking what turns it aside by more than --deflection) or
    /// `direct` (its predecessor: the knee-form moved in -x until it first
    /// touches the part, for surfaces facing +x such as an instrument
    /// panel; the area is every first-contact point, within --e0, over
    /// every position and angle; --deflection, --rate and --algorithm
    /// are recorded but not used). See README, "Two approaches".
    #[arg(
        long,
        default_value = "slide",
        value_name = "APPROACH",
        value_parser = one_of(&Approach::ALL, Approach::name)
    )]
    pub approach: Approach,
    /// Worker threads (default: one per CPU). Results do not depend on it.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Blind-spot depth (mm, > 0): a grid cell where the part sticks out
    /// towards the knee between the cell's four nodes by more than this is
    /// a blind spot, a feature the grid cannot see at this pitch (a thin
    /// rib, a sharp edge, a boss). Listed in blind_spots.csv with the pitch
    /// that resolves it; warned of when near the colliding area.
    #[arg(long, default_value_t = Setup::DEFAULT_BLIND_DEPTH, value_name = "MM")]
    pub blind_depth: f64,
    /// Refuse grids whose estimated working memory exceeds this (GiB).
    #[arg(long, default_value_t = 16.0, value_name = "GIB")]
    pub max_memory: f64,
}

/// `kneeform analyze`.
#[derive(Debug, Args)]
pub struct AnalyzeArgs {
    /// The part: an STL file (binary or ASCII), or a scenario file
    /// (`scenarios/*.toml`, tessellated on the fly). Several files are
    /// analysed as one part (an assembly): each colliding node is
    /// attributed to the file whose surface set its height (the first
    /// file given where two set the same height), in summary.json, the
    /// CSV files' `file` column and the report.
    #[arg(required = true, value_name = "PART")]
    pub parts: Vec<PathBuf>,
    /// A file of the assembly that the regulation disregards (a material
    /// softer than 50 Shore A): identified in summary.json (path, SHA-256)
    /// but kept out of the height grid, so the knee-form passes through
    /// it. Repeatable; it may also be among the PART files.
    #[arg(long, value_name = "FILE")]
    pub ignore: Vec<PathBuf>,
    #[command(flatten)]
    pub part: PartArgs,
    #[command(flatten)]
    pub setup: SetupArgs,
    /// Output directory (created; it appears whole or not at all): it
    /// holds summary.json, composite.csv.gz, zones.csv, blind_spots.csv,
    /// depth.png, composite.png and kneeform-run.json (about 2 MB for the
    /// bundled console), and what --csv, --stl, --ply, --points-csv and
    /// --report add. An existing one is refused unless --force is given.
    #[arg(long, default_value = "kneeform-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Replace an existing --out directory of an earlier result (one whose
    /// kneeform-run.json, kneeform's record of the files it wrote, lists
    /// every file in it, unchanged, and which holds none of this run's
    /// inputs; or empty) with this run's results, whole.
    #[arg(long)]
    pub force: bool,
    /// Also write the evidence report, `report.html`, into the output
    /// directory (as `kneeform report DIR` would). The analysis is kept if
    /// only the report fails (exit code 3).
    #[arg(long)]
    pub report: bool,
    /// Also write colliding_points.csv: one row per colliding node per
    /// angle (angle_deg,i,j,x,y,z; mm, shortest round-trip decimals). Off
    /// by default: composite.csv holds the same sets, one row per node with
    /// its angles as a bit mask (angle_mask), some fifty times smaller.
    #[arg(long)]
    pub points_csv: bool,
    #[command(flatten)]
    pub files: FileArgs,
    /// Compute one shard of the angles and write it as a partial result
    /// (shard.json, shard.bin) for `kneeform merge`: shard K of N takes
    /// the run's angles a (0-based, in --angles order) with a % N == K - 1.
    /// 1 <= K <= N <= the number of angles. A Slurm array task passes
    /// `--shard $((SLURM_ARRAY_TASK_ID + 1))/N`, a Kubernetes Indexed Job
    /// `--shard $((JOB_COMPLETION_INDEX + 1))/N`. Default: every angle.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// With --pitch auto: the largest decided area miss distance (mm)
    /// allowed between the exact knee-form's colliding area and the
    /// grid's, judged as `verify` and `converge --tolerance` judge it, on
    /// their default starts: the coarsest pitch whose outcome is PASS.
    #[arg(long, value_name = "MM")]
    pub tolerance: Option<f64>,
    /// With --pitch auto: the longest predicted analysis (seconds) the
    /// chosen pitch may need; a tolerance needing more is refused (exit 2)
    /// with the pitch and time it would need.
    #[arg(long, default_value_t = kneeform::harness::AutoPitch::DEFAULT_BUDGET_S, value_name = "S")]
    pub budget_s: f64,
    /// Skip the sample check. By default every analysis runs the exact
    /// oracle on 5 seeded starts of its own at its first, middle and last
    /// angle, compares them with its grid as `verify` does, and states the
    /// decided miss and false-alarm distances it measured (console,
    /// summary.json's `sample_check`, the report), warning when they
    /// exceed sqrt 2 pitches (`verify`'s default tolerance); it costs the
    /// oracle's time on those 15 pairs (about half a second on the bundled
    /// console). With --no-check the
    /// summary says the analysis carries no measured accuracy.
    #[arg(long)]
    pub no_check: bool,
}

/// `kneeform merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shards' directories (`analyze`, `verify` or `converge --shard
    /// K/N --out DIR`), one per shard, in any order; every K from 1 to N
    /// exactly once, all of one run or study.
    #[arg(required = true, value_name = "SHARD_DIR")]
    pub shards: Vec<PathBuf>,
    /// Output directory of the merged run (created; it appears whole or
    /// not at all). An existing one is refused unless --force is given.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Replace an existing --out directory of an earlier result (as
    /// analyze --force: its kneeform-run.json lists every file in it,
    /// unchanged, and it holds no shard merged here; or empty) with the
    /// merged results, whole.
    #[arg(long)]
    pub force: bool,
    /// Also write colliding_points.csv (as `analyze --points-csv`; an
    /// analysis's shards only).
    #[arg(long)]
    pub points_csv: bool,
    /// (An analysis's shards only.)
    #[command(flatten)]
    pub files: FileArgs,
}

/// The large result files an analysis writes only when asked: by default
/// a run keeps `composite.csv.gz`, the images, `zones.csv`,
/// `blind_spots.csv` and `summary.json` (about 2 MB for the bundled
/// console at its default pitch).
#[derive(Debug, Args)]
pub struct FileArgs {
    /// Write the composite table as plain composite.csv instead of
    /// composite.csv.gz (the same rows, uncompressed: about 50 bytes per
    /// colliding node, 11 MB for the bundled console at its default pitch,
    /// some eight times the compressed file). Default: compressed, which
    /// `zcat`, `gunzip -k` and pandas' `read_csv` read as it is.
    #[arg(long)]
    pub csv: bool,
    /// Also write colliding_area.stl: the colliding area as a binary STL
    /// surface in the part's coordinates (mm), 100 bytes per triangle,
    /// 22 MB for the bundled console. Default: not written.
    #[arg(long)]
    pub stl: bool,
    /// Also write colliding_area.ply: the colliding area as a binary PLY
    /// mesh (mm, part's coordinates, 32-bit floats of values rounded to
    /// 1 um), each vertex coloured by its number of striking angles, for
    /// MeshLab or Blender; about 45 bytes per colliding node, 10 MB for the
    /// bundled console. Default: not written.
    #[arg(long)]
    pub ply: bool,
}

impl FileArgs {
    /// Whether any large file is asked for.
    pub fn any(&self) -> bool {
        self.csv || self.stl || self.ply
    }
}

/// `kneeform batch`.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// The manifest (TOML): `[[item]]` tables, each one `kneeform
    /// analyze` with `part = "FILE"` (or a list: an assembly), `out =
    /// "DIR"` and optionally `pitch` (mm), `angles` (as --angles), `side`
    /// and `args = ["--flag", "value", ...]` (any other analyze flags); a
    /// `[defaults]` table of the same flags applies to every item first.
    /// Paths are relative to the manifest's directory, where the items
    /// run.
    #[arg(value_name = "MANIFEST.toml")]
    pub manifest: PathBuf,
}

/// `kneeform report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The `analyze` output directory.
    pub run_dir: PathBuf,
    /// Output directories of `kneeform verify` or `kneeform converge`.
    #[arg(value_name = "VERIFY_DIR")]
    pub verify_dirs: Vec<PathBuf>,
    /// The HTML file to write. An existing file is refused unless
    /// --force is given.
    #[arg(long, default_value = "report.html", value_name = "FILE")]
    pub out: PathBuf,
    /// Replace an existing --out report (an .html file only: never a part
    /// or a run's file).
    #[arg(long)]
    pub force: bool,
    /// The analysed part, when it is no longer at the path the run names
    /// (its SHA-256 must still be the run's).
    #[arg(long, value_name = "FILE")]
    pub part: Option<PathBuf>,
    /// Another `analyze` run. Of the same approach: an earlier revision of
    /// the part (same knee-form, rule, side, frame and angles), and the
    /// page opens with what changed (as `kneeform diff RUN_DIR RUN`: the
    /// area struck only before, only now, the zones that appeared,
    /// vanished, grew or shrank). Of the other --approach, the same part
    /// (slide against direct): both areas painted on the same rendered
    /// part, with the area only push-and-slide strikes (what the direct
    /// approach cannot reach) and the area only the direct approach
    /// touches.
    #[arg(long, value_name = "RUN_DIR")]
    pub compare: Option<PathBuf>,
}

/// `kneeform diff`.
#[derive(Debug, Args)]
pub struct DiffArgs {
    /// The earlier revision's `analyze` output directory (A): the
    /// comparison is drawn on its grid.
    pub run_a: PathBuf,
    /// The later revision's `analyze` output directory (B), mapped onto
    /// A's grid (each node of A takes the largest count of B's nodes
    /// within half B's pitch in x and z). Its part, pitch and extent may
    /// differ from A's.
    pub run_b: PathBuf,
    /// Output directory (created; it appears whole or not at all):
    /// diff.json, diff_nodes.csv, diff_zones.csv, diff.png. An existing
    /// one is refused unless --force is given.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Replace an existing --out directory of an earlier diff.
    #[arg(long)]
    pub force: bool,
}

/// Which starts a comparison uses.
#[derive(Debug, Args)]
pub struct StartArgs {
    /// Starts to compare: `patches:N:L:R` for N seeded patches of R
    /// adjacent start rows of L adjacent starts (the default, 10 patches
    /// of 3 rows of 5: places measured in x and z, spread over the part,
    /// each row costing the oracle about one start, its traces chained),
    /// `runs:N:L` for N seeded runs of L adjacent starts along one row
    /// (1 <= L <= 64), `strip:Z0:Z1` for every placed start
    /// with Z0 <= z <= Z1 (mm): a whole strip of start rows, whose area
    /// distance is the colliding area a user sees there, a number N for a
    /// seeded random sample of N scattered starts (each traced on its own:
    /// about 4x the oracle's time of the same number in runs: too few
    /// neighbours to measure an area, so INCONCLUSIVE), or `all` (every
    /// node whose start is placed at some angle).
    #[arg(
        long,
        default_value = "patches:10:5:3",
        value_name = "runs:N:L|patches:N:L:R|strip:Z0:Z1|N|all",
        allow_hyphen_values = true
    )]
    pub starts: String,
    /// Seed of the start sample or of the runs.
    #[arg(long, default_value_t = 1, value_name = "S")]
    pub seed: u64,
    /// Growth of the tie band with the pitch (per mm): exact contacts whose
    /// deflection rate is within a factor 1 + TIE_BAND x pitch of the
    /// threshold are undecided (either answer is right at this pitch) and
    /// never fail a comparison; they are counted and shown.
    #[arg(long, default_value_t = kneeform::harness::TieBand::DEFAULT_PER_MM, value_name = "PER_MM")]
    pub tie_band: f64,
}

impl StartArgs {
    /// Validates the flags.
    pub fn validate(&self) -> anyhow::Result<kneeform::harness::StartSelection> {
        use kneeform::harness::StartSelection;
        if self.starts == "all" {
            return Ok(StartSelection::All);
        }
        if let Some(range) = self.starts.strip_prefix("strip:") {
            let (lo, hi) = range
                .split_once(':')
                .and_then(|(a, b)| {
                    Some((a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?))
                })
                .with_context(|| {
                    format!("--starts {:?}: expected strip:Z0:Z1 in mm", self.starts)
                })?;
            return Ok(StartSelection::Strip { z: [lo, hi] });
        }
        if let Some(patches) = self.starts.strip_prefix("patches:") {
            let parts: Vec<Option<usize>> =
                patches.split(':').map(|p| p.trim().parse().ok()).collect();
            let &[Some(count), Some(length), Some(rows)] = &parts[..] else {
                anyhow::bail!(
                    "--starts {:?}: expected patches:N:L:R (N patches of R rows of L starts)",
                    self.starts
                );
            };
            return Ok(StartSelection::Patches {
                count,
                length,
                rows,
                seed: self.seed,
            });
        }
        if let Some(runs) = self.starts.strip_prefix("runs:") {
            let (count, length) = runs
                .split_once(':')
                .and_then(|(n, l)| Some((n.trim().parse().ok()?, l.trim().parse().ok()?)))
                .with_context(|| {
                    format!(
                        "--starts {:?}: expected runs:N:L (N runs of L starts)",
                        self.starts
                    )
                })?;
            return Ok(StartSelection::Runs {
                count,
                length,
                seed: self.seed,
            });
        }
        let count: usize = self.starts.parse().with_context(|| {
            format!(
                "--starts {:?}: expected runs:N:L, strip:Z0:Z1, a number of starts or `all` (or patches:N:L:R)",
                self.starts
            )
        })?;
        Ok(StartSelection::Sample {
            count,
            seed: self.seed,
        })
    }
}

/// What `verify` and `converge` compare: a part, a setup, starts.
#[derive(Debug, Args)]
pub struct StudyArgs {
    /// The part: an STL file (binary or ASCII), or a scenario file
    /// (`scenarios/*.toml`, tessellated on the fly). One file: an
    /// assembly is analysed with `analyze`.
    #[arg(value_name = "PART")]
    pub path: PathBuf,
    #[command(flatten)]
    pub part: PartArgs,
    #[command(flatten)]
    pub setup: SetupArgs,
    #[command(flatten)]
    pub starts: StartArgs,
    /// Compare one shard of the starts and write it as a partial result
    /// (shard.json, shard.bin) for `kneeform merge`: shard K of N takes
    /// the study's starts s (0-based, in the order the study compares them,
    /// after --starts sampling) with s % N == K - 1, and runs the exact
    /// oracle on those alone. 1 <= K <= N <= the number of starts. A
    /// shard exits 0 once written: pass or fail is the merge's. With
    /// --approach direct, the study's positions alike. Default: every
    /// start.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Replace an existing --out directory of an earlier result (as
    /// analyze --force: its kneeform-run.json lists every file in it,
    /// unchanged, and it holds no input of this study; or empty) with this
    /// study's results, whole. Without it an existing --out is refused,
    /// before any work.
    #[arg(long)]
    pub force: bool,
}

/// `kneeform verify`.
#[derive(Debug, Args)]
pub struct VerifyArgs {
    #[command(flatten)]
    pub study: StudyArgs,
    /// Largest decided area miss distance allowed (mm): how far a decided
    /// exact strike away from blind spots may lie from the grid's colliding
    /// area, at the worst angle (the other metrics are shown against it as
    /// diagnostics). Default: sqrt 2 pitches (1.753624 mm at the default
    /// 1.24 mm), the grid's own sampling error: a nearest node lies up to
    /// that far from a point of the part, so a correct grid cannot do
    /// better, and a fixed 1 mm below the pitch would fail every correct
    /// run. Give your own (say 1) to ask whether this pitch is fine enough
    /// for it; a failing figure then names the pitch that would be.
    #[arg(long, value_name = "MM")]
    pub tolerance: Option<f64>,
    /// The longest the exact oracle may take (seconds). One start in
    /// twenty is traced first, at every angle; its time predicts the rest
    /// (always printed), and a prediction beyond this is refused (exit 2)
    /// naming the --shard count that would fit, before the rest is traced.
    /// Default: no limit.
    #[arg(long, value_name = "S")]
    pub budget_s: Option<f64>,
    /// Output directory for verify.csv and verify.json (created; it
    /// appears whole or not at all). An existing one is refused unless
    /// --force is given.
    #[arg(long, default_value = "kneeform-verify", value_name = "DIR")]
    pub out: PathBuf,
}

/// `kneeform converge`.
#[derive(Debug, Args)]
pub struct ConvergeArgs {
    #[command(flatten)]
    pub study: StudyArgs,
    /// Pitches to compare (mm), each dividing the coarsest so that grids
    /// nest, e.g. 8,4,2,1,0.5. Overrides --pitch.
    #[arg(long, default_value = "8,4,2,1", value_name = "MM,MM,...")]
    pub pitches: String,
    /// Name the coarsest pitch whose outcome, as verify's, is PASS at this
    /// tolerance (mm): its decided area miss distance within it, on enough
    /// evidence.
    #[arg(long, value_name = "MM")]
    pub tolerance: Option<f64>,
    /// The longest the exact oracle may take (seconds), as verify's: one
    /// start in twenty is traced first, at every angle; its time predicts
    /// the rest (always printed), and a prediction beyond this is refused
    /// (exit 2) naming the --shard count that would fit. Default: no limit.
    #[arg(long, value_name = "S")]
    pub budget_s: Option<f64>,
    /// Output directory for converge.csv, converge.json and the plots
    /// (created; it appears whole or not at all). An existing one is
    /// refused unless --force is given.
    #[arg(long, default_value = "kneeform-converge", value_name = "DIR")]
    pub out: PathBuf,
}

/// `kneeform scenario`.
#[derive(Debug, Args)]
pub struct ScenarioArgs {
    /// The synthetic part: a scenario file (`.toml`, e.g.
    /// scenarios/thin-rib.toml) or the name of one of scenarios/, built
    /// into the binary (its stem: wave, thin-rib, console, ...; an unknown
    /// name lists them all).
    #[arg(value_name = "NAME|FILE.toml")]
    pub part: String,
    /// Where to write the STL.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Tessellate into at least N triangles, refining the part's step
    /// uniformly (e.g. 369408, the paper's console); default: the part's
    /// own step.
    #[arg(long, value_name = "N")]
    pub triangles: Option<usize>,
}

/// `kneeform bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// The angles of the fast engine's timing (the paper's workload is all
    /// 61).
    #[command(flatten)]
    pub angles: AnglesArg,
    /// Timed runs of the fast engine; the median is reported.
    #[arg(long, default_value_t = 5, value_name = "N")]
    pub runs: usize,
    /// Start rows sampled for the paper-algorithm baseline.
    #[arg(long, default_value_t = 6, value_name = "N")]
    pub paper_rows: usize,
    /// Angles sampled for the paper-algorithm baseline.
    #[arg(long, default_value_t = 3, value_name = "N")]
    pub paper_angles: usize,
    /// Starts traced by the exact oracle (angle 0), for its cost per start
    /// against the engine's in the same run.
    #[arg(long, default_value_t = 8, value_name = "N")]
    pub oracle_starts: usize,
    /// Worker threads (default: one per CPU).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Which level the timed engine follows (SPEC v4), as `analyze
    /// --level`: `node` (default) or `surface`. Under `surface` the
    /// comparison in the same runs is the node level (instead of `--rate
    /// x-slope`); the paper-algorithm baseline stays at the node level.
    #[arg(
        long,
        default_value = "node",
        value_name = "LEVEL",
        value_parser = one_of(&Level::ALL, Level::name)
    )]
    pub level: Level,
    /// Also write the figures as Markdown to this file.
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
}

impl SetupArgs {
    /// Parses the flags into the library's [`Setup`] and checks it, naming
    /// the flag at fault; also returns `--threads`.
    pub fn validate(&self) -> anyhow::Result<(Setup, Option<usize>)> {
        if let Some(n) = self.threads {
            check_threads(n)?;
        }
        let grid = match (&self.grid_origin, &self.grid_size) {
            (Some(origin), Some(size)) => GridPlacement::Explicit {
                origin: pair::<f64>(origin)
                    .with_context(|| format!("--grid-origin {origin:?}: expected X,Z in mm"))?,
                size: pair::<usize>(size)
                    .with_context(|| format!("--grid-size {size:?}: expected NX,NZ node counts"))?,
            },
            _ => GridPlacement::AroundPart,
        };
        // The rule keeps tan(--deflection): a value beyond 90 degrees
        // would come back as another angle (1e9 was reported as -80).
        if !(self.deflection.is_finite() && (0.0..45.0).contains(&self.deflection)) {
            return Err(with_flag(SetupError::Deflection(self.deflection)));
        }
        let setup = Setup {
            // `auto`: a placeholder until the pitch study chooses.
            pitch: match self.pitch {
                PitchArg::Mm(p) => p,
                PitchArg::Auto => Setup::default().pitch,
            },
            knee: KneeForm {
                triangle_side: self.triangle_side,
                radius: self.radius,
                thickness: self.thickness,
            },
            angles: parse_angles(&self.angles.angles)?,
            rule: StrikeRule::new(self.deflection, self.e0)
                .with_rate(self.rate)
                .with_window(self.window)
                .with_level(self.level),
            grid,
            algorithm: self.algorithm,
            max_memory_bytes: self.max_memory * f64::from(1u32 << 30),
            blind_depth: self.blind_depth,
            approach: self.approach,
        };
        setup.validate().map_err(with_flag)?;
        Ok((setup, self.threads))
    }
}

/// The parser of a flag taking one of a library enum's values by name
/// (`name` of each of `all`): the library's types carry no clap derive,
/// and the flag's own help says what each value does.
fn one_of<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
) -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(all.iter().map(|&v| name(v))).map(move |s| {
        *all.iter()
            .find(|&&v| name(v) == s)
            .expect("the parser admits only the names of `all`")
    })
}

/// A setup error with the flag it concerns in front: `--pitch: ...`.
pub fn with_flag(err: SetupError) -> anyhow::Error {
    let flag = format!("--{}", err.field().replace('_', "-"));
    anyhow::Error::new(err).context(flag)
}

impl PartArgs {
    /// The matrix file `--frame @FILE` names, if any: an input of the run.
    pub fn frame_file(&self) -> Option<&std::path::Path> {
        self.frame
            .as_deref()
            .and_then(|f| f.strip_prefix('@'))
            .map(std::path::Path::new)
    }

    /// Validates the flags into where the part's files are read from:
    /// `files`, less `ignored`, scaled, framed and sided.
    pub fn validate(&self, files: &[PathBuf], ignored: &[PathBuf]) -> anyhow::Result<PartSource> {
        // The run's files name each part by its path: one that is not
        // UTF-8 would be stored altered, and `report` could not find it.
        if let Some(path) = files.iter().chain(ignored).find(|p| p.to_str().is_none()) {
            anyhow::bail!(
                "the part path {} is not valid UTF-8, and the run's files could not name it: rename it or link it under a UTF-8 name",
                path.display()
            );
        }
        kneeform::input::check_scale(self.scale).context("--scale")?;
        let frame = match &self.frame {
            None => Frame::none(),
            Some(value) => Frame::parse(value).context("--frame")?,
        };
        Ok(PartSource {
            files: files.to_vec(),
            ignored: ignored.to_vec(),
            scale: self.scale,
            placement: Placement {
                side: self.side,
                frame,
                approach: Approach::Slide,
            },
        })
    }
}

/// `--threads`: at least 1, at most [`kneeform::limits::MAX_THREADS`].
pub fn check_threads(n: usize) -> anyhow::Result<()> {
    ensure!(
        (1..=kneeform::limits::MAX_THREADS).contains(&n),
        "--threads must be between 1 and {}, got {n}",
        kneeform::limits::MAX_THREADS
    );
    Ok(())
}

fn pair<T: std::str::FromStr>(s: &str) -> anyhow::Result<[T; 2]>
where
    T::Err: std::error::Error + Send + Sync + 'static,
{
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    ensure!(parts.len() == 2, "expected two comma-separated values");
    Ok([parts[0].parse()?, parts[1].parse()?])
}

/// Parses `FROM:TO:STEP` (inclusive) or a comma-separated list of angles.
pub fn parse_angles(s: &str) -> anyhow::Result<Vec<f64>> {
    let number = |t: &str| -> anyhow::Result<f64> {
        t.trim()
            .parse()
            .with_context(|| format!("--angles: {t:?} is not a number"))
    };
    let angles = if s.contains(':') {
        let parts: Vec<&str> = s.split(':').collect();
        ensure!(parts.len() == 3, "--angles {s:?}: expected FROM:TO:STEP");
        let (from, to, step) = (number(parts[0])?, number(parts[1])?, number(parts[2])?);
        ensure!(
            from.is_finite() && to.is_finite() && step.is_finite(),
            "--angles {s:?}: FROM, TO and STEP must be finite"
        );
        ensure!(step > 0.0, "--angles {s:?}: STEP must be > 0");
        ensure!(to >= from, "--angles {s:?}: TO must be >= FROM");
        // Counted before any angle is made: `-90:90:1e-9` is refused, not
        // allocated.
        let count = ((to - from) / step + 1e-9).floor() + 1.0;
        ensure!(
            count <= kneeform::limits::MAX_ANGLES as f64,
            "--angles {s:?}: {} angles, more than the {} a run takes (use a larger STEP)",
            kneeform::limits::short(count),
            kneeform::limits::MAX_ANGLES
        );
        let n = count as usize;
        // Rounded to 1e-9 degree so that 0.1-degree steps print cleanly.
        (0..n)
            .map(|k| ((from + k as f64 * step) * 1e9).round() / 1e9)
            .collect()
    } else {
        let count = s.split(',').count();
        ensure!(
            count <= kneeform::limits::MAX_ANGLES,
            "--angles: {count} angles, more than the {} a run takes",
            kneeform::limits::MAX_ANGLES
        );
        s.split(',')
            .map(number)
            .collect::<anyhow::Result<Vec<f64>>>()?
    };
    Ok(angles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_ranges_and_lists() {
        assert_eq!(parse_angles("-30:30:1").unwrap().len(), 61);
        assert_eq!(
            parse_angles("-30,-13,0,7,30").unwrap(),
            vec![-30.0, -13.0, 0.0, 7.0, 30.0]
        );
        assert_eq!(parse_angles("0:1:0.1").unwrap()[3], 0.3);
        assert!(parse_angles("0:1").is_err());
        assert!(parse_angles("a").is_err());
        assert!(parse_angles("0:10:0").is_err());
    }

    #[test]
    fn negative_angle_lists_parse_as_values() {
        let cli =
            Cli::try_parse_from(["kneeform", "analyze", "p.stl", "--angles", "-30,-13"]).unwrap();
        let Command::Analyze(a) = cli.command else {
            panic!("not analyze")
        };
        assert_eq!(a.setup.validate().unwrap().0.angles, vec![-30.0, -13.0]);
        let repeated =
            Cli::try_parse_from(["kneeform", "analyze", "p.stl", "--angles", "1,1"]).unwrap();
        let Command::Analyze(a) = repeated.command else {
            panic!("not analyze")
        };
        let err = format!("{:#}", a.setup.validate().unwrap_err());
        assert!(err.starts_with("--angles: "), "{err}");
    }
}
