//! The analysis as one call: a part and a validated [`Setup`] in; the
//! grid, the colliding mask per angle, the composite, the warnings and the
//! summary out ([`Analysis`]).
//!
//! This is the pipeline every front end shares (the CLI's `analyze` and
//! `analyze --shard`, the tests, an embedding program; the harness's
//! studies lay their grids through the same [`Setup`]):
//! SPEC's default grid extent, the memory check before anything is
//! allocated, the grid laid and sampled, the footprints laid on that grid,
//! push and slide, the composite. Progress and warnings go through a
//! [`Progress`] callback; nothing here prints or writes files (the writers
//! are in [`crate::output`]).

use std::time::Instant;

use crate::assembly::{PartSource, colliding_nodes_per_file};
use crate::blind::{BlindSpot, blind_spots};
use crate::direct::{DirectFootprint, direct_masks};
use crate::engine::{AngleMask, EngineOptions, Probe, colliding_masks, composite};
use crate::frame::Approach;
use crate::grid::{GridError, HeightGrid};
use crate::input::{MeshError, PartFile};
use crate::kneeform::{GridFootprint, KneeForm};
use crate::memory::MemoryEstimate;
use crate::partition::Shard;
use crate::sanity::{self, Warning};
use crate::setup::{GIB, Limit, Sampled, Setup, SetupError, check_estimate};
use crate::summary::{AngleSummary, FileSummary, Summary, Timings};

/// Estimates above this (bytes) are said before the run: 256 MiB.
const NOTE_MEMORY_BYTES: f64 = 256.0 * 1024.0 * 1024.0;

/// Why an analysis could not run.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// The setup is invalid.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The part could not be read.
    #[error(transparent)]
    Part(#[from] MeshError),
    /// Reading the part would take more memory than allowed.
    #[error(
        "reading {path} needs about {need_gib:.2} GiB, more than the {limit_gib:.2} GiB of {what}"
    )]
    ReadTooLarge {
        /// The part file.
        path: String,
        /// The estimate.
        need_gib: f64,
        /// The limit.
        limit_gib: f64,
        /// Which limit, in words.
        what: &'static str,
    },
    /// The grid cannot be laid (empty, or too large for the memory limit).
    #[error(transparent)]
    Grid(#[from] GridError),
}

/// What a long computation reports while it runs. Every method has an
/// empty default, and `()` reports nothing.
pub trait Progress: Sync {
    /// A finding, said as soon as it is known (before the work it
    /// concerns).
    fn warn(&self, warning: &Warning) {
        let _ = warning;
    }
    /// A fact worth a line before long work (the memory a large run will
    /// take).
    fn note(&self, line: &str) {
        let _ = line;
    }
    /// A stage begins: `what` in words, `total` steps when known.
    fn begin(&self, what: &str, total: Option<u64>) {
        let _ = (what, total);
    }
    /// One step of the current stage is done.
    fn step(&self) {}
    /// The current stage is done.
    fn end(&self) {}
}

impl Progress for () {}

/// The outcome of an analysis, in one word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Some node is struck at some angle.
    Struck,
    /// Nothing is struck at any angle: a part in the wrong units or facing
    /// the wrong way, more often than a part with no knee contact (see the
    /// warnings).
    NothingStruck,
}

