//! What an analysis computes ([`Setup`]: the knee-form, the grid, the
//! angles, the strike rule, the approach), checked before any work
//! ([`Setup::validate`]), and what it costs: the grid it lays on a part and
//! the memory that grid needs, checked against the memory allowed before
//! anything is allocated. Then the one sampling stage every pipeline runs
//! (the analysis, the studies' grids at every pitch, the benchmark; the
//! verification's half- and quarter-pitch bands of one start aside):
//! [`Setup::lay`] and [`Setup::sample_on`] give the height grid and the
//! slide's footprints, [`Sampled`].

use crate::engine::Algorithm;
use crate::frame::Approach;
use crate::grid::{GridError, GridSpec, HeightGrid};
use crate::kneeform::{Footprint, GridFootprint, KneeForm};
use crate::limits::{self, short};
use crate::memory::MemoryEstimate;
use crate::mesh::{Bbox, Part, Triangle};
use crate::strike::{Level, RateEstimate, StrikeRule};

/// Where the grid lies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GridPlacement {
    /// SPEC's default extent: every node whose footprint, at any angle or
    /// its mirror, can reach the part's xz bounding box.
    AroundPart,
    /// An explicit origin (mm, snapped to multiples of the pitch) and
    /// size (nodes).
    Explicit {
        /// Origin x, z (mm).
        origin: [f64; 2],
        /// Nodes along x, z.
        size: [usize; 2],
    },
}

/// What an analysis computes: the knee-form, the grid, the angles and the
/// strike rule. Lengths in mm, angles in degrees. [`Setup::validate`]
/// checks it; [`crate::Analysis::run`] does so before any work.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// Grid pitch (mm).
    pub pitch: f64,
    /// The knee-form.
    pub knee: KneeForm,
    /// Knee-form angles (degrees, positive raises its back), distinct.
    pub angles: Vec<f64>,
    /// SPEC's strike rule.
    pub rule: StrikeRule,
    /// Where the grid lies.
    pub grid: GridPlacement,
    /// Which implementation of push and slide runs (both give the same
    /// masks).
    pub algorithm: Algorithm,
    /// The largest estimated working memory allowed (bytes).
    pub max_memory_bytes: f64,
    /// How far the part must stick out between nodes (mm) for a grid cell
    /// to be a blind spot ([`crate::blind`]).
    pub blind_depth: f64,
    /// Push-and-slide (the default) or the direct approach.
    pub approach: Approach,
}

impl Default for Setup {
    /// The paper's setup: 1.24 mm pitch, the default knee-form, every
    /// whole degree from -30 to 30, SPEC's default strike rule, the default
    /// extent, the fast engine, 16 GiB.
    fn default() -> Self {
        Setup {
            pitch: 1.24,
            knee: KneeForm::default(),
            angles: (-30..=30).map(f64::from).collect(),
            rule: StrikeRule::default(),
            grid: GridPlacement::AroundPart,
            algorithm: Algorithm::Fast,
            max_memory_bytes: 16.0 * GIB,
            blind_depth: Setup::DEFAULT_BLIND_DEPTH,
            approach: Approach::Slide,
        }
    }
}

