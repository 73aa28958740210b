//! SPEC's strike rule (Step 2, slide, rules 1 and 2): which contacts of a
//! slide are colliding points.
//!
//! A node met by the knee-form at face level `f` is a **contact** when it
//! sticks out past the face by more than the rounding tolerance `e0`
//! (`h < f - e0`), and a contact is a **strike** when the knee-form is
//! turned aside by more than `delta` (`sigma = tan(delta)`), measured by
//! one of two rules:
//!
//! * **window** (SPEC's default): the level dropped by more than
//!   `sigma * W` over the last `W` mm of travel, `f(s - W) - h > sigma W`,
//!   where `f(s - W)` is the start's own level after every earlier group
//!   whose travel is `<= s - W + 1e-9` (the pushed level `yr` where there
//!   is none) and `W` the **deflection window** (`--window`, mm);
//! * **x-slope** (SPEC's former baseline, kept so that implementations can
//!   be compared node for node): `r = (h[i+1][j] - h) / p`, the rise of
//!   the surface from the node one pitch behind it in the same row, or
//!   `(f - h) / p` where that node is `+inf` (off the part), above `sigma`.
//!
//! The knee-form strikes a surface that turns it aside; one it merely
//! brushes, nearly parallel to its motion, is not a strike. Every test is
//! monotone in each level it reads (the level at the node, and under the
//! window the level `W` earlier): a higher level strikes at least what a
//! lower one does, which is what lets the fast path keep per node the
//! highest level that met it, and per start the newest level only.
//!
//! Every implementation (fast, paper-literal, the harness's per-start
//! trace) evaluates the rule through [`StrikeRule::is_contact`],
//! [`StrikeRule::window_strikes`] and [`StrikeRule::strikes`], so the same
//! floating-point expression decides everywhere; the integration tests
//! compare them with an independent transcription.

use serde::{Deserialize, Serialize};

/// How a grid contact's deflection is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RateEstimate {
    /// SPEC's default: the drop of the start's own level over the last
    /// `W` mm of travel (the deflection window), against `sigma * W`. A
    /// fixed length, independent of the pitch, so the grid's level error
    /// moves the measured rate by about `p / W` and the grid converges to
    /// the exact rule.
    #[default]
    Window,
    /// SPEC's former baseline, comparable node for node with any
    /// implementation of it: the rise of the surface from the node one
    /// pitch behind the contact, `(h[i+1][j] - h) / p` (`(f - h) / p`
    /// where that node is off the part).
    XSlope,
}

impl RateEstimate {
    /// Every rule, as `--rate` offers them.
    pub const ALL: [RateEstimate; 2] = [RateEstimate::Window, RateEstimate::XSlope];

    /// The name, as `--rate` takes it and `summary.json` records it.
    pub fn name(self) -> &'static str {
        match self {
            RateEstimate::Window => "window",
            RateEstimate::XSlope => "x-slope",
        }
    }
}

/// Which level the knee-form's face follows (SPEC v4, "The level follows
/// the grid's surface"): the nodes only, or the grid's piecewise-linear
/// surface between them. It travels with the rule, so every run, study
/// and summary that records the rule records it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Level {
    /// SPEC's default until the gate holds: the level drops only at the
    /// nodes the slide meets.
    #[default]
    Node,
    /// The minimum of the grid's surface `S` over the swept footprint,
    /// evaluated as SPEC v4 says (the crate's `surface` module); window rule only,
    /// fast algorithm and the slide approach only.
    Surface,
}

impl Level {
    /// Every level, as `--level` offers them.
    pub const ALL: [Level; 2] = [Level::Node, Level::Surface];

    /// The name, as `--level` takes it and every summary records it.
    pub fn name(self) -> &'static str {
        match self {
            Level::Node => "node",
            Level::Surface => "surface",
        }
    }
}

/// What the rule reads of one node met by a slide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Meeting {
    /// The node's height `h` (mm, analysis y).
    pub h: f64,
    /// The height of the node one pitch behind it (+x) in its row, `+inf`
    /// off the part or past the grid (read by `x-slope` only).
    pub behind: f64,
    /// The face level `f` the node is met at: the level before its tie
    /// group (mm).
    pub level: f64,
    /// The start's level `W` mm of travel earlier, `f(s - W)` (mm; read by
    /// `window` only).
    pub earlier: f64,
    /// The grid pitch `p` (mm).
    pub pitch: f64,
}