/// One analysed part: the grid it was sampled on, the colliding mask per
/// angle, their composite and what was found on the way.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The part and its file's identity. For the direct approach its
    /// triangles are in the direct frame, as its grid ([`Analysis::placement`]
    /// maps both back).
    pub input: PartFile,
    /// The setup it ran with.
    pub setup: Setup,
    /// The height grid.
    pub grid: HeightGrid,
    /// The footprints, laid on `grid`, in the order of `setup.angles`;
    /// empty for the direct approach ([`crate::direct::DirectFootprint`]).
    pub footprints: Vec<GridFootprint>,
    /// For an assembly ([`crate::assembly`]): per grid node, the index
    /// (into the assembly's files) of the file whose surface set its
    /// height, the lowest index on a tie; `None` for one file.
    pub node_file: Option<Vec<u32>>,
    /// The share of `setup.angles` whose push and slide this analysis
    /// computed: [`Shard::WHOLE`], or one shard's ([`crate::shard`]).
    pub angles: Shard,
    /// The colliding mask per angle, in the order of `setup.angles`
    /// (empty at the angles outside `angles`).
    pub masks: Vec<AngleMask>,
    /// Per node, the number of angles at which it collides.
    pub composite: Vec<u16>,
    /// The grid cells the grid cannot see into ([`crate::blind`]), with
    /// the angles at which the knee-form would meet them.
    pub blind_spots: Vec<BlindSpot>,
    /// The sanity checks' findings, in the order they were made.
    pub warnings: Vec<Warning>,
    /// The pitch study that chose `setup.pitch`, when one did (set by the
    /// caller: [`crate::harness::choose_pitch`]).
    pub pitch_choice: Option<crate::summary::PitchChoice>,
    /// The sample check against the exact oracle, when one was run or
    /// declined (set by the caller: [`crate::harness::check_analysis`]).
    pub sample_check: Option<crate::summary::SampleCheck>,
    /// The working memory estimated before the run.
    pub memory: MemoryEstimate,
    /// Seconds per stage (`write_s` and `total_s` are the writer's).
    pub timings: Timings,
}

/// Sizes up every file of `source` before any is read, and checks that
/// reading them fits `max_memory_bytes` and the system's limits
/// ([`MemoryEstimate::reading`]): a part too large is refused in a line
/// before it is read, not in an abort while it is. The files' bytes, where
/// known (regular files).
pub fn check_reading(
    source: &PartSource,
    max_memory_bytes: f64,
) -> Result<Option<u64>, AnalysisError> {
    // Every file is sized up before any is read.
    let (mut file_bytes, mut triangles, mut known) = (0u64, 0u64, true);
    for path in source.files.iter().chain(&source.ignored) {
        let size = crate::input::part_size(path)?;
        file_bytes = file_bytes.saturating_add(size.file_bytes);
        triangles = triangles.saturating_add(size.triangles);
        known &= size.known;
    }
    let reading = MemoryEstimate::reading(file_bytes, triangles);
    let shown = source
        .files
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    check_estimate(&reading, max_memory_bytes).map_err(|limit| {
        let (limit_gib, what) = match limit {
            Limit::Allowed(b) => (b / GIB, "--max-memory"),
            Limit::Machine(b, what) => (b / GIB, what),
        };
        AnalysisError::ReadTooLarge {
            path: shown.clone(),
            need_gib: reading.bytes() / GIB,
            limit_gib,
            what,
        }
    })?;
    Ok(known.then_some(file_bytes))
}

impl Analysis {
    /// Reads the part at `path` ([`crate::read_part`]) and analyses it.
    pub fn of_file(
        path: &std::path::Path,
        scale: f64,
        side: crate::frame::Side,
        setup: &Setup,
        progress: &dyn Progress,
    ) -> Result<Analysis, AnalysisError> {
        Analysis::of_source(&PartSource::file(path, scale, side.into()), setup, progress)
    }

    /// Reads the part's file or files ([`PartSource::read`]: a frame, an
    /// assembly, files disregarded) and analyses it.
    pub fn of_source(
        source: &PartSource,
        setup: &Setup,
        progress: &dyn Progress,
    ) -> Result<Analysis, AnalysisError> {
        Analysis::of_source_at(source, setup, Shard::WHOLE, progress)
    }

    /// As [`Analysis::of_source`], with push and slide computed only at
    /// the share `angles` of `setup.angles` ([`Shard::indices`];
    /// [`Shard::WHOLE`]: all), a shard of the run ([`crate::shard`]). The
    /// other angles' masks are empty (no node, no placed start, no blind
    /// spot met); all else (the grid, the blind spots, the memory
    /// estimate, the warnings about the part and the angles) is the whole
    /// run's.
    pub fn of_source_at(
        source: &PartSource,
        setup: &Setup,
        angles: Shard,
        progress: &dyn Progress,
    ) -> Result<Analysis, AnalysisError> {
        setup.validate()?;
        crate::input::check_scale(source.scale)?;
        let angle_warnings = sanity::angle_warnings(&setup.angles);
        for w in &angle_warnings {
            progress.warn(w);
        }
        let known = check_reading(source, setup.max_memory_bytes)?;
        let t = Instant::now();
        let input = source.read()?;
        let read_s = t.elapsed().as_secs_f64();
        // What reading held, now that the triangles are counted.
        // (A stream's bytes, unknown before, as those of the binary STL of
        // the triangles read.)
        let n = input.part.file_triangles as u64;
        let read_bytes = if let Some(file_bytes) = known {
            file_bytes
        } else {
            crate::input::binary_stl_len(n)
        };
        let read = MemoryEstimate::reading(read_bytes, n);
        let mut analysis = Analysis::run_checked(input, setup, angles, progress, angle_warnings)?;
        analysis.timings.read_s = read_s;
        analysis.memory.cover_reading(read.bytes());
        Ok(analysis)
    }