/// A setup that cannot be run. Each names the field at fault
/// ([`SetupError::field`]), so that a front end can name its own flag.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetupError {
    /// A length or limit that must be a finite positive number is not.
    #[error("the {field} must be a finite number > 0, got {}", short(*value))]
    NotPositive {
        /// The field (`max_memory`).
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// A number is outside the bounds of [`crate::limits`].
    #[error("the {field} must be a number from {} to {}, got {}", short(*min), short(*max), short(*value))]
    OutOfRange {
        /// The field (`pitch`, `triangle_side`, `radius`, `thickness`,
        /// `blind_depth`, `scale`, `window`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// The smallest allowed.
        min: f64,
        /// The largest allowed.
        max: f64,
    },
    /// More angles than [`crate::limits::MAX_ANGLES`].
    #[error("{0} angles given, at most {max} are analysed in one run", max = crate::limits::MAX_ANGLES)]
    TooManyAngles(usize),
    /// The angle list is empty.
    #[error("no angle given")]
    NoAngles,
    /// An angle is not finite or beyond +-90 degrees.
    #[error("angle {} is outside -90..90 degrees", short(*.0))]
    AngleOutOfRange(f64),
    /// An angle is given twice.
    #[error("angle {} is given twice", short(*.0))]
    RepeatedAngle(f64),
    /// The deflection threshold is outside [0, 45) degrees.
    #[error("the deflection threshold must be a number of degrees in [0, 45), got {}", short(*.0))]
    Deflection(f64),
    /// The rounding tolerance is outside [0, 0.01] mm.
    #[error("e0 must be a number of mm in [0, 0.01] (it only absorbs rounding), got {}", short(*.0))]
    E0(f64),
    /// The explicit grid's origin is not finite, or beyond
    /// `MAX_COORD_MM`.
    #[error("the grid origin must be two numbers of mm within +-{}, got {},{}", short(crate::limits::MAX_COORD_MM), short(.0[0]), short(.0[1]))]
    GridOrigin([f64; 2]),
    /// The explicit grid has no node, or more than
    /// `MAX_GRID_NODES`.
    #[error("the grid size must be from 1,1 to {} nodes in all, got {},{}", crate::limits::MAX_GRID_NODES, .0[0], .0[1])]
    GridSize([usize; 2]),
    /// The surface level asked with what it has no form for: the x-slope
    /// rate, the paper-literal algorithm or the direct approach (the
    /// reason, in words).
    #[error("the surface level {0}")]
    Level(&'static str),
}

impl SetupError {
    /// The [`Setup`] field at fault, snake_case (`pitch`, `angles`,
    /// `deflection`, `e0`, `grid_origin`, ...).
    pub fn field(&self) -> &'static str {
        match self {
            SetupError::NotPositive { field, .. } | SetupError::OutOfRange { field, .. } => field,
            SetupError::NoAngles
            | SetupError::TooManyAngles(_)
            | SetupError::AngleOutOfRange(_)
            | SetupError::RepeatedAngle(_) => "angles",
            SetupError::Deflection(_) => "deflection",
            SetupError::E0(_) => "e0",
            SetupError::GridOrigin(_) => "grid_origin",
            SetupError::GridSize(_) => "grid_size",
            SetupError::Level(_) => "level",
        }
    }
}

impl Setup {
    /// The default depth of a blind spot (mm): well above the sag of a
    /// smooth part between nodes (0.06 mm for the 8 mm waves at a 4 mm
    /// pitch), half the 1 mm tolerance the evidence is held to.
    pub const DEFAULT_BLIND_DEPTH: f64 = 0.5;

