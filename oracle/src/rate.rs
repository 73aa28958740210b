//! The deflection rate `-df/ds` at each contact of a traced slide, and how
//! accurately it is known (SPEC, "The exact oracle", "Exact strikes").
//!
//! **The curve.** A trace samples the face level `f(s)`, a non-increasing
//! function of the travel `s`, at its contacts `(s_k, f_k)`, preceded by
//! the push pose `(0, yr*)`. Every contact lies on SPEC's curve, the slide
//! released at `yr*` (see [`crate::OracleOptions::eps`]): the push pose and
//! the first contact bound the first `eps` of the curve's drop.
//!
//! **Chords.** Between two consecutive points (the push pose first) the
//! chord slope is `c = (f_a - f_b) / (s_b - s_a)`, clamped to `>= 0` (a
//! negative value is rounding: the levels of a trace only decrease). A
//! chord is one of three kinds, by the tracer's own bisection test:
//!
//! * a **riser**: the travels agree within
//!   [`crate::OracleOptions::jump_tolerance`]: the level drops at constant
//!   travel, an infinite rate;
//! * **short**: travels and witnesses within
//!   [`crate::OracleOptions::witness_tolerance`]: the tracer found nothing
//!   between the two contacts to bisect, the knee-form slides along one
//!   surface, and `c` is the mean of `-df/ds` over the chord;
//! * **long**: across a jump: a straight run over a depression (the levels
//!   agree within `jump_tolerance`), or the push pose's chord to a first
//!   contact further away (it drops by `eps` over the run). The knee-form
//!   runs at constant level, so `c` (at most `jump_tolerance` or `eps` over
//!   the chord's length) is that side's rate.
//!
//! **The estimate.** A contact's `rate` is the larger of its two chord
//! slopes, incoming and outgoing (the last contact has only the incoming
//! one), and infinite where either is a riser: each chord stands for the
//! one-sided rate on its side, and SPEC takes the larger at a kink.
//!
//! **Why that is accurate, and how much.**
//!
//! 1. *No strike from nothing.* `f` is monotone, so a chord slope above
//!    `sigma` means `-df/ds > sigma` somewhere in the chord's travel (or a
//!    drop at constant travel there). Every contact reported as a strike
//!    is therefore within one chord of travel where the knee-form truly
//!    deflects faster than `sigma`: `witness_tolerance` for a short chord,
//!    `eps / sigma` (0.115 mm at 0.5 degrees) for the push pose's chord.
//! 2. *Bracketing.* Where `-df/ds` is monotone over the two chords of a
//!    contact (no inflection of the contact curve within them; a single
//!    kink of a faceted surface is allowed), both one-sided rates lie
//!    between the two chord slopes: `rate` is an upper bound, and
//!    `rate - |c_in - c_out|` a lower one. On a smooth piece with
//!    `|f''| <= K`, each chord is within `K ds / 2` of the rate at its end,
//!    while `|c_in - c_out|` is about `K (ds_in + ds_out) / 2`: the stated
//!    error is about twice the actual one. Where `-df/ds` has a local
//!    maximum between the chords, both chords fall short of it by a second
//!    order amount, `|f'''| ds^2 / 6`.
//! 3. *Next to a jump.* The run's side is exact up to rounding; the other side's chord
//!    stands for its one-sided rate with an error estimated by its
//!    difference to the next short chord further out, which measures
//!    `K (ds + ds') / 2 >= K ds / 2`. A contact with no such chord (a
//!    touch isolated between runs) has its chord slope as its error.
//! 4. *Rounding.* A cast's travel carries parry's gap error
//!    (`jump_tolerance`) along the contact normal, which moves a chord
//!    slope by up to `2 jump_tolerance sqrt(1 + c^2) / ds`: added, to every
//!    chord, runs and witness switches included (a switch at nearly the
//!    same travel has a tiny `ds`, so its slope is mostly rounding).
//!
//! `rate_error` is the half-width of the interval around `rate` that then
//! holds SPEC's rate (the larger one-sided one): each side `i` gives
//! `c_i +- e_i`, the true rate lies between `max(c_i - e_i)` and
//! `max(c_i + e_i)`, and `rate_error` is the larger distance from `rate`
//! to those ends. It is 0 at a riser.
//!
//! **What this means for strikes.** On a smooth contact curve the chord
//! error `K ds / 2` reaches `sigma = tan 0.5 deg` where the curve's radius
//! of curvature `1 / K` is below `ds / (2 sigma)`: 5.7 mm at the default
//! `ds = 0.1` mm. At a kink of a faceted mesh the contact next to the kink
//! has an error up to the facets' difference in slope, however close the
//! contacts: a finer trace brings that contact closer to the kink, it
//! does not shrink its error. Either way the rate moves by at most the
//! error over one chord, so a contact judged on the wrong side of `sigma`
//! lies within one chord (`witness_tolerance` in travel) of a travel where
//! the true rate crosses `sigma`: the error in a strike's position is that
//! of the trace itself, a tenth of the pitch checked. That is why the
//! tracer does not bisect further for the rate; a finer
//! `witness_tolerance` sharpens both.

