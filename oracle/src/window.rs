//! SPEC's window rule on the exact trace ("Exact strikes"): a contact of
//! the traced level curve at travel `s` is a strike when the knee-form's
//! level dropped by more than `sigma * W` over the last `W` mm,
//! `f*(s - W) - f*(s) > sigma W`, with `f*(s - W) = yr*` for `s < W`.
//!
//! **The curve between samples.** A trace samples `f*` at the push pose
//! `(0, yr*)` and at its contacts, by increasing travel. Between two
//! samples the curve is taken as the straight line joining them (SPEC:
//! "interpolated between its samples"). Past the last contact the
//! knee-form has cleared the part and its level no longer changes.
//!
//! **How well that is known.** `f*` only falls, so between samples `a`
//! and `b` it lies in `[f_b, f_a]` whatever its shape: the interpolated
//! value is off by at most the larger distance to those ends. That is the
//! drop's stated error ([`WindowDrop::error`]); a sample itself (a cast's
//! contact) is exact up to the casts' `jump_tolerance`, which is added.
//! The tracer bisects wherever consecutive witnesses lie further apart
//! than `witness_tolerance`, so the bracket is small where the curve
//! moves and zero along a straight run.

use crate::trace::{StartStatus, StartTrace};

/// The level curve `f*(s)` of a placed start, read between its samples.
#[derive(Debug, Clone, Copy)]
pub struct LevelCurve<'a> {
    trace: &'a StartTrace,
    yr: f64,
}

/// A level of the curve and the interval that surely holds it (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// The interpolated level.
    pub value: f64,
    /// The lowest the level can be: the next sample's.
    pub lowest: f64,
    /// The highest: the previous sample's.
    pub highest: f64,
}

/// The window drop at one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowDrop {
    /// `f*(s - W) - f*(s)` (mm), the curve interpolated between samples.
    pub drop: f64,
    /// The drop's stated error (mm): the true drop lies within
    /// `drop +- error`.
    pub error: f64,
}

