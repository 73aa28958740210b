//! Push and slide of one start, by parry3d shape casts (SPEC, "The exact
//! oracle").
//!
//! **Push.** The knee-form starts with its face 1 mm below the whole mesh
//! and is cast along +y; the time of impact gives `yr*`, the contact point
//! is the push witness. No hit: the start is not placed.
//!
//! **Slide.** The face level as a function of travel `s` is
//! `f(s) = max{ f <= f0 : the knee-form at level f travels [0, s] without
//! penetrating the mesh }`. A cast along -x at level `f` gives `s_max(f)`
//! and its witness point. The trace steps `f` down by
//! [`OracleOptions::level_step`] and bisects between consecutive levels
//! whose contacts differ by more than [`OracleOptions::witness_tolerance`]
//! (witness distance or travel), until the levels are closer than
//! [`OracleOptions::jump_tolerance`]: a gap still open then is a genuine
//! jump (the straight run over a depression, or the stop at a peak). It
//! ends when a cast misses (the knee-form clears the part) or a witness
//! lies past [`OracleOptions::x_min`] (the grid's -x edge).
//!
//! **Release offset.** The slide starts at `f0 = yr* - eps`
//! ([`OracleOptions::eps`]), not at `yr*`: this keeps the first cast off
//! the touching pose, where parry reports a time of impact of 0. On a
//! part that bounds a solid it changes nothing but the first contact:
//! lowering the knee-form only lets it travel further, so the slide
//! released at `f0` follows SPEC's slide from `yr*` wherever that one is
//! below `f0`, and every reported contact lies on SPEC's curve. What the
//! trace does not sample is the curve's first drop by `eps`, between the
//! push pose and the first contact: the first contact is late by the
//! travel that drop takes, at most `eps / rate` (0.115 mm for any strike
//! at 0.5 degrees), and a feature that sticks out less than `eps` beyond
//! `yr*` is not seen. The push pose's chord to the first contact keeps
//! that drop in the rates ([`crate::rate`]). Every reported `face_level`
//! is the level of the cast that touched.
//!
//! **Deflection rates.** Once the trace is complete, each contact gets its
//! rate `-df/ds` and a bound on that rate's error from the chords to its
//! neighbours; [`crate::rate`] says how and how accurately.
//! [`StartTrace::strikes`] are the contacts whose rate exceeds `sigma`.
//!
//! **Monotone travel.** A lower level normally travels at least as far as a
//! higher one (lowering the knee-form only moves it away from a part that
//! bounds a solid). Where it does not (a broken mesh, a floating sheet, or
//! a grazing contact whose travel carries the cast's gap error divided by
//! the grazing slope), the lower level's contact is not on `f(s)` (the
//! knee-form is already past it) and is skipped, so reported travels never
//! decrease by more than `jump_tolerance`.

use parry3d_f64::math::Vector;
use serde::{Deserialize, Serialize};

use crate::knee_form::{KneeForm, KneeFormDims};
use crate::rate;
use crate::sweep::{self, Motion};
use crate::{OracleError, Part};

/// How far below the mesh's lowest point the push cast starts, mm. Any
/// positive value works; 1 mm keeps the time of impact small and exact.
const PUSH_CLEARANCE: f64 = 1.0;

/// A swept knee-form overlapping the mesh by less than this fraction of
/// `eps` after a cast reported no hit is a grazing pass, not a failure.
const GRAZING_FRACTION: f64 = 0.1;

/// How far past the mesh (or `x_min`) a slide cast looks, mm.
const SLIDE_MARGIN: f64 = 1.0;

