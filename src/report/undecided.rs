//! Where a verification says the grid's boundary is undecided, on the
//! report's first page: `verify.json`'s `undecided_nodes` (the nodes of
//! the verified grid nearest an undecided exact contact, a
//! [`NodeRuns`]) read back, drawn hatched over the face-on picture with
//! its legend entry, and the struck zones an undecided node touches
//! ([`crate::zones::touched_by`]).
//!
//! **Invariant:** the zones are flagged only from a verification of the
//! run's own grid (the same pitch: grids sit on the lattice, so its nodes
//! are the run's). The report refuses a `verify.json` of another pitch
//! anyway; a record of another pitch is neither hatched nor put against
//! the zones.

use maud::{Markup, html};
use serde_json::Value;

use super::html::{SUP2, cite, svg_empty};
use super::render::View;
use super::run::Run;
use super::verify::Verification;
use crate::frame::Approach;
use crate::zones::NodeRuns;

/// The id of the hatched overlay on the face-on picture.
pub(crate) const OVERLAY_ID: &str = "undecided-overlay";

/// The undecided nodes of one verification.
pub(crate) struct Undecided<'a> {
    /// Which verification (0 for the first given).
    pub k: usize,
    /// Its `verify.json`, for citations.
    pub json: &'a Value,
    /// Its undecided nodes, on the run's grid.
    pub runs: NodeRuns,
}

impl<'a> Undecided<'a> {
    /// The undecided nodes of the first verification of `verifications`
    /// that records them on the run's grid (pitch `pitch`, mm); `None`
    /// when none does (a convergence study, or a file of an earlier
    /// version).
    pub fn of(verifications: &'a [Verification], pitch: f64) -> Option<Undecided<'a>> {
        verifications.iter().enumerate().find_map(|(k, v)| {
            let json = v.verify.as_ref()?;
            let runs: NodeRuns =
                serde_json::from_value(json.get("undecided_nodes")?.clone()).ok()?;
            let same_grid = (runs.pitch_mm - pitch).abs() <= 1e-9 * pitch;
            same_grid.then_some(Undecided { k, json, runs })
        })
    }

    /// The file its figures are cited from.
    fn file(&self) -> String {
        super::verify::verify_label(self.k, "verify.json")
    }

    /// For each of the run's zones (`summary.json`'s, in their order),
    /// whether an undecided node is on or 8-adjacent to one of its nodes;
    /// `None` when the run's composite does not give its zones back (a run
    /// of an earlier version lists none).
    pub fn zones_touched(&self, run: &Run) -> Option<Vec<bool>> {
        let spec = run.spec;
        let marked = self.runs.mask_on(&spec)?;
        let members = crate::zones::components(&run.composite.count, spec.nx, spec.nz);
        let zones = &run.summary.zones;
        let same = members.len() == zones.len()
            && members.iter().zip(zones).all(|(m, z)| m.len() == z.nodes);
        same.then(|| crate::zones::touched_by(&members, spec.nx, spec.nz, &marked))
    }

    /// The undecided nodes' cells hatched over the face-on picture `view`
    /// of `run`, as an SVG laid on it as the axes are; nothing for the
    /// direct approach (its verification records no undecided nodes) or
    /// when no node is undecided.
    pub fn overlay_svg(&self, run: &Run, view: &View) -> Markup {
        if run.summary.approach != Approach::Slide || self.runs.runs.is_empty() {
            return html! {};
        }
        let (w, h) = (view.width as f64, view.height as f64);
        let sign = view.horizontal_sign();
        let (p, mm) = (self.runs.pitch_mm, view.mm_per_px);
        let column = |x: f64| (sign * x - view.u_left) / mm;
        let mut path = String::new();
        for &[row, first, last] in &self.runs.runs {
            let (a, b) = (
                column((first as f64 - 0.5) * p),
                column((last as f64 + 0.5) * p),
            );
            let (left, width) = (a.min(b), (a - b).abs());
            let top = (view.v_top - (row as f64 + 0.5) * p) / mm;
            let height = p / mm;
            let outside = left > w || left + width < 0.0 || top > h || top + height < 0.0;
            if !outside {
                path.push_str(&format!(
                    "M{left:.1} {top:.1}h{width:.1}v{height:.1}h{:.1}z",
                    -width
                ));
            }
        }
        html! {
            svg class="axes-overlay" id=(OVERLAY_ID) style="overflow:hidden" viewBox=(format!("0 0 {w} {h}")) role="img"
                aria-label="hatched: where the grid's boundary is undecided" {
                defs { (hatch("undecided-hatch")) }
                (svg_empty("path", &[("d", &path), ("fill", &"url(#undecided-hatch)"), ("stroke", &"#000"), ("stroke-opacity", &"0.5"), ("stroke-width", &"0.5")]))
            }
        }
    }

    /// The legend entry of [`Undecided::overlay_svg`], for the picture's
    /// caption.
    pub fn legend(&self) -> Markup {
        let file = self.file();
        let c = |p: &str| cite(&file, self.json, p);
        html! {
            " "
            span id="undecided-legend" {
                svg width="18" height="12" viewBox="0 0 18 12" role="img" aria-label="hatching" style="vertical-align:middle" {
                    defs { (hatch("undecided-hatch-key")) }
                    (svg_empty("rect", &[("x", &"0.5"), ("y", &"0.5"), ("width", &"17"), ("height", &"11"), ("fill", &"url(#undecided-hatch-key)"), ("stroke", &"#000")]))
                }
                " Hatched: where the grid's boundary is undecided (verification " (self.k + 1)
                ": the cells of the " (c("/undecided_nodes/nodes"))
                " nodes nearest an exact contact in the tie band, "
                (c("/undecided_area_mm2")) " mm" (SUP2)
                "): either answer is right there at this pitch. Only where its starts slid: elsewhere unknown."
            }
        }
    }
}

/// The hatching: dark diagonal lines 4 px apart, the colours beneath
/// still seen between them.
fn hatch(id: &str) -> Markup {
    html! {
        pattern id=(id) patternUnits="userSpaceOnUse" width="4" height="4" patternTransform="rotate(45)" {
            (svg_empty("line", &[("x1", &"0"), ("y1", &"0"), ("x2", &"0"), ("y2", &"4"), ("stroke", &"#111"), ("stroke-width", &"1.5")]))
        }
    }
}