/// SPEC's strike rule: the rounding tolerance `e0`, the deflection
/// threshold `sigma = tan(delta)`, how the deflection is measured and over
/// which window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StrikeRule {
    /// Rounding tolerance (mm, >= 0): a node is a contact when it sticks
    /// out past the face level by more than this.
    pub e0: f64,
    /// Deflection threshold as a rate, `tan(delta)` (>= 0): a contact is a
    /// strike when the surface turns the knee-form aside faster than this.
    pub sigma: f64,
    /// How the deflection is measured.
    pub rate: RateEstimate,
    /// The deflection window `W` (mm, > 0) of [`RateEstimate::Window`].
    #[serde(default = "default_window")]
    pub window: f64,
    /// The level the face follows (`node` where a file predates it).
    #[serde(default)]
    pub level: Level,
}

fn default_window() -> f64 {
    StrikeRule::DEFAULT_WINDOW_MM
}

impl StrikeRule {
    /// SPEC's default deflection threshold `delta` (degrees).
    pub const DEFAULT_DEFLECTION_DEG: f64 = 0.5;
    /// SPEC's default rounding tolerance `e0` (mm).
    pub const DEFAULT_E0: f64 = 1e-6;
    /// SPEC's default deflection window `W` (mm): the smallest of 2, 5 and
    /// 10 mm that tamed the tilted wave's undecided strikes (SPEC, "Why a
    /// window").
    pub const DEFAULT_WINDOW_MM: f64 = 5.0;
    /// How far (mm) a group's travel may lie past `s - W` and still count
    /// as `W` behind: SPEC's tolerance, so that travels equal in exact
    /// arithmetic (a window that is a multiple of the pitch) agree whatever
    /// their rounding.
    pub const WINDOW_TOL: f64 = 1e-9;

    /// The window rule for a deflection threshold of `deflection_deg`
    /// degrees (in `[0, 90)`), a rounding tolerance of `e0` mm and SPEC's
    /// default window.
    pub fn new(deflection_deg: f64, e0: f64) -> StrikeRule {
        StrikeRule {
            e0,
            sigma: deflection_deg.to_radians().tan(),
            rate: RateEstimate::default(),
            window: Self::DEFAULT_WINDOW_MM,
            level: Level::Node,
        }
    }

    /// The same rule with the deflection measured by `rate`.
    pub fn with_rate(self, rate: RateEstimate) -> StrikeRule {
        StrikeRule { rate, ..self }
    }

    /// The same rule with the face following `level`.
    pub fn with_level(self, level: Level) -> StrikeRule {
        StrikeRule { level, ..self }
    }

    /// The same rule with the deflection window `window` (mm).
    pub fn with_window(self, window: f64) -> StrikeRule {
        StrikeRule { window, ..self }
    }

    /// The deflection threshold `delta` (degrees): the shortest decimal
    /// whose tangent is this rule's `sigma`, so that a threshold given as
    /// 3 degrees reads back as 3, not as the round trip's
    /// 3.0000000000000004.
    pub fn deflection_deg(&self) -> f64 {
        let delta = self.sigma.atan().to_degrees();
        (1..=17)
            .filter_map(|digits| format!("{delta:.*e}", digits - 1).parse::<f64>().ok())
            .find(|d| d.to_radians().tan() == self.sigma)
            .unwrap_or(delta)
    }

    /// The window in mm as recorded (`window_mm`): the window rule's `W`,
    /// `None` under `x-slope`, which has none.
    pub fn window_mm(&self) -> Option<f64> {
        (self.rate == RateEstimate::Window).then_some(self.window)
    }

    /// Whether the node of height `h`, met at face level `level`, is a
    /// contact: it sticks out past the face by more than `e0`. Monotone in
    /// `level`.
    #[inline(always)]
    pub fn is_contact(&self, h: f64, level: f64) -> bool {
        h < level - self.e0
    }