impl<'a> LevelCurve<'a> {
    /// The curve of `trace`, when it is placed (a start that is not placed
    /// or failed has none to read).
    pub fn of(trace: &'a StartTrace) -> Option<LevelCurve<'a>> {
        match (trace.status, trace.yr_star) {
            (StartStatus::Placed, Some(yr)) => Some(LevelCurve { trace, yr }),
            _ => None,
        }
    }

    /// The level at travel `s` (mm): `yr*` up to travel 0, the last
    /// contact's past the last contact, the straight line between the two
    /// samples around `s` elsewhere (at a travel shared by several samples,
    /// a riser, the first of them: the knee-form touches the riser at its
    /// upper level).
    pub fn at(&self, s: f64) -> Level {
        let exact = |f: f64| Level {
            value: f,
            lowest: f,
            highest: f,
        };
        let contacts = &self.trace.contacts;
        if s <= 0.0 || contacts.is_empty() {
            return exact(if s <= 0.0 || contacts.is_empty() {
                self.yr
            } else {
                contacts[contacts.len() - 1].face_level
            });
        }
        // The first contact at or past s.
        let next = contacts.partition_point(|c| c.travel < s);
        let Some(b) = contacts.get(next) else {
            return exact(contacts[contacts.len() - 1].face_level);
        };
        let (sa, fa) = match next {
            0 => (0.0, self.yr),
            n => (contacts[n - 1].travel, contacts[n - 1].face_level),
        };
        let (sb, fb) = (b.travel, b.face_level);
        if sb - sa <= 0.0 || s >= sb {
            return exact(fb.max(if s >= sb { fb } else { fa }));
        }
        let t = (s - sa) / (sb - sa);
        Level {
            value: fa + (fb - fa) * t,
            lowest: fb.min(fa),
            highest: fa.max(fb),
        }
    }

    /// The window drop at contact `k` over a window of `window` mm, with
    /// the casts' tolerance `jump_tolerance` (mm) added to its error.
    pub fn drop_at(&self, k: usize, window: f64, jump_tolerance: f64) -> WindowDrop {
        let c = &self.trace.contacts[k];
        let back = self.at(c.travel - window);
        WindowDrop {
            drop: back.value - c.face_level,
            error: (back.value - back.lowest).max(back.highest - back.value) + 2.0 * jump_tolerance,
        }
    }
}

impl StartTrace {
    /// The strikes of a placed start by SPEC's window rule: its contacts
    /// whose level dropped by more than `sigma * window` over the last
    /// `window` mm of travel, the curve interpolated between samples
    /// ([`LevelCurve`]), in the order of the slide.
    ///
    /// A start that is not placed has none. A failed start's strikes are
    /// unknown, not absent: that is an error, as for
    /// [`StartTrace::strikes`].
    pub fn window_strikes(
        &self,
        sigma: f64,
        window: f64,
    ) -> Result<Vec<&crate::ContactPoint>, crate::FailureReason> {
        match self.status {
            StartStatus::Failed { reason } => Err(reason),
            StartStatus::NotPlaced => Ok(Vec::new()),
            StartStatus::Placed => {
                let Some(curve) = LevelCurve::of(self) else {
                    return Ok(Vec::new());
                };
                Ok((0..self.contacts.len())
                    .filter(|&k| curve.drop_at(k, window, 0.0).drop > sigma * window)
                    .map(|k| &self.contacts[k])
                    .collect())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::{ContactPoint, SlideEnd};

    fn trace(yr: f64, points: &[(f64, f64)]) -> StartTrace {
        StartTrace {
            angle_deg: 0.0,
            start: [0.0, 0.0],
            status: StartStatus::Placed,
            yr_star: Some(yr),
            push_witness: Some([0.0, yr, 0.0]),
            contacts: points
                .iter()
                .map(|&(travel, face_level)| ContactPoint {
                    travel,
                    face_level,
                    witness: [-travel, face_level, 0.0],
                    rate: 0.0,
                    rate_error: 0.0,
                })
                .collect(),
            slide_end: SlideEnd::Cleared,
            casts: 0,
        }
    }

    #[test]
    fn the_curve_is_interpolated_between_samples_and_bracketed_by_them() {
        let t = trace(10.0, &[(2.0, 10.0), (4.0, 9.0), (4.0, 7.0), (8.0, 5.0)]);
        let c = LevelCurve::of(&t).unwrap();
        assert_eq!(c.at(-1.0).value, 10.0);
        assert_eq!(c.at(1.0).value, 10.0);
        let mid = c.at(3.0);
        assert_eq!((mid.value, mid.lowest, mid.highest), (9.5, 9.0, 10.0));
        // At a riser, the upper level.
        assert_eq!(c.at(4.0).value, 9.0);
        assert_eq!(c.at(6.0).value, 6.0);
        // Past the last contact, the level stays.
        assert_eq!(c.at(100.0).value, 5.0);
    }

    #[test]
    fn a_window_strike_is_a_drop_of_more_than_sigma_w() {
        // A slope of 0.2 from travel 2: over W = 5, a drop of 1 at s = 7.
        let t = trace(
            10.0,
            &[(2.0, 10.0), (3.0, 9.8), (5.0, 9.4), (7.0, 9.0), (9.0, 9.0)],
        );
        let c = LevelCurve::of(&t).unwrap();
        let d = c.drop_at(3, 5.0, 0.0);
        assert!((d.drop - 1.0).abs() < 1e-12, "{d:?}");
        // s - W = 2 is a sample: known exactly.
        assert!(d.error < 1e-12);
        // Interpolated between samples 2 and 3 at s - W = 2.5... here 4.
        let d = c.drop_at(4, 5.0, 0.0);
        assert!(
            (d.drop - 0.6).abs() < 1e-12 && (d.error - 0.2).abs() < 1e-12,
            "{d:?}"
        );
        let strikes: Vec<f64> = t
            .window_strikes(0.15, 5.0)
            .unwrap()
            .iter()
            .map(|c| c.travel)
            .collect();
        // Drops: 0, 0.2, 0.6, 1.0, 0.6 against 0.75.
        assert_eq!(strikes, vec![7.0]);
        let failed = StartTrace {
            status: StartStatus::Failed {
                reason: crate::FailureReason::CastNotConverged,
            },
            ..t
        };
        assert!(failed.window_strikes(0.15, 5.0).is_err());
    }
}