    /// Analyses a part already read: the checks of the part, the grid, push
    /// and slide at every angle, the composite.
    pub fn run(
        input: PartFile,
        setup: &Setup,
        progress: &dyn Progress,
    ) -> Result<Analysis, AnalysisError> {
        setup.validate()?;
        let angle_warnings = sanity::angle_warnings(&setup.angles);
        for w in &angle_warnings {
            progress.warn(w);
        }
        Analysis::run_checked(input, setup, Shard::WHOLE, progress, angle_warnings)
    }

    fn run_checked(
        mut input: PartFile,
        setup: &Setup,
        angles: Shard,
        progress: &dyn Progress,
        mut warnings: Vec<Warning>,
    ) -> Result<Analysis, AnalysisError> {
        let mut part_warnings = sanity::part_warnings(&input.part, input.side, &setup.knee);
        // The slide pushes the knee along y; the direct approach meets the
        // part along x, where its own frame is checked.
        if setup.approach == Approach::Slide {
            part_warnings.extend(sanity::facing_axis_warning(
                &input.part,
                !input.frame.is_none(),
            ));
        }
        for w in &part_warnings {
            progress.warn(w);
        }
        warnings.extend(part_warnings);

        // The direct approach samples the part turned into the direct
        // frame, where SPEC's z-buffer from -y is its depth grid along x.
        if setup.approach == Approach::Direct {
            for v in input.part.triangles.iter_mut().flatten() {
                *v = crate::frame::to_direct(*v);
            }
        }
        let t = Instant::now();
        let (spec, memory) = setup.lay(&input.part)?;
        if memory.bytes() > NOTE_MEMORY_BYTES {
            progress.note(&format!(
                "this run needs about {:.2} GiB of memory ({} x {} grid, {} angles; --max-memory {:.2} GiB)",
                memory.bytes() / GIB,
                spec.nx,
                spec.nz,
                setup.angles.len(),
                setup.max_memory_bytes / GIB
            ));
        }
        // An assembly's grid is the same heights, each node tagged with
        // the file that set it; the direct approach lays its own fronts.
        let file_of = input.assembly.as_ref().map(|a| &a.file_of[..]);
        let Sampled {
            grid,
            node_file,
            footprints,
            ..
        } = setup.sample_on(spec, &input.part.triangles, file_of);
        let sample_s = t.elapsed().as_secs_f64();

        let t = Instant::now();
        let mut blind = blind_spots(&input.part.triangles, &grid, setup.blind_depth);
        let blind_count = blind.len();
        let blind_s = t.elapsed().as_secs_f64();

        let t = Instant::now();
        let probes: Vec<Probe> = blind
            .iter()
            .map(|b| Probe {
                cell: (b.i, b.j),
                y: b.y,
            })
            .collect();
        // A shard computes its own angles; the others are empty.
        let chosen = angles.indices(setup.angles.len());
        let step = || progress.step();
        let found = match setup.approach {
            Approach::Slide => {
                progress.begin("push and slide", Some(chosen.len() as u64));
                let options = EngineOptions {
                    rule: setup.rule,
                    algorithm: setup.algorithm,
                    start_rows: None,
                    probes,
                };
                let mine: Vec<GridFootprint>;
                let footprints = if angles.is_whole() {
                    &footprints[..]
                } else {
                    mine = chosen.iter().map(|&a| footprints[a].clone()).collect();
                    &mine[..]
                };
                colliding_masks(&grid, footprints, &options, &step)
            }
            Approach::Direct => {
                progress.begin("direct approach", Some(chosen.len() as u64));
                let fronts: Vec<DirectFootprint> = chosen
                    .iter()
                    .map(|&a| DirectFootprint::new(&setup.knee, setup.angles[a], spec.pitch))
                    .collect();
                direct_masks(&grid, &fronts, setup.rule.e0, &probes, &step)
            }
        };
        let mut found = found.into_iter();
        let masks: Vec<AngleMask> = (setup.angles.iter().enumerate())
            .map(|(a, &angle_deg)| {
                if angles.has(a) {
                    found.next().expect("a mask per chosen angle")
                } else {
                    AngleMask {
                        angle_deg,
                        mask: vec![0; spec.len()],
                        placed: 0,
                        colliding: 0,
                        probes_met: vec![false; blind_count],
                    }
                }
            })
            .collect();
        progress.end();
        let push_slide_s = t.elapsed().as_secs_f64();

        for (b, met) in blind.iter_mut().zip(probes_met(&masks, blind_count)) {
            b.met_angles_deg = met;
        }

        let composite = composite(&masks);
        let struck = composite.iter().filter(|&&c| c > 0).count();
        let mut result_warnings = sanity::blind_spot_warnings(&blind, &placement(&input, setup));
        result_warnings.extend(sanity::result_warnings(struck));
        for w in &result_warnings {
            progress.warn(w);
        }
        warnings.extend(result_warnings);
        Ok(Analysis {
            input,
            setup: setup.clone(),
            grid,
            node_file,
            footprints,
            angles,
            masks,
            composite,
            blind_spots: blind,
            warnings,
            pitch_choice: None,
            sample_check: None,
            memory,
            timings: Timings {
                sample_s,
                push_slide_s,
                blind_s,
                ..Timings::default()
            },
        })
    }

