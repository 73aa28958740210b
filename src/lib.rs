//! kneeform: the UN Regulation No. 21 knee-form push-and-slide inspection of
//! interior parts, on a sampled height grid (Inui, Gunji and Umezu).
//!
//! The pipeline, each step named as in SPEC.md and the paper:
//!
//! * [`input`]: STL in, a [`mesh`] of triangles in the analysis frame (mm,
//!   knee pushed in +y, sliding in -x); [`frame`]: parts in other
//!   coordinates (`--frame`); [`assembly`]: several files as one part;
//! * [`setup`]: what an analysis computes, checked before any work;
//! * [`grid`]: step 1, the height grid (an orthographic depth buffer);
//! * [`kneeform`]: the knee-form, its footprint per angle and row intervals;
//! * [`engine`]: step 2, push and slide at every angle and start (the fast
//!   path, and the paper-literal reference), the colliding masks and
//!   composite; its rooms are private, its surface [`colliding_masks`],
//!   [`composite`], [`push_levels`] and their options;
//! * [`direct`]: the direct approach (`--approach direct`), the knee-form
//!   moved straight in -x until it first touches the part;
//! * [`analysis`]: the pipeline above as one call, with its typed setup;
//! * [`sanity`]: the checks that warn of a part in the wrong units or
//!   facing the wrong way, and of a result with nothing struck.
//!
//! All lengths are mm and all angles degrees.
//!
//! The whole analysis is one call, [`Analysis::run`] (or
//! [`Analysis::of_file`]); [`harness::verify()`] and [`harness::converge()`]
//! check it against the exact oracle; [`output`] writes the results. The
//! `kneeform` binary (feature `cli`, on by default) only parses flags, shows
//! progress and calls these.
//!
//! # Example
//!
//! A bundled scenario analysed at a 4 mm pitch and three angles:
//!
//! ```
//! use kneeform::{Analysis, Setup, Side, Status};
//!
//! let setup = Setup { pitch: 4.0, angles: vec![-30.0, 0.0, 30.0], ..Setup::default() };
//! let wave = std::path::Path::new("scenarios/wave.toml");
//! let analysis = Analysis::of_file(wave, 1.0, Side::Left, &setup, &())?;
//! assert_eq!(analysis.status(), Status::Struck);
//! let summary = analysis.summary();
//! println!("composite: {} nodes, {:.0} mm^2", summary.composite_nodes, summary.composite_area_mm2);
//! # Ok::<(), kneeform::AnalysisError>(())
//! ```

pub mod analysis;
pub mod assembly;
pub mod blind;
pub mod direct;
pub mod engine;
pub mod frame;
pub mod grid;
#[cfg(feature = "harness")]
pub mod harness;
pub mod input;
pub mod kneeform;
pub mod limits;
pub mod manifest;
pub mod memory;
pub mod mesh;
pub mod output;
pub mod partition;
pub mod report;
pub mod sanity;
pub mod scenario;
pub mod setup;
pub mod shard;
pub mod strike;
pub mod summary;
mod surface;
mod zbuffer;
pub mod zones;

pub use analysis::{Analysis, AnalysisError, Progress, Status};
pub use assembly::PartSource;
pub use engine::{Algorithm, AngleMask, EngineOptions, colliding_masks, composite, push_levels};
pub use frame::{Approach, Frame, Placement, Side};
pub use grid::{GridSpec, HeightGrid};
pub use input::{PartFile, read_part};
pub use kneeform::{Footprint, GridFootprint, KneeForm};
pub use mesh::Part;
pub use setup::{GridPlacement, Setup, SetupError};
pub use strike::StrikeRule;
pub use summary::{Summary, SummaryError};