/// Options of the exact push-and-slide. Lengths in mm, analysis frame.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OracleOptions {
    /// The knee-form's `L`, `R`, `W`.
    pub knee_form: KneeFormDims,
    /// The release offset (mm, > 0): the slide starts this far below
    /// `yr*`, which keeps its first cast off the touching pose. It moves
    /// the first contact later by at most `eps / rate` (0.115 mm for any
    /// strike at 0.5 degrees) and hides features that stick out less than
    /// `eps` beyond `yr*`; later contacts are unchanged (module docs).
    /// Default 1e-3 mm.
    pub eps: f64,
    /// Consecutive contact points further apart than this (witness
    /// distance, or difference in travel) are bisected (mm). Default 0.1 mm,
    /// a tenth of a 1 mm grid pitch: set it to a tenth of the pitch checked.
    pub witness_tolerance: f64,
    /// The step of the face level between casts before bisection (mm).
    /// Default 1 mm; a step larger than a feature's depth could step over
    /// a contact that leaves and comes back within `witness_tolerance`.
    pub level_step: f64,
    /// A gap between contacts whose levels are closer than this is a
    /// genuine jump, and contacts whose travels differ by less than this
    /// are at the same travel (mm). Default 1e-6 mm, parry3d-f64's accuracy
    /// on part-sized coordinates.
    pub jump_tolerance: f64,
    /// Shape casts allowed per start (push + slide); a start that needs
    /// more fails with [`FailureReason::CastBudgetExhausted`].
    pub max_casts: usize,
    /// The grid's -x edge (mm): a contact whose witness has `x < x_min`
    /// ends the trace and is not reported. Default `-inf`.
    pub x_min: f64,
    /// Whether a cast skips, before GJK, the triangles it cannot meet
    /// (the oracle's `prune` module): the same traces, bit for bit, about three times
    /// faster on a console. Off only to check that (default on).
    #[serde(default = "prune_on")]
    pub prune: bool,
    /// Starts on a lattice traced as chains along their row ([`Chain`]):
    /// a start's curve joins its -x neighbour's once it has passed it
    /// below its release level, and from there on its contacts are the
    /// neighbour's. `None` (the default): every start traced on its own.
    #[serde(default)]
    pub chain: Option<Chain>,
}

/// How starts on a lattice share their traces (SPEC's curve is the same
/// function whichever start it is sampled from).
///
/// The starts of one knee-form row (one `z`, one angle) at the lattice's
/// columns `c` (x = `pitch * c`) are cut into blocks of `block` columns
/// (`c.div_euclid(block)`); within a block, start `c` is traced after
/// start `c - 1` and joins its curve: once one of its own contacts lies
/// at a travel of at least `pitch` and a level at or below the
/// neighbour's release level (`yr* - eps`), every lower level travels
/// the pitch freely (lowering the knee-form only moves it away from a
/// part that bounds a solid) and then exactly as far as the neighbour
/// does, so its further contacts are the neighbour's, `pitch` further
/// along; the gap to the first of them is bisected with its own casts as
/// any other. The first start of a block, and one whose neighbour is not
/// placed or failed, is traced on its own. A start's trace is a function
/// of its block alone, whatever other starts are asked for, so any subset
/// of starts (a shard's) traces as the whole does; a start off the
/// lattice is traced on its own.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Chain {
    /// The lattice's pitch along x (mm, > 0).
    pub pitch: f64,
    /// Columns per block (>= 1; 1 traces every start on its own).
    pub block: usize,
}

impl Chain {
    /// The column of `x` on the lattice, when `x` is a node of it
    /// (`pitch * c` to the bit, as a grid's node is).
    pub(crate) fn column(&self, x: f64) -> Option<i64> {
        let c = (x / self.pitch).round();
        (c.abs() < 9.0e15 && self.pitch * c == x).then_some(c as i64)
    }

    /// The first column of `c`'s block.
    pub(crate) fn head(&self, c: i64) -> i64 {
        let k = self.block as i64;
        c.div_euclid(k) * k
    }

    /// The node at column `c` (mm).
    pub(crate) fn x(&self, c: i64) -> f64 {
        self.pitch * c as f64
    }
}

/// [`OracleOptions::prune`]'s default.
fn prune_on() -> bool {
    true
}

impl Default for OracleOptions {
    fn default() -> Self {
        Self {
            knee_form: KneeFormDims::default(),
            eps: 1e-3,
            witness_tolerance: 0.1,
            level_step: 1.0,
            jump_tolerance: 1e-6,
            max_casts: 100_000,
            x_min: f64::NEG_INFINITY,
            prune: true,
            chain: None,
        }
    }
}

