//! SPEC's strike rule (Step 2, slide, rules 1 and 2): which contacts of a
//! slide are colliding points.
//!
//! A node met by the knee-form at face level `f` is a **contact** when it
//! sticks out past the face by more than the rounding tolerance `e0`
//! (`h < f - e0`), and a contact is a **strike** when its **deflection
//! rate** exceeds `sigma = tan(delta)`:
//!
//! * `r = (h[i+1][j] - h) / p`, the rise of the surface from the node one
//!   pitch behind it in the same row (the node the knee-form met just
//!   before);
//! * `r = (f - h) / p` where that node is `+inf` (off the part).
//!
//! The knee-form strikes a surface that turns it aside by more than
//! `delta`; one it merely brushes, nearly parallel to its motion, is not a
//! strike. Both conditions are monotone in `f` (a higher level strikes at
//! least what a lower one does), which is what lets the fast path keep each
//! node's highest level ("reach") and decide once per angle.
//!
//! Every implementation (fast, paper-literal, the harness's per-start
//! trace) evaluates the rule through [`StrikeRule::strikes`], so the same
//! floating-point expression decides everywhere; the integration tests
//! compare them with an independent transcription.

use serde::{Deserialize, Serialize};

/// How a grid contact's deflection rate is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum RateEstimate {
    /// SPEC's baseline (the default, comparable node for node with any
    /// implementation of SPEC): the rise of the surface from the node one
    /// pitch behind the contact, `(h[i+1][j] - h) / p` (`(f - h) / p`
    /// where that node is off the part).
    #[default]
    XSlope,
    /// The x-slope, capped by how far the contact turns the knee-form
    /// aside over one pitch: `min(x-slope, (f - h) / p)`. A node that
    /// sticks out past the level only a little is no strike however steep
    /// the surface behind it (a crest the knee-form crosses nearly level, a
    /// crease its edge rides along); on a steady slope and at a riser both
    /// are the same. Still monotone in `f`. Measured (`results/README.md`):
    /// it removes the near-level false alarms of the tilted wave but delays
    /// strikes where footprint rows interleave (each node then sticks out
    /// past a level its neighbour rows just set by less than `sigma p`),
    /// so it is not the default.
    Capped,
}

impl RateEstimate {
    /// The name, as `--rate` takes it and `summary.json` records it.
    pub fn name(self) -> &'static str {
        match self {
            RateEstimate::XSlope => "x-slope",
            RateEstimate::Capped => "capped",
        }
    }
}

/// SPEC's strike rule: the rounding tolerance `e0`, the deflection
/// threshold `sigma = tan(delta)` and how a contact's rate is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StrikeRule {
    /// Rounding tolerance (mm, >= 0): a node is a contact when it sticks
    /// out past the face level by more than this.
    pub e0: f64,
    /// Deflection threshold as a rate, `tan(delta)` (>= 0): a contact is a
    /// strike when the surface turns the knee-form aside faster than this.
    pub sigma: f64,
    /// The rate estimate.
    pub rate: RateEstimate,
}

impl StrikeRule {
    /// SPEC's default deflection threshold `delta` (degrees).
    pub const DEFAULT_DEFLECTION_DEG: f64 = 0.5;
    /// SPEC's default rounding tolerance `e0` (mm).
    pub const DEFAULT_E0: f64 = 1e-6;

    /// The rule for a deflection threshold of `deflection_deg` degrees
    /// (in `[0, 90)`) and a rounding tolerance of `e0` mm.
    pub fn new(deflection_deg: f64, e0: f64) -> StrikeRule {
        StrikeRule {
            e0,
            sigma: deflection_deg.to_radians().tan(),
            rate: RateEstimate::default(),
        }
    }

    /// The same rule with the rate estimated by `rate`.
    pub fn with_rate(self, rate: RateEstimate) -> StrikeRule {
        StrikeRule { rate, ..self }
    }

    /// The deflection threshold `delta` (degrees).
    pub fn deflection_deg(&self) -> f64 {
        self.sigma.atan().to_degrees()
    }

