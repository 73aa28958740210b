//! kneeform: the UN Regulation No. 21 knee-form push-and-slide inspection of
//! interior parts, on a sampled height grid (Inui, Gunji and Umezu).
//!
//! The pipeline, each step named as in SPEC.md and the paper:
//!
//! * [`mesh`]: STL in, triangles in the analysis frame (mm, knee pushed in
//!   +y, sliding in -x);
//! * [`grid`]: step 1, the height grid (an orthographic depth buffer);
//! * [`kneeform`]: the knee-form, its footprint per angle and row intervals;
//! * [`push`] and [`slide`]: step 2, the fast path; [`paper`]: the
//!   paper-literal reference;
//! * [`engine`]: every angle and start, the colliding masks and composite;
//! * [`sanity`]: the checks that warn of a part in the wrong units or
//!   facing the wrong way, and of a result with nothing struck.
//!
//! All lengths are mm and all angles degrees.

pub mod engine;
pub mod grid;
pub mod harness;
pub mod kneeform;
pub mod mesh;
pub mod output;
pub mod padded;
pub mod paper;
pub mod push;
pub mod report;
pub mod sanity;
pub mod scenario;
mod simd;
pub mod slide;
pub mod strike;
pub mod summary;

pub use engine::{Algorithm, AngleMask, EngineOptions, colliding_masks, composite, push_levels};
pub use grid::{GridSpec, HeightGrid};
pub use kneeform::{Footprint, GridFootprint, KneeForm};
pub use mesh::{Part, Side};
pub use strike::StrikeRule;