impl OracleOptions {
    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), OracleError> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(OracleError::InvalidOptions(format!(
                    "{name} must be finite and > 0, got {v}"
                )))
            }
        };
        if !self.knee_form.is_valid() {
            return Err(OracleError::InvalidOptions(format!(
                "knee-form dimensions must be finite and > 0, got {:?}",
                self.knee_form
            )));
        }
        positive("eps", self.eps)?;
        positive("witness_tolerance", self.witness_tolerance)?;
        positive("level_step", self.level_step)?;
        positive("jump_tolerance", self.jump_tolerance)?;
        if self.max_casts == 0 {
            return Err(OracleError::InvalidOptions("max_casts must be > 0".into()));
        }
        if let Some(chain) = self.chain {
            positive("chain pitch", chain.pitch)?;
            if chain.block == 0 {
                return Err(OracleError::InvalidOptions(
                    "a chain's block must hold at least one column".into(),
                ));
            }
        }
        if self.x_min.is_nan() || self.x_min == f64::INFINITY {
            return Err(OracleError::InvalidOptions(format!(
                "x_min must be finite or -inf, got {}",
                self.x_min
            )));
        }
        Ok(())
    }
}

/// One point of the contact curve of a slide.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactPoint {
    /// Travel `s` of the reference point along -x from the start (mm).
    pub travel: f64,
    /// Face level `f` of the knee-form at this contact (mm, analysis y).
    pub face_level: f64,
    /// The touched point of the mesh, `[x, y, z]` (mm, analysis frame).
    pub witness: [f64; 3],
    /// The deflection rate `-df/ds` here (dimensionless, `>= 0`): the larger
    /// of the chord slopes to the previous contact (the push pose
    /// `(0, yr*)` for the first) and to the next one; `f64::INFINITY` where
    /// a neighbour is at the same travel within `jump_tolerance` (a riser). JSON has no infinity:
    /// an infinite rate is written as `null` and read back as infinite.
    /// See [the crate docs](crate#deflection-rates-and-strikes) for how
    /// accurate it is.
    #[serde(with = "crate::rate::serde_rate")]
    pub rate: f64,
    /// The stated accuracy of `rate` (dimensionless, `>= 0`, finite): the
    /// rate SPEC defines lies within `rate +- rate_error`. Between two
    /// short chords this is a bound wherever the contact curve has no
    /// inflection within them (a single kink is allowed); next to a jump,
    /// and at the last contact, an estimate from the next chord out. 0 at
    /// a riser and along a plane, up to rounding; about `|f''| ds` on a
    /// smooth curve with contacts `ds` apart; the jump in slope next to a
    /// kink. See [the crate docs](crate#deflection-rates-and-strikes).
    pub rate_error: f64,
}

/// Why a start's trace could not be trusted.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, thiserror::Error)]
pub enum FailureReason {
    /// A shape cast stopped with `ShapeCastStatus::OutOfIterations` or
    /// `Failed`.
    #[error("a shape cast did not converge")]
    CastNotConverged,
    /// A cast reported no hit, but the swept knee-form overlaps the mesh by
    /// more than a tenth of `eps`: the cast gave up (parry's GJK returns no hit when it runs out of
    /// iterations).
    #[error("a cast reported no hit but the swept knee-form touches the part")]
    UnconfirmedMiss,
    /// A slide cast found the knee-form already penetrating at travel 0.
    #[error("the knee-form penetrates the part at the start of a slide cast")]
    PenetratingStart,
    /// More than [`OracleOptions::max_casts`] casts were needed.
    #[error("the cast budget per start is exhausted")]
    CastBudgetExhausted,
    /// parry3d does not support the query (never expected).
    #[error("parry3d does not support this query")]
    Unsupported,
}

/// Outcome of one start.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StartStatus {
    /// The knee-form touched the part when pushed; `yr*` is known.
    Placed,
    /// No point of the mesh lies in the footprint: SPEC's "not placed".
    NotPlaced,
    /// A query failed; the contacts found before the failure are kept but
    /// the trace is incomplete.
    Failed {
        /// What went wrong.
        reason: FailureReason,
    },
}