    /// How the part file's coordinates map to this analysis's grid: the
    /// file's frame and side, then, for the direct approach, the turn into
    /// the direct frame ([`crate::direct`]). The writers map results back
    /// by it.
    pub fn placement(&self) -> crate::frame::Placement {
        placement(&self.input, &self.setup)
    }

    /// Nodes colliding at some angle.
    pub fn composite_nodes(&self) -> usize {
        self.composite.iter().filter(|&&c| c > 0).count()
    }

    /// The composite's struck zones ([`crate::zones`]), largest first: what
    /// `zones.csv` and `summary.json`'s `zones` hold.
    pub fn zones(&self) -> Vec<crate::zones::Zone> {
        crate::zones::zones(
            &self.grid,
            &self.composite,
            &self.masks,
            &self.blind_spots,
            &self.placement(),
        )
    }

    /// Whether anything is struck.
    pub fn status(&self) -> Status {
        if self.composite_nodes() > 0 {
            Status::Struck
        } else {
            Status::NothingStruck
        }
    }

    /// `summary.json`'s content: every parameter, the input's identity,
    /// the counts; the timings as measured so far.
    pub fn summary(&self) -> Summary {
        let spec = self.grid.spec;
        let area = spec.pitch * spec.pitch;
        let part = &self.input.part;
        let side = self.input.side;
        let (bbox_min, bbox_max) = self.part_bbox();
        let composite_nodes = self.composite_nodes();
        let setup = &self.setup;
        let (input_file, files) = match (&self.input.assembly, &self.node_file) {
            (Some(assembly), Some(node_file)) => {
                let nodes = colliding_nodes_per_file(assembly, node_file, &self.composite);
                let files: Vec<FileSummary> = assembly
                    .files
                    .iter()
                    .zip(nodes)
                    .map(|(f, nodes)| FileSummary {
                        path: f.path.display().to_string(),
                        sha256: f.sha256.clone(),
                        triangles: f.triangles,
                        degenerate_triangles: f.degenerate,
                        bodies: f.bodies,
                        ignored: f.ignored,
                        colliding_nodes: nodes,
                        colliding_area_mm2: nodes as f64 * area,
                    })
                    .collect();
                let names: Vec<&str> = files
                    .iter()
                    .filter(|f| !f.ignored)
                    .map(|f| f.path.as_str())
                    .collect();
                (names.join(" + "), files)
            }
            _ => (self.input.path.display().to_string(), Vec::new()),
        };
        Summary {
            kneeform_version: env!("CARGO_PKG_VERSION").into(),
            run_unix_time: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            input_file,
            sha256: self.input.sha256.clone(),
            files,
            triangles: part.file_triangles,
            degenerate_triangles: part.degenerate,
            bodies: part.bodies,
            bbox_min,
            bbox_max,
            scale: self.input.scale,
            side,
            frame: self.input.frame.record(),
            triangle_side_mm: setup.knee.triangle_side,
            triangle_side_assumed: setup.knee.triangle_side == KneeForm::default().triangle_side,
            radius_mm: setup.knee.radius,
            thickness_mm: setup.knee.thickness,
            pitch_mm: spec.pitch,
            grid_origin: [spec.x(0), spec.z(0)],
            grid_size: [spec.nx, spec.nz],
            sampled_nodes: self.grid.finite_count(),
            angles_deg: setup.angles.clone(),
            deflection_deg: setup.rule.deflection_deg(),
            sigma: setup.rule.sigma,
            e0_mm: setup.rule.e0,
            rate: setup.rule.rate.name().into(),
            level: setup.rule.level,
            window_mm: setup.rule.window_mm(),
            algorithm: setup.algorithm,
            approach: setup.approach,
            threads: rayon::current_num_threads(),
            per_angle: self
                .masks
                .iter()
                .map(|m| AngleSummary {
                    angle_deg: m.angle_deg,
                    placed_starts: m.placed,
                    colliding_nodes: m.colliding,
                    colliding_area_mm2: m.colliding as f64 * area,
                })
                .collect(),
            composite_nodes,
            composite_area_mm2: composite_nodes as f64 * area,
            blind_depth_mm: setup.blind_depth,
            pitch_study: self.pitch_choice.clone(),
            sample_check: self.sample_check.clone(),
            memory_estimate_mib: self.memory.mib(),
            peak_rss_mib: None,
            blind_spots: self.blind_spots.len(),
            blind_spots_met: self
                .blind_spots
                .iter()
                .filter(|s| !s.met_angles_deg.is_empty())
                .count(),
            timings: self.timings.clone(),
            warnings: self.warnings.iter().map(ToString::to_string).collect(),
            // Set by the writer from the results it writes, whole or
            // merged from shards (`output::write_results`).
            zones: Vec::new(),
        }
    }
}

