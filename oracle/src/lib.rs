//! `kneeform-oracle`: the exact push-and-slide of the UN R21 knee-form, in
//! continuous geometry on the part's triangle mesh (SPEC, "The exact
//! oracle"). It shares no geometry code with the grid engine, so it can
//! catch the engine's mistakes.
//!
//! All lengths are mm and all points are in the analysis frame: the knee
//! slides in -x, the analysed surface faces -y and the knee is pushed in
//! +y, z is up. Angles are degrees.
//!
//! * [`KneeForm`]: the knee-form as a parry3d shape. It is the **exact**
//!   rounded prism, a custom support-map shape (triangle support + `R` in
//!   the xz direction of the query + the face or the back along y), not a
//!   tessellated polyhedron: a custom [`parry3d_f64::shape::SupportMap`]
//!   shape goes through parry's GJK shape casting against a
//!   [`parry3d_f64::shape::TriMesh`] like a built-in one, so nothing is
//!   gained by approximating it. Tests check its support points against
//!   the analytic rounded triangle and its casts against analytic contacts.
//! * [`Part`]: the mesh, read from STL with the engine's `scale` and
//!   `side`, or built from triangles.
//! * [`trace_start`] and [`evaluate`]: push and slide one start, or many
//!   starts at many angles in parallel; [`OracleOptions`] in,
//!   [`StartTrace`] with a [`StartStatus`] out. The casts walk the mesh's
//!   BVH with bounds from the exact footprint and cast each remaining
//!   triangle with parry's GJK (30x faster than parry's composite cast on
//!   a 400k-triangle part, same answers).
//! * [`Chain`] ([`OracleOptions::chain`]): the starts of one row on a
//!   lattice traced in chains, each joining its -x neighbour's curve
//!   after a few casts of its own (a console row: 48x fewer casts);
//!   [`chain_groups`] says which pairs [`evaluate_pairs`] traces together.
//! * [`rapier_slide`]: the same slide driven by rapier3d's kinematic
//!   character controller, a second view for cross-checking.
//!
//! # Deflection rates and strikes
//!
//! Each [`ContactPoint`] of a trace carries the deflection rate
//! `rate = -df/ds` of the slide there and its stated accuracy
//! `rate_error`; [`StartTrace::strikes`] gives the contacts with
//! `rate > sigma`, SPEC's exact strikes. The rate is the larger of the two
//! chord slopes `(f_a - f_b) / (s_b - s_a)` from the contact to its
//! neighbours on the traced curve (the push pose `(0, yr*)` before the
//! first contact), and infinite where a neighbour is at the same travel
//! within `jump_tolerance` (a riser). A chord between contacts within
//! `witness_tolerance` of each other is the mean of `-df/ds` over it; a
//! longer chord is a straight run over a depression, whose rate is its
//! chord (about 0). Because `f` is monotone, a chord steeper than `sigma`
//! has travel in it where the true rate exceeds `sigma`, so every reported
//! strike lies within one chord (`witness_tolerance` in travel) of a true
//! one. Where `-df/ds` is monotone over the two chords (no inflection of
//! the contact curve within them; one kink allowed) the true rate lies
//! between the chord slopes, so `rate_error` is the difference of the two
//! chords, a bound (next to a run, and at the last contact, the difference
//! of the chord and the next one out on the same side, an estimate of the
//! extrapolation error), plus the casts' rounding,
//! `2 jump_tolerance sqrt(1 + rate^2) / ds`. That is 0 along a plane, about `|f''| ds` on a smooth contact
//! curve with contacts `ds` apart (twice the actual error), and the jump
//! in slope next to a kink of a faceted mesh, however close the contacts.
//! A contact judged on the wrong side of `sigma` is therefore within one
//! chord of a travel where the true rate crosses `sigma`: the strike's
//! position is as accurate as the trace. The module `rate.rs` gives the
//! reasoning in full.
//!
//! **Invariant:** a start is never reported clear on a failed query: parry
//! returns "no hit" when GJK runs out of iterations, so every triangle a
//! cast reports as missed is confirmed by a contact query with the swept
//! knee-form, and every non-converged cast makes the start
//! [`StartStatus::Failed`].
//!
//! **Invariant:** the oracle does not depend on the `kneeform` engine.

mod batch;
mod direct;
mod error;
mod knee_form;
mod part;
mod prune;
mod rapier;
mod rate;
mod sweep;
mod trace;
mod window;

pub use batch::{chain_groups, evaluate, evaluate_pairs, evaluate_reporting};
pub use direct::{
    DirectContact, DirectOptions, DirectStatus, DirectTrace, direct_contact, evaluate_direct,
};
pub use error::OracleError;
pub use knee_form::{KneeForm, KneeFormDims};
pub use part::{Part, Side};
pub use rapier::{RapierComparison, RapierContact, RapierOptions, RapierSlide, rapier_slide};
pub use trace::{
    Chain, ContactPoint, FailureReason, OracleOptions, SlideEnd, StartStatus, StartTrace,
    trace_start,
};
pub use window::{Level, LevelCurve, WindowDrop};