/// Why a slide stopped.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SlideEnd {
    /// No slide was run (not placed, or failed before).
    NotRun,
    /// A cast missed: the knee-form clears the part (or reaches the grid's
    /// -x edge without touching anything more).
    Cleared,
    /// A contact's witness lay past [`OracleOptions::x_min`].
    PastXMin,
}

/// The exact push and slide of one start at one angle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartTrace {
    /// The knee-form angle, degrees.
    pub angle_deg: f64,
    /// The start: the reference point's `(x, z)`, mm, analysis frame.
    pub start: [f64; 2],
    /// Placed, not placed or failed.
    pub status: StartStatus,
    /// `yr*`: the face level at push contact (mm), when placed.
    pub yr_star: Option<f64>,
    /// The mesh point touched by the push, `[x, y, z]` mm, when placed.
    pub push_witness: Option<[f64; 3]>,
    /// The slide's contact points, by increasing travel (decreasing level).
    pub contacts: Vec<ContactPoint>,
    /// Why the slide stopped.
    pub slide_end: SlideEnd,
    /// Shape casts spent on this start (push + slide).
    pub casts: usize,
}

impl StartTrace {
    /// The strikes of a placed start: its contacts whose deflection rate
    /// exceeds `sigma = tan(delta)` (SPEC, "Exact strikes"), in the order
    /// of the slide. Risers (infinite rate) are strikes for any `sigma`.
    ///
    /// A start that is not placed has none. A failed start's strikes are
    /// unknown, not absent: that is an error, so no caller can take a
    /// failed query for a clear start.
    pub fn strikes(
        &self,
        sigma: f64,
    ) -> Result<impl Iterator<Item = &ContactPoint> + '_, FailureReason> {
        let contacts: &[ContactPoint] = match self.status {
            StartStatus::Placed => &self.contacts,
            StartStatus::NotPlaced => &[],
            StartStatus::Failed { reason } => return Err(reason),
        };
        Ok(contacts.iter().filter(move |c| c.rate > sigma))
    }
}

/// Push and slide one start: the reference point at `start = (x, z)` (mm,
/// analysis frame), the knee-form at `angle_deg` degrees.
pub fn trace_start(
    part: &Part,
    start: [f64; 2],
    angle_deg: f64,
    options: &OracleOptions,
) -> Result<StartTrace, OracleError> {
    options.validate()?;
    let knee = KneeForm::new(options.knee_form, angle_deg);
    Ok(trace_validated(part, &knee, start, options))
}

/// [`trace_start`] with options already validated and the knee-form built.
pub(crate) fn trace_validated(
    part: &Part,
    knee: &KneeForm,
    start: [f64; 2],
    options: &OracleOptions,
) -> StartTrace {
    trace_joining(part, knee, start, options, None)
}

/// [`trace_validated`], joining the curve of `left` (the trace of the
/// start on the same row `pitch` to the -x, at the same angle, with the
/// same options) where the two meet ([`Chain`]).
pub(crate) fn trace_joining(
    part: &Part,
    knee: &KneeForm,
    start: [f64; 2],
    options: &OracleOptions,
    left: Option<&StartTrace>,
) -> StartTrace {
    // A placed start's slide has run (its end is never `NotRun`).
    let join = left
        .filter(|l| l.status == StartStatus::Placed && l.start[1] == start[1])
        .filter(|l| start[0] > l.start[0])
        .and_then(|l| {
            Some(Join {
                contacts: &l.contacts,
                end: l.slide_end,
                shift: start[0] - l.start[0],
                release: l.yr_star? - options.eps,
            })
        });
    let mut tracer = Tracer {
        part,
        knee: *knee,
        start,
        options,
        casts: 0,
        contacts: Vec::new(),
        end: None,
        join,
    };
    let mut trace = StartTrace {
        angle_deg: knee.angle_deg(),
        start,
        status: StartStatus::NotPlaced,
        yr_star: None,
        push_witness: None,
        contacts: Vec::new(),
        slide_end: SlideEnd::NotRun,
        casts: 0,
    };
    let outcome = tracer.push().and_then(|push| match push {
        None => Ok(StartStatus::NotPlaced),
        Some((yr_star, witness)) => {
            trace.yr_star = Some(yr_star);
            trace.push_witness = Some(witness.to_array());
            tracer.slide(yr_star - options.eps)?;
            Ok(StartStatus::Placed)
        }
    });
    trace.status = outcome.unwrap_or_else(|reason| StartStatus::Failed { reason });
    if trace.status == StartStatus::Placed {
        trace.slide_end = tracer.end.unwrap_or(SlideEnd::Cleared);
    }
    trace.contacts = tracer.contacts;
    trace.casts = tracer.casts;
    if let (Some(yr_star), Some(push_witness)) = (trace.yr_star, trace.push_witness) {
        rate::deflection_rates(yr_star, push_witness, &mut trace.contacts, options);
    }
    trace
}