impl Analysis {
    /// The part's bounding box in its own frame (mm), smallest and largest
    /// corner.
    fn part_bbox(&self) -> ([f64; 3], [f64; 3]) {
        let part = &self.input.part;
        if self.input.frame.is_none() && self.setup.approach == Approach::Slide {
            // A mirrored side only swaps the y bounds.
            let bbox = part.bbox();
            let side = self.input.side;
            let (y0, y1) = (side.to_part(bbox.min[1]), side.to_part(bbox.max[1]));
            return (
                [bbox.min[0], y0.min(y1), bbox.min[2]],
                [bbox.max[0], y0.max(y1), bbox.max[2]],
            );
        }
        // A rotation does not map boxes to boxes: map every vertex back.
        let placement = self.placement();
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &v in part.triangles.iter().flatten() {
            for (k, c) in placement.to_part(v).into_iter().enumerate() {
                lo[k] = lo[k].min(c);
                hi[k] = hi[k].max(c);
            }
        }
        (lo, hi)
    }
}

/// Per probe, the angles (degrees) at which it was met.
pub(crate) fn probes_met(masks: &[AngleMask], probes: usize) -> Vec<Vec<f64>> {
    (0..probes)
        .map(|k| {
            masks
                .iter()
                .filter(|m| m.probes_met.get(k) == Some(&true))
                .map(|m| m.angle_deg)
                .collect()
        })
        .collect()
}

/// How `input`'s coordinates map to the grid of an analysis by `setup`:
/// the file's frame and side, then the approach's turn.
fn placement(input: &PartFile, setup: &Setup) -> crate::frame::Placement {
    crate::frame::Placement {
        approach: setup.approach,
        ..input.placement()
    }
}