    /// Under the window rule, whether a node of height `h` passes the
    /// deflection test against the level `earlier`, `W` mm of travel
    /// before it: `f(s - W) - h > sigma W`. Monotone in `earlier`.
    #[inline(always)]
    pub fn window_strikes(&self, h: f64, earlier: f64) -> bool {
        earlier - h > self.sigma * self.window
    }

    /// SPEC's former baseline rate of a contact: the rise `behind - h` of
    /// the surface over one pitch `p` from the node behind it, or
    /// `level - h` over `p` where that node is off the part (`+inf`).
    #[inline(always)]
    pub fn x_slope(h: f64, behind: f64, level: f64, p: f64) -> f64 {
        let from = if behind == f64::INFINITY {
            level
        } else {
            behind
        };
        (from - h) / p
    }

    /// Whether the node met as `m` is a strike. Monotone in `m.level` and
    /// in `m.earlier`.
    #[inline(always)]
    pub fn strikes(&self, m: Meeting) -> bool {
        self.is_contact(m.h, m.level)
            && match self.rate {
                RateEstimate::Window => self.window_strikes(m.h, m.earlier),
                RateEstimate::XSlope => Self::x_slope(m.h, m.behind, m.level, m.pitch) > self.sigma,
            }
    }
}

impl Default for StrikeRule {
    fn default() -> Self {
        StrikeRule::new(Self::DEFAULT_DEFLECTION_DEG, Self::DEFAULT_E0)
    }
}

/// A start's level history along its slide, for the window rule's
/// `f(s - W)`: the level after each tie group (or after each that lowered
/// it), by increasing travel. What the per-start implementations (the
/// paper-literal path, the harness's trace, the fast path's scalar
/// slides) share. `L` is a level: a height in mm or its rank.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelHistory<L = f64> {
    /// `(travel, level after the group)` per group so far.
    groups: Vec<(f64, L)>,
    /// How many of `groups` lie at least `W` behind the last group asked.
    behind: usize,
    /// The pushed level `yr`.
    pushed: L,
}

impl<L: Copy> LevelHistory<L> {
    /// An empty history of a start pushed to `yr`.
    pub fn new(yr: L) -> LevelHistory<L> {
        LevelHistory {
            groups: Vec::new(),
            behind: 0,
            pushed: yr,
        }
    }

    /// SPEC's `f(s - W)` for the group at travel `s` (asked by
    /// non-decreasing travel): the level after every earlier group whose
    /// travel is `<= s - W + 1e-9`, `yr` where there is none.
    pub fn earlier(&mut self, s: f64, window: f64) -> L {
        let limit = s - window + StrikeRule::WINDOW_TOL;
        while self.behind < self.groups.len() && self.groups[self.behind].0 <= limit {
            self.behind += 1;
        }
        match self.behind {
            0 => self.pushed,
            n => self.groups[n - 1].1,
        }
    }