/// A slide cast's contact: travel (mm) and mesh witness point.
#[derive(Copy, Clone, Debug)]
struct Hit {
    travel: f64,
    witness: Vector,
}

struct Tracer<'a> {
    part: &'a Part,
    knee: KneeForm,
    start: [f64; 2],
    options: &'a OracleOptions,
    casts: usize,
    contacts: Vec<ContactPoint>,
    end: Option<SlideEnd>,
    /// The -x neighbour's curve to join, until joined ([`Chain`]).
    join: Option<Join<'a>>,
}

/// The curve of a start's -x neighbour on its row ([`Chain`]).
struct Join<'a> {
    /// Its contacts, by increasing travel.
    contacts: &'a [ContactPoint],
    /// How its slide ended.
    end: SlideEnd,
    /// How far it lies to the -x (mm, > 0).
    shift: f64,
    /// Its release level `yr* - eps` (mm): its trace covers every level
    /// at or below it.
    release: f64,
}

impl Tracer<'_> {
    /// One shape cast (see [`crate::sweep`]) from the reference point at
    /// `start`, face level `level`, counted against the budget.
    fn cast(
        &mut self,
        level: f64,
        motion: Motion,
        max_travel: f64,
    ) -> Result<Option<(f64, Vector)>, FailureReason> {
        if self.casts >= self.options.max_casts {
            return Err(FailureReason::CastBudgetExhausted);
        }
        self.casts += 1;
        let origin = Vector::new(self.start[0], level, self.start[1]);
        let grazing = GRAZING_FRACTION * self.options.eps;
        let hit = sweep::cast(
            self.part.mesh(),
            &self.knee,
            origin,
            motion,
            max_travel,
            grazing,
            self.options.prune,
        )?;
        Ok(hit.map(|c| (c.travel, c.witness)))
    }

    /// The push: `Some((yr*, witness))`, or `None` when not placed.
    fn push(&mut self) -> Result<Option<(f64, Vector)>, FailureReason> {
        let (mins, maxs) = self.part.bounds();
        let from = mins[1] - PUSH_CLEARANCE;
        let reach = maxs[1] - from + PUSH_CLEARANCE;
        Ok(self
            .cast(from, Motion::Push, reach)?
            .map(|(toi, witness)| (from + toi, witness)))
    }

    /// The slide cast at face level `level`: travel to first contact along
    /// -x and its witness, or `None` when the knee-form clears the part
    /// before its back passes the mesh or `x_min`.
    fn slide_cast(&mut self, level: f64) -> Result<Option<Hit>, FailureReason> {
        let (mins, _) = self.part.bounds();
        let back = self.start[0] + self.knee.x_extent().1;
        let edge = mins[0].max(self.options.x_min);
        let reach = (back - edge + SLIDE_MARGIN).max(SLIDE_MARGIN);
        Ok(self
            .cast(level, Motion::Slide, reach)?
            .map(|(travel, witness)| Hit { travel, witness }))
    }

    /// Whether nothing needs bisecting between two consecutive casts.
    fn resolved(&self, a: Option<Hit>, b: Option<Hit>) -> bool {
        match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => {
                let travel = (b.travel - a.travel).abs();
                // The knee-form did not move between the two levels: every
                // level in between stops at the same travel, whatever the
                // witnesses (a face-to-face contact has no unique witness).
                travel <= self.options.jump_tolerance
                    || (travel <= self.options.witness_tolerance
                        && (b.witness - a.witness).length() <= self.options.witness_tolerance)
            }
            _ => false,
        }
    }

    /// Records the contact at `level`, or ends the trace past `x_min`.
    fn emit(&mut self, level: f64, hit: Hit) {
        if hit.witness.x < self.options.x_min {
            self.end = Some(SlideEnd::PastXMin);
            return;
        }
        // `f(s)` takes the highest level that can still travel `s`: a lower
        // level that stops earlier than one already traced is never
        // reached, so its contact is not on the curve.
        let reached = self.contacts.last().map_or(f64::NEG_INFINITY, |c| c.travel);
        if hit.travel < reached - self.options.jump_tolerance {
            return;
        }
        self.contacts.push(ContactPoint {
            travel: hit.travel,
            face_level: level,
            witness: hit.witness.to_array(),
            // Filled in once the trace is complete (`rate`).
            rate: f64::NAN,
            rate_error: f64::NAN,
        });
    }

    /// Emits the contacts of the levels in `(b, a)` (bisected as needed)
    /// and then `b`'s, in decreasing level; `a`'s is already emitted.
    fn refine(
        &mut self,
        a: f64,
        hit_a: Option<Hit>,
        b: f64,
        hit_b: Option<Hit>,
    ) -> Result<(), FailureReason> {
        if !self.resolved(hit_a, hit_b) && a - b > self.options.jump_tolerance {
            let mid = 0.5 * (a + b);
            let hit_mid = self.slide_cast(mid)?;
            self.refine(a, hit_a, mid, hit_mid)?;
            if self.end.is_none() {
                self.refine(mid, hit_mid, b, hit_b)?;
            }
            return Ok(());
        }
        if let Some(hit) = hit_b {
            self.emit(b, hit);
            self.join_if_met(b, hit)?;
        }
        Ok(())
    }

    /// Joins the neighbour's curve ([`Chain`]) when the contact just
    /// emitted at `level` (`hit`) lies a pitch or more along and at or
    /// below the neighbour's release level: every lower level travels the
    /// pitch freely, then as the neighbour does. Its contacts below
    /// `level`, shifted by the pitch, end the trace, after the gap to the
    /// first of them is bisected with this start's own casts; the trace
    /// ends as the neighbour's did. Nothing happens when the neighbour has
    /// no contact below `level`.
    fn join_if_met(&mut self, level: f64, hit: Hit) -> Result<(), FailureReason> {
        // Only a contact this start has just recorded (not one skipped,
        // nor past the end) can join.
        let recorded =
            self.end.is_none() && self.contacts.last().is_some_and(|c| c.face_level == level);
        let Some(join) = self
            .join
            .take_if(|j| recorded && hit.travel >= j.shift && level <= j.release)
        else {
            return Ok(());
        };
        let below = join.contacts.partition_point(|c| c.face_level >= level);
        let Some(first) = join.contacts.get(below) else {
            // Nothing to join below this level: trace on alone.
            return Ok(());
        };
        let shifted = |c: &ContactPoint| Hit {
            travel: c.travel + join.shift,
            witness: Vector::from_array(c.witness),
        };
        self.refine(level, Some(hit), first.face_level, Some(shifted(first)))?;
        for c in &join.contacts[below + 1..] {
            if self.end.is_some() {
                break;
            }
            self.emit(c.face_level, shifted(c));
        }
        if self.end.is_none() {
            self.end = Some(join.end);
        }
        Ok(())
    }

    /// Traces the contact curve from level `top` down.
    fn slide(&mut self, top: f64) -> Result<(), FailureReason> {
        let mut level = top;
        let mut hit = self.slide_cast(level)?;
        match hit {
            None => {
                self.end = Some(SlideEnd::Cleared);
                return Ok(());
            }
            Some(h) => {
                self.emit(level, h);
                self.join_if_met(level, h)?;
            }
        }
        while self.end.is_none() {
            let next = level - self.options.level_step;
            let next_hit = self.slide_cast(next)?;
            self.refine(level, hit, next, next_hit)?;
            if next_hit.is_none() && self.end.is_none() {
                self.end = Some(SlideEnd::Cleared);
            }
            level = next;
            hit = next_hit;
        }
        Ok(())
    }
}