    /// Checks every field, before any work.
    pub fn validate(&self) -> Result<(), SetupError> {
        let within = |field: &'static str, value: f64, min: f64, max: f64| {
            if value.is_finite() && (min..=max).contains(&value) {
                Ok(())
            } else {
                Err(SetupError::OutOfRange {
                    field,
                    value,
                    min,
                    max,
                })
            }
        };
        within(
            "pitch",
            self.pitch,
            limits::MIN_PITCH_MM,
            limits::MAX_PITCH_MM,
        )?;
        let length =
            |field, value| within(field, value, limits::MIN_PITCH_MM, limits::MAX_LENGTH_MM);
        length("triangle_side", self.knee.triangle_side)?;
        length("radius", self.knee.radius)?;
        length("thickness", self.knee.thickness)?;
        length("blind_depth", self.blind_depth)?;
        if !(self.max_memory_bytes.is_finite() && self.max_memory_bytes > 0.0) {
            return Err(SetupError::NotPositive {
                field: "max_memory",
                value: self.max_memory_bytes,
            });
        }
        if self.angles.is_empty() {
            return Err(SetupError::NoAngles);
        }
        if self.angles.len() > limits::MAX_ANGLES {
            return Err(SetupError::TooManyAngles(self.angles.len()));
        }
        if let Some(&a) = self
            .angles
            .iter()
            .find(|a| !(a.is_finite() && a.abs() <= 90.0))
        {
            return Err(SetupError::AngleOutOfRange(a));
        }
        let mut sorted = self.angles.clone();
        sorted.sort_by(f64::total_cmp);
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(SetupError::RepeatedAngle(w[0]));
        }
        let deflection = self.rule.deflection_deg();
        if !(deflection.is_finite() && (0.0..45.0).contains(&deflection)) {
            return Err(SetupError::Deflection(deflection));
        }
        if !(self.rule.e0.is_finite() && (0.0..=0.01).contains(&self.rule.e0)) {
            return Err(SetupError::E0(self.rule.e0));
        }
        if self.rule.window_mm().is_some() {
            let longest = limits::MAX_WINDOW_MM.min(limits::MAX_WINDOW_PITCHES * self.pitch);
            within("window", self.rule.window, limits::MIN_PITCH_MM, longest)?;
        }
        if self.rule.level == Level::Surface {
            if self.rule.rate != RateEstimate::Window {
                return Err(SetupError::Level(
                    "takes --rate window only (the x-slope rule reads the node behind a node)",
                ));
            }
            if self.algorithm != Algorithm::Fast {
                return Err(SetupError::Level(
                    "has no paper-literal form: use --algorithm fast",
                ));
            }
            if self.approach != Approach::Slide {
                return Err(SetupError::Level(
                    "applies to --approach slide only (the direct approach's erosion is per node)",
                ));
            }
        }
        if let GridPlacement::Explicit { origin, size } = self.grid {
            if !origin
                .iter()
                .all(|c| c.is_finite() && c.abs() <= limits::MAX_COORD_MM)
            {
                return Err(SetupError::GridOrigin(origin));
            }
            let nodes = size[0].checked_mul(size[1]);
            if !nodes.is_some_and(|n| (1..=limits::MAX_GRID_NODES).contains(&n)) {
                return Err(SetupError::GridSize(size));
            }
        }
        Ok(())
    }

    /// The grid for `part` (analysis frame; the direct frame for
    /// [`Approach::Direct`]), at this setup's pitch: SPEC's
    /// default extent covers every requested angle and its mirror, so that
    /// a part mirrored in z gets the mirrored grid. Checked to have a
    /// bounded number of nodes and the analysis on it to fit the memory
    /// allowed ([`Setup::check_memory`]).
    pub fn grid_spec(&self, part: &Part) -> Result<GridSpec, GridError> {
        Ok(self.lay(part)?.0)
    }

    /// The grid of [`Setup::grid_spec`] and the working memory it was
    /// checked for: the first step of the sampling stage.
    pub fn lay(&self, part: &Part) -> Result<(GridSpec, MemoryEstimate), GridError> {
        let spec = self.grid_placed(&part.bbox())?;
        let memory = self.check_memory(&spec, part.triangles.len())?;
        Ok((spec, memory))
    }

    /// `triangles` sampled on `spec` (SPEC's z-buffer from -y; with an
    /// assembly's `file_of`, per triangle the index of its file, each
    /// node tagged with the file that set its height), and the slide's
    /// footprints laid on it: the second step of the sampling stage. The
    /// direct approach lays no footprints here (its fronts move along x:
    /// [`crate::direct::DirectFootprint`]).
    pub fn sample_on(
        &self,
        spec: GridSpec,
        triangles: &[Triangle],
        file_of: Option<&[u32]>,
    ) -> Sampled {
        let t = std::time::Instant::now();
        let (grid, node_file) = match file_of {
            None => (HeightGrid::sample(triangles, spec), None),
            Some(file_of) => {
                let (grid, files) = HeightGrid::sample_attributed(triangles, file_of, spec);
                (grid, Some(files))
            }
        };
        let footprints = match self.approach {
            Approach::Slide => self.footprints(&spec),
            Approach::Direct => Vec::new(),
        };
        Sampled {
            grid,
            node_file,
            footprints,
            sample_s: t.elapsed().as_secs_f64(),
        }
    }

    /// The grid alone, its node count checked, not its memory. For the
    /// direct approach `bbox` is the part's in the direct frame.
    pub(crate) fn grid_placed(&self, bbox: &Bbox) -> Result<GridSpec, GridError> {
        let spec = match self.grid {
            GridPlacement::AroundPart if self.approach == Approach::Direct => {
                crate::direct::grid_around(bbox, &self.knee, &self.angles, self.pitch)
            }
            GridPlacement::AroundPart => {
                let extents: Vec<Footprint> = self
                    .angles
                    .iter()
                    .flat_map(|&a| {
                        [
                            Footprint::new(&self.knee, a),
                            Footprint::new(&self.knee, -a),
                        ]
                    })
                    .collect();
                Footprint::grid_around(bbox, &extents, self.pitch)
            }
            GridPlacement::Explicit { origin, size } => {
                GridSpec::explicit(origin[0], origin[1], size[0], size[1], self.pitch)
            }
        };
        spec.check_nodes()?;
        Ok(spec)
    }

    /// The working memory of analysing a part of `triangles` triangles on
    /// `spec` with this setup, on the current thread pool.
    pub fn memory_estimate(&self, spec: &GridSpec, triangles: usize) -> MemoryEstimate {
        MemoryEstimate::analysis(
            spec,
            &self.footprints(spec),
            &self.rule,
            triangles,
            rayon::current_num_threads(),
        )
    }

    /// The estimate of [`Setup::memory_estimate`], checked against the
    /// memory allowed and the machine's physical memory before anything is
    /// allocated.
    pub fn check_memory(
        &self,
        spec: &GridSpec,
        triangles: usize,
    ) -> Result<MemoryEstimate, GridError> {
        spec.check_nodes()?;
        let estimate = self.memory_estimate(spec, triangles);
        check_estimate(&estimate, self.max_memory_bytes).map_err(|limit| {
            let (nx, nz, angles) = (spec.nx, spec.nz, self.angles.len());
            let need_gib = estimate.bytes() / GIB;
            match limit {
                Limit::Allowed(limit) => GridError::TooLarge {
                    nx,
                    nz,
                    angles,
                    need_gib,
                    limit_gib: limit / GIB,
                },
                Limit::Machine(machine, what) => GridError::BeyondMachine {
                    nx,
                    nz,
                    angles,
                    need_gib,
                    machine_gib: machine / GIB,
                    what,
                },
            }
        })?;
        Ok(estimate)
    }

    /// The knee-form's footprint at every angle, laid on `spec`.
    pub fn footprints(&self, spec: &GridSpec) -> Vec<GridFootprint> {
        self.angles
            .iter()
            .map(|&a| GridFootprint::new(&self.knee, a, spec))
            .collect()
    }
}