    /// Records the group at travel `s` that left the level at `level`.
    pub fn push(&mut self, s: f64, level: L) {
        self.groups.push((s, level));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn met(h: f64, behind: f64, level: f64, earlier: f64, pitch: f64) -> Meeting {
        Meeting {
            h,
            behind,
            level,
            earlier,
            pitch,
        }
    }

    #[test]
    fn x_slope_is_the_rise_from_the_node_behind_or_from_the_level_off_the_part() {
        assert_eq!(StrikeRule::x_slope(1.0, 3.0, 10.0, 2.0), 1.0);
        assert_eq!(StrikeRule::x_slope(1.0, f64::INFINITY, 10.0, 2.0), 4.5);
        assert_eq!(StrikeRule::default().rate, RateEstimate::Window);
        assert_eq!(StrikeRule::default().window, 5.0);
    }

    #[test]
    fn an_x_slope_contact_strikes_only_above_the_threshold() {
        let rule = StrikeRule::new(45.0, 1e-6).with_rate(RateEstimate::XSlope);
        assert!((rule.sigma - 1.0).abs() < 1e-12);
        // Rise 2 over pitch 1: rate 2 > 1.
        assert!(rule.strikes(met(0.0, 2.0, 5.0, 5.0, 1.0)));
        // Rise 0.5 over pitch 1: a contact, but too gentle.
        assert!(!rule.strikes(met(0.0, 0.5, 5.0, 5.0, 1.0)));
        // Not below the level by more than e0: no contact at all.
        assert!(!rule.strikes(met(5.0 - 1e-7, 100.0, 5.0, 5.0, 1.0)));
        // Off the part behind: the drop from the level decides.
        assert!(rule.strikes(met(0.0, f64::INFINITY, 1.5, 1.5, 1.0)));
        assert!(!rule.strikes(met(0.0, f64::INFINITY, 0.5, 0.5, 1.0)));
    }

    #[test]
    fn a_window_contact_strikes_when_the_level_dropped_more_than_sigma_w() {
        // sigma 0.1 over W = 5: a drop of more than 0.5 mm.
        let rule = StrikeRule {
            e0: 1e-6,
            sigma: 0.1,
            rate: RateEstimate::Window,
            window: 5.0,
            level: Level::Node,
        };
        assert!(rule.strikes(met(0.0, 0.0, 0.2, 0.6, 1.0)));
        assert!(!rule.strikes(met(0.0, 0.0, 0.2, 0.4, 1.0)));
        // The x-slope is not read: a steep rise behind changes nothing.
        assert!(!rule.strikes(met(0.0, 100.0, 0.2, 0.4, 1.0)));
        // A contact is still needed, however far the level dropped.
        assert!(!rule.strikes(met(0.0, 0.0, 0.0, 9.0, 1.0)));
        assert_eq!(rule.window_mm(), Some(5.0));
        assert_eq!(rule.with_rate(RateEstimate::XSlope).window_mm(), None);
    }

    #[test]
    fn zero_deflection_strikes_any_contact_under_the_window() {
        let rule = StrikeRule::new(0.0, 1e-6);
        assert!(rule.strikes(met(0.0, 0.0, 1e-5, 1e-5, 1.0)));
        assert!(!rule.strikes(met(0.0, 0.0, 1e-7, 1.0, 1.0)));
        assert!((StrikeRule::default().deflection_deg() - 0.5).abs() < 1e-12);
        // Issue 24, item 5: no float noise in what is recorded.
        for given in [0.0, 0.5, 3.0, 0.1, 44.9, 1.0 / 3.0] {
            let rule = StrikeRule::new(given, 1e-6);
            assert_eq!(rule.deflection_deg(), given, "{given}");
        }
    }

    #[test]
    fn the_level_w_earlier_is_read_after_the_last_group_that_far_behind() {
        let mut history = LevelHistory::new(10.0);
        // Before W of travel: the pushed level.
        assert_eq!(history.earlier(1.0, 5.0), 10.0);
        history.push(1.0, 9.0);
        history.push(3.0, 7.0);
        assert_eq!(history.earlier(5.9, 5.0), 10.0);
        // Exactly W behind (within 1e-9) counts as behind.
        assert_eq!(history.earlier(6.0 - 5e-10, 5.0), 9.0);
        history.push(6.0, 6.0);
        assert_eq!(history.earlier(7.5, 5.0), 9.0);
        assert_eq!(history.earlier(8.0, 5.0), 7.0);
        assert_eq!(history.earlier(100.0, 5.0), 6.0);
    }

    #[test]
    fn strikes_are_monotone_in_both_levels() {
        let rules = [RateEstimate::XSlope, RateEstimate::Window]
            .map(|r| StrikeRule::default().with_rate(r));
        for (rule, behind) in rules
            .iter()
            .flat_map(|r| [f64::INFINITY, 0.0, 0.004, 0.02].map(|b| (r, b)))
        {
            for earlier_k in [0, 100, 500, 2000] {
                let mut struck = false;
                for k in 0..2000 {
                    let level = k as f64 * 1e-4;
                    let earlier = level.max(earlier_k as f64 * 1e-4);
                    let s = rule.strikes(met(0.0, behind, level, earlier, 1.0));
                    assert!(s || !struck, "struck at a lower level only");
                    struck |= s;
                }
            }
        }
    }
}