    /// SPEC's baseline rate of a contact: the rise `behind - h` of the
    /// surface over one pitch `p` from the node behind it, or `level - h`
    /// over `p` where that node is off the part (`+inf`).
    #[inline(always)]
    pub fn x_slope(h: f64, behind: f64, level: f64, p: f64) -> f64 {
        let from = if behind == f64::INFINITY {
            level
        } else {
            behind
        };
        (from - h) / p
    }

    /// The rate of a contact under this rule's estimate.
    #[inline(always)]
    pub fn rate(&self, h: f64, behind: f64, level: f64, p: f64) -> f64 {
        let x_slope = Self::x_slope(h, behind, level, p);
        match self.rate {
            RateEstimate::XSlope => x_slope,
            RateEstimate::Capped => x_slope.min((level - h) / p),
        }
    }

    /// Whether the node of height `h`, with `behind` the height of the node
    /// one pitch behind it in its row (`+inf` off the part), met by the
    /// knee-form at face level `level` on a grid of pitch `p`, is a strike.
    /// Monotone in `level` (both rates are non-decreasing in it).
    #[inline(always)]
    pub fn strikes(&self, h: f64, behind: f64, level: f64, p: f64) -> bool {
        h < level - self.e0 && self.rate(h, behind, level, p) > self.sigma
    }
}

impl Default for StrikeRule {
    fn default() -> Self {
        StrikeRule::new(Self::DEFAULT_DEFLECTION_DEG, Self::DEFAULT_E0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rate_is_the_rise_from_the_node_behind_or_from_the_level_off_the_part() {
        let x_slope = StrikeRule::default().with_rate(RateEstimate::XSlope);
        assert_eq!(x_slope.rate(1.0, 3.0, 10.0, 2.0), 1.0);
        assert_eq!(x_slope.rate(1.0, f64::INFINITY, 10.0, 2.0), 4.5);
        // Capped: a node 0.1 mm past the level, however steep behind it.
        assert_eq!(StrikeRule::default().rate, RateEstimate::XSlope);
        let capped = StrikeRule::default().with_rate(RateEstimate::Capped);
        assert!((capped.rate(1.0, 3.0, 1.1, 2.0) - 0.05).abs() < 1e-12);
        assert_eq!(capped.rate(1.0, 3.0, 10.0, 2.0), 1.0);
        assert_eq!(capped.rate(1.0, f64::INFINITY, 10.0, 2.0), 4.5);
    }

    #[test]
    fn a_contact_strikes_only_above_the_threshold() {
        let rule = StrikeRule::new(45.0, 1e-6).with_rate(RateEstimate::XSlope);
        assert!((rule.sigma - 1.0).abs() < 1e-12);
        // Rise 2 over pitch 1: rate 2 > 1.
        assert!(rule.strikes(0.0, 2.0, 5.0, 1.0));
        // Rise 0.5 over pitch 1: a contact, but too gentle.
        assert!(!rule.strikes(0.0, 0.5, 5.0, 1.0));
        // Not below the level by more than e0: no contact at all.
        assert!(!rule.strikes(5.0 - 1e-7, 100.0, 5.0, 1.0));
        // Off the part behind: the drop from the level decides.
        assert!(rule.strikes(0.0, f64::INFINITY, 1.5, 1.0));
        assert!(!rule.strikes(0.0, f64::INFINITY, 0.5, 1.0));
    }

    #[test]
    fn zero_deflection_strikes_any_rise() {
        let rule = StrikeRule::new(0.0, 1e-6).with_rate(RateEstimate::XSlope);
        assert!(rule.strikes(0.0, 1e-9, 1.0, 1.0));
        assert!(!rule.strikes(0.0, 0.0, 1.0, 1.0));
        assert!((StrikeRule::default().deflection_deg() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn strikes_are_monotone_in_the_level() {
        let rules = [RateEstimate::XSlope, RateEstimate::Capped]
            .map(|r| StrikeRule::default().with_rate(r));
        for (rule, behind) in rules
            .iter()
            .flat_map(|r| [f64::INFINITY, 0.0, 0.004, 0.02].map(|b| (r, b)))
        {
            let mut struck = false;
            for k in 0..2000 {
                let level = k as f64 * 1e-4;
                let s = rule.strikes(0.0, behind, level, 1.0);
                assert!(s || !struck, "struck at a lower level only");
                struck |= s;
            }
        }
    }
}
