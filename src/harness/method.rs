//! What a study does its own way for each approach ([`Method`]), in a
//! leaf that the approaches' modules (`converge`, `direct`) implement and
//! the one study path (`study`) calls, so that neither imports the other.

use super::error::HarnessError;
use super::pairs::PitchPart;
use crate::analysis::Progress;
use crate::grid::GridSpec;
use crate::mesh::Triangle;
use crate::setup::{Sampled, Setup};

/// What [`Method::trace`] traces, and within what time.
#[derive(Debug, Clone, Default)]
pub(crate) struct Tracing {
    /// The starts (some of [`Method::all_starts`], in their order).
    pub share: Vec<[f64; 2]>,
    /// The finest pitch the traces must resolve (mm).
    pub finest: f64,
    /// Refuse, before the traces, an oracle predicted (from a sample) to
    /// take longer (s): `--budget-s`.
    pub refuse_beyond_s: Option<f64>,
    /// Give up as soon as this many seconds are spent (a pitch study's
    /// budget, `--pitch auto`).
    pub within_s: Option<f64>,
    /// Refuse, before the traces, a study predicted (from the sample) to
    /// hold more than this many bytes of traces and comparisons, over its
    /// pitches (`--max-memory`); none when `None`.
    pub memory: Option<MemoryLimit>,
}

/// The memory a study's traces and comparisons may take.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MemoryLimit {
    /// Bytes allowed (`--max-memory`; the machine's memory is checked
    /// too).
    pub bytes: f64,
    /// Pitches whose comparisons the study holds at once.
    pub pitches: usize,
    /// What the study holds besides its traces and comparisons, whatever
    /// the share of starts (bytes): the program, the part and the
    /// oracle's copy of it, each pitch's grid and the refinement's finer
    /// bands ([`super::approach::StudyApproach::refinement_bytes`]).
    pub held_bytes: f64,
}

/// One pitch of a study, as [`Method::pitch`] compares it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pitch {
    /// The pitch (mm, dividing the coarsest).
    pub p: f64,
    /// Whether it is one of a convergence study's pitches: a stage named
    /// by its pitch, with the engine's full run timed. A verification's
    /// one pitch is the stage comparing the grid with the exact side.
    pub converging: bool,
}

impl Pitch {
    /// The progress stage of this pitch on the grid `spec`, comparing
    /// `pairs` start-angle pairs; `approach` follows a convergence
    /// study's stage name (` (direct)`, or nothing).
    pub fn stage(self, spec: &GridSpec, pairs: usize, approach: &str) -> String {
        if self.converging {
            format!(
                "pitch {} mm: {} x {} grid{approach}",
                self.p, spec.nx, spec.nz
            )
        } else {
            super::stage::comparing(pairs)
        }
    }
}

/// `triangles` sampled at `spec` as `setup` samples them
/// ([`Setup::sample_on`]): `kept` (the coarsest grid, sampled when the
/// study was laid) when it is that grid, else sampled. `kept` is taken
/// either way: the coarsest pitch is measured first.
pub(super) fn sampled_at(
    kept: &mut Option<Sampled>,
    setup: &Setup,
    triangles: &[Triangle],
    spec: GridSpec,
) -> Sampled {
    match kept.take() {
        Some(sampled) if sampled.grid.spec == spec => sampled,
        _ => setup.sample_on(spec, triangles, None),
    }
}

/// The coarsest grid of a study and its starts, as a [`Method`] lays them.
#[derive(Debug, Clone)]
pub(crate) struct Laid {
    /// The coarsest grid (the study's starts are its nodes).
    pub coarse: GridSpec,
    /// Every start of the study (mm), in its order.
    pub starts: Vec<[f64; 2]>,
    /// Seconds sampling the coarsest grid (the slide's summaries report
    /// them; 0 where none does).
    pub sample_s: f64,
}

/// What a study does its own way for one approach: its grids, its exact
/// side and its pairs. The study's steps, in order: the coarsest grid
/// and the starts laid ([`Method::laid`]), [`Method::trace`] on a share
/// of them, then [`Method::pitch`] at each pitch, coarsest first.
pub(crate) trait Method {
    /// The coarsest grid and the study's starts on it, as laid.
    fn laid(&self) -> &Laid;
    /// Takes the exact side of `what.share` at the study's angles,
    /// resolving pitches down to `what.finest`; the oracle's seconds.
    fn trace(&mut self, what: Tracing, progress: &dyn Progress) -> Result<f64, HarnessError>;
    /// The share's pairs at `at.p`.
    fn pitch(&mut self, at: Pitch, progress: &dyn Progress) -> Result<PitchPart, HarnessError>;
}

/// The grid at pitch `p` over exactly the extent of `coarse`, from its
/// origin (`p` divides its pitch).
pub(super) fn spec_at(coarse: &GridSpec, p: f64) -> GridSpec {
    let c = coarse;
    let r = (c.pitch / p).round() as usize;
    GridSpec::explicit(c.x(0), c.z(0), (c.nx - 1) * r + 1, (c.nz - 1) * r + 1, p)
}