/// A part sampled as a setup lays it ([`Setup::sample_on`]).
#[derive(Debug, Clone)]
pub struct Sampled {
    /// The height grid (its nodes: `grid.spec`).
    pub grid: HeightGrid,
    /// For an assembly: per node, the index of the file whose surface set
    /// its height (the lowest on a tie); `None` for one file.
    pub node_file: Option<Vec<u32>>,
    /// The slide's footprints on the grid, in the order of the setup's
    /// angles; none for the direct approach.
    pub footprints: Vec<GridFootprint>,
    /// Seconds sampling the grid and laying the footprints.
    pub sample_s: f64,
}

pub(crate) const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Which limit an estimate broke (bytes).
pub(crate) enum Limit {
    Allowed(f64),
    /// The system's limit, and which one ([`crate::memory::limit_bytes`]).
    Machine(f64, &'static str),
}

/// Whether `estimate` fits `allowed` bytes and the machine's memory, and
/// the system gives that much now ([`crate::memory::unmappable`]).
pub(crate) fn check_estimate(estimate: &MemoryEstimate, allowed: f64) -> Result<(), Limit> {
    let need = estimate.bytes();
    if need > allowed {
        return Err(Limit::Allowed(allowed));
    }
    match crate::memory::limit_bytes() {
        Some((machine, what)) if need > machine => return Err(Limit::Machine(machine, what)),
        _ => {}
    }
    match crate::memory::unmappable(need) {
        Some(mappable) => Err(Limit::Machine(mappable, UNMAPPABLE)),
        None => Ok(()),
    }
}

/// The limit [`crate::memory::unmappable`] finds, in words.
const UNMAPPABLE: &str = "memory the system would give this process now";