use crate::{ContactPoint, OracleOptions};

/// A point of the traced curve: the push pose or a contact.
#[derive(Copy, Clone, Debug)]
struct Point {
    travel: f64,
    level: f64,
    witness: [f64; 3],
}

impl From<&ContactPoint> for Point {
    fn from(c: &ContactPoint) -> Self {
        Point {
            travel: c.travel,
            level: c.face_level,
            witness: c.witness,
        }
    }
}

/// What lies between two consecutive points of the curve (module docs).
#[derive(Copy, Clone, Debug, PartialEq)]
enum Chord {
    /// A drop at constant travel.
    Riser,
    /// A piece of the curve along one surface: its slope and the slope's
    /// rounding error.
    Short { slope: f64, rounding: f64 },
    /// A straight run, or a switch of the witness between features at
    /// nearly the same travel: its slope is its rate, known to within the
    /// casts' rounding over its travel.
    Long { slope: f64, rounding: f64 },
}

impl Chord {
    fn between(a: Point, b: Point, options: &OracleOptions) -> Chord {
        let ds = b.travel - a.travel;
        if ds.abs() <= options.jump_tolerance {
            return Chord::Riser;
        }
        let slope = ((a.level - b.level) / ds).max(0.0);
        let witness_gap = (0..3)
            .map(|i| (b.witness[i] - a.witness[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let rounding = 2.0 * options.jump_tolerance * slope.hypot(1.0) / ds.abs();
        if ds <= options.witness_tolerance && witness_gap <= options.witness_tolerance {
            Chord::Short { slope, rounding }
        } else {
            Chord::Long { slope, rounding }
        }
    }

    fn short_slope(chord: Option<Chord>) -> Option<f64> {
        match chord {
            Some(Chord::Short { slope, .. }) => Some(slope),
            _ => None,
        }
    }
}

/// One side's estimate of the one-sided rate at a contact: `(value,
/// error)`, `None` for a riser (infinite). `near` is the side's chord,
/// `across` the other side's, `outer` the next chord out on this side.
fn one_sided(near: Chord, across: Option<Chord>, outer: Option<Chord>) -> Option<(f64, f64)> {
    match near {
        Chord::Riser => None,
        // Rounding matters here too: where the witness switches between
        // facets at nearly the same travel, the bisection stops with the
        // levels `jump_tolerance` apart over microns of travel, and the
        // chord's slope is that rounding over its travel (measured: 0.047,
        // eight times the surface's slope, on a crease of a faceted bulge).
        Chord::Long { slope, rounding } => Some((slope, rounding)),
        Chord::Short { slope, rounding } => {
            let probe = Chord::short_slope(across).or(Chord::short_slope(outer));
            let curvature = probe.map_or(slope, |p| (slope - p).abs());
            Some((slope, curvature + rounding))
        }
    }
}

/// Fills `rate` and `rate_error` of every contact of a trace whose push
/// gave `yr_star` at `push_witness` (see the module docs).
pub(crate) fn deflection_rates(
    yr_star: f64,
    push_witness: [f64; 3],
    contacts: &mut [ContactPoint],
    options: &OracleOptions,
) {
    let push = Point {
        travel: 0.0,
        level: yr_star,
        witness: push_witness,
    };
    let points: Vec<Point> = std::iter::once(push)
        .chain(contacts.iter().map(Point::from))
        .collect();
    // chords[k] joins points[k] and points[k + 1]: contact k's incoming
    // chord is chords[k], its outgoing one chords[k + 1].
    let chords: Vec<Chord> = points
        .windows(2)
        .map(|w| Chord::between(w[0], w[1], options))
        .collect();
    for (k, contact) in contacts.iter_mut().enumerate() {
        let incoming = chords[k];
        let outgoing = chords.get(k + 1).copied();
        let before = k.checked_sub(1).map(|j| chords[j]);
        let after = chords.get(k + 2).copied();
        let sides = [
            one_sided(incoming, outgoing, before),
            outgoing.and_then(|c| one_sided(c, Some(incoming), after)),
        ];
        let riser = sides[0].is_none() || (outgoing.is_some() && sides[1].is_none());
        (contact.rate, contact.rate_error) = if riser {
            (f64::INFINITY, 0.0)
        } else {
            let sides = sides.into_iter().flatten();
            let (mut rate, mut hi, mut lo) = (0.0_f64, 0.0_f64, 0.0_f64);
            for (value, error) in sides {
                rate = rate.max(value);
                hi = hi.max(value + error);
                lo = lo.max(value - error);
            }
            (rate, (hi - rate).max(rate - lo))
        };
    }
}

/// Serde for [`ContactPoint::rate`]: an infinite rate (a riser) is written
/// as `null`, which JSON has instead of infinity, and read back as
/// `f64::INFINITY`; a finite rate is a plain number.
pub(crate) mod serde_rate {
    use serde::{Deserialize, Deserializer, Serializer};

    pub(crate) fn serialize<S: Serializer>(rate: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        if rate.is_finite() {
            serializer.serialize_f64(*rate)
        } else {
            serializer.serialize_none()
        }
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(deserializer)?.unwrap_or(f64::INFINITY))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Contacts sampled from `f` at `travels` with witnesses along x (as a
    /// front point would give), and their rates.
    fn rates(
        yr_star: f64,
        f: impl Fn(f64) -> f64,
        travels: &[f64],
        options: &OracleOptions,
    ) -> Vec<ContactPoint> {
        let mut contacts: Vec<ContactPoint> = travels
            .iter()
            .map(|&s| ContactPoint {
                travel: s,
                face_level: f(s),
                witness: [-s, f(s), 0.0],
                rate: f64::NAN,
                rate_error: f64::NAN,
            })
            .collect();
        deflection_rates(yr_star, [0.0, yr_star, 0.0], &mut contacts, options);
        contacts
    }

    /// Contacts up to 0.5 mm apart count as short chords.
    fn options() -> OracleOptions {
        OracleOptions {
            witness_tolerance: 0.5,
            ..OracleOptions::default()
        }
    }

    fn spaced(from: f64, to: f64, ds: f64) -> Vec<f64> {
        let n = ((to - from) / ds).round() as usize;
        (0..=n)
            .map(|i| from + (to - from) * i as f64 / n as f64)
            .collect()
    }

    #[test]
    fn a_straight_climb_has_its_slope_at_every_contact() {
        let options = options();
        for g in [0.005, 0.05, 2.0] {
            let travels = spaced(0.001 / g, 20.0, 0.09);
            let contacts = rates(0.0, |s| -g * s, &travels, &options);
            for (k, c) in contacts.iter().enumerate() {
                assert!((c.rate - g).abs() <= c.rate_error + 1e-12, "{g}: {c:?}");
                // Only rounding is left on a straight line: at most that of
                // the shorter chord, plus float noise.
                let prev = if k == 0 { 0.0 } else { travels[k - 1] };
                let next = travels.get(k + 1).map_or(f64::INFINITY, |&s| s - c.travel);
                let ds = (c.travel - prev).min(next);
                let rounding = 2.0 * options.jump_tolerance * g.hypot(1.0) / ds;
                assert!(c.rate_error <= rounding + 1e-12, "{g}: {c:?}");
            }
        }
    }

    #[test]
    fn a_smooth_curve_is_bracketed_within_its_stated_error() {
        // f = -s^2 / (2 rho): -df/ds = s / rho, |f''| = 1 / rho.
        let options = options();
        let rho = 8.0;
        let travels = spaced(0.5, 30.0, 0.1);
        let contacts = rates(
            -0.5f64.powi(2) / (2.0 * rho) + 1e-3,
            |s| -s * s / (2.0 * rho),
            &travels,
            &options,
        );
        for c in &contacts[..contacts.len() - 1] {
            let exact = c.travel / rho;
            assert!((c.rate - exact).abs() <= c.rate_error, "{c:?} vs {exact}");
            // Bracketing: the chord maximum is an upper bound; the stated
            // error is about K (ds_in + ds_out) / 2 = 0.1 / rho.
            assert!(c.rate >= exact - 1e-9, "{c:?} vs {exact}");
            assert!(c.rate_error < 1.1 * 0.1 / rho, "{c:?}");
        }
        // The last contact extrapolates its incoming chord; its error
        // comes from the chord before.
        let last = contacts.last().unwrap();
        assert!(
            (last.rate - last.travel / rho).abs() <= last.rate_error,
            "{last:?}"
        );
    }

    #[test]
    fn a_kink_takes_the_larger_rate_and_states_the_jump_in_slope_as_its_error() {
        // Slope 0.3 up to s = 5.05, then 0.1: contacts every 0.1 mm, the
        // kink between two of them.
        let options = options();
        let f = |s: f64| {
            if s < 5.05 {
                -0.3 * s
            } else {
                -0.3 * 5.05 - 0.1 * (s - 5.05)
            }
        };
        let travels = spaced(0.1, 10.0, 0.1);
        let contacts = rates(0.0, f, &travels, &options);
        for c in &contacts {
            let exact = if c.travel < 5.05 { 0.3 } else { 0.1 };
            assert!(
                (c.rate - exact).abs() <= c.rate_error + 1e-9,
                "{c:?} vs {exact}"
            );
            if (c.travel - 5.05).abs() > 0.2 {
                assert!(c.rate_error < 1e-4, "{c:?}");
            }
        }
    }

    #[test]
    fn a_riser_is_infinite_and_a_run_is_flat() {
        // Run from the push pose to s = 30, drop 5 mm at constant travel,
        // run again to s = 80 at the lower level, then climb at 0.2.
        let options = OracleOptions::default();
        let mut contacts = vec![
            ContactPoint {
                travel: 30.0,
                face_level: -1e-3,
                witness: [-30.0, -1e-3, 0.0],
                rate: 0.0,
                rate_error: 0.0,
            },
            ContactPoint {
                travel: 30.0 + 1e-9,
                face_level: -5.0,
                witness: [-30.0, -5.0, 0.0],
                rate: 0.0,
                rate_error: 0.0,
            },
        ];
        for s in spaced(80.0, 85.0, 0.05) {
            contacts.push(ContactPoint {
                travel: s,
                face_level: -5.0 - 0.2 * (s - 80.0),
                witness: [-s, -5.0 - 0.2 * (s - 80.0), 0.0],
                rate: 0.0,
                rate_error: 0.0,
            });
        }
        deflection_rates(0.0, [0.0, 0.0, 0.0], &mut contacts, &options);
        assert_eq!(
            (contacts[0].rate, contacts[0].rate_error),
            (f64::INFINITY, 0.0)
        );
        assert_eq!(
            (contacts[1].rate, contacts[1].rate_error),
            (f64::INFINITY, 0.0)
        );
        // The landing after the run takes the climb's rate, not the run's.
        for c in &contacts[2..] {
            assert!((c.rate - 0.2).abs() <= c.rate_error + 1e-12, "{c:?}");
            assert!(c.rate_error < 1e-4, "{c:?}");
        }
    }

    #[test]
    fn a_witness_switch_at_nearly_constant_travel_states_its_rounding() {
        // A climb at 0.0056 whose witness jumps 0.16 mm sideways between
        // two contacts 2e-5 mm apart in travel and one jump_tolerance apart
        // in level (where the bisection stops): measured on a crease of a
        // faceted bulge. The chord's slope, 0.05, is rounding: it must come
        // with an error at least as large, never as a decided strike.
        let options = OracleOptions {
            witness_tolerance: 0.05,
            ..OracleOptions::default()
        };
        let g = 0.0056;
        let point = |s: f64, level: f64, w: [f64; 3]| ContactPoint {
            travel: s,
            face_level: level,
            witness: w,
            rate: f64::NAN,
            rate_error: f64::NAN,
        };
        let mut contacts = vec![
            point(10.0, -g * 10.0, [-10.0, 0.0, 0.0]),
            point(10.02, -g * 10.02, [-10.02, 0.0, 0.0]),
            point(
                10.02002,
                -g * 10.02 - options.jump_tolerance,
                [-10.135, 0.0, -0.08],
            ),
            point(
                10.04,
                -g * 10.04 - options.jump_tolerance,
                [-10.155, 0.0, -0.08],
            ),
        ];
        deflection_rates(0.0, [0.0, 0.0, 0.0], &mut contacts, &options);
        for c in &contacts[1..3] {
            assert!(c.rate > 0.04, "{c:?}");
            assert!(
                c.rate - c.rate_error <= 2.0 * g,
                "rounding taken for a rate: {c:?}"
            );
        }
    }
}
