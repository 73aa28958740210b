//! The report as one self-contained HTML page: images inline as `data:`
//! URIs, charts and legends as inline SVG, a print stylesheet, no network;
//! one script, the interactive 3D view's ([`super::view3d`]), which the
//! page does without.
//!
//! Sections, in order (each a `<section>` with this id):
//!
//! * `result`: the analysed side painted with the composite (the main
//!   image, `#main-view`), its legend, the oblique view, and the
//!   interactive 3D view (`#view3d`);
//! * `compare` (with `--compare`): a push-and-slide run and a direct one
//!   of the same part, both areas on one rendered part, and what only
//!   push-and-slide strikes;
//! * `part`: the part's identity (file, SHA-256, triangles, bounding box,
//!   units, frame; an assembly's files with each one's colliding area);
//! * `method`: the knee-form (the assumed triangle side called out), grid,
//!   angles, side, software version and run date;
//! * `per-angle`: small multiples at -30, 0 and +30 degrees, a chart and a
//!   table of the colliding area per angle;
//! * `accuracy`: each verification run's metrics against its tolerance
//!   with the verdict, the convergence study and its recommended pitch;
//! * `resolution`: what the grid cannot see at its pitch (the blind spots,
//!   also magenta on the main image), the pitch study when `--pitch auto`
//!   chose the pitch, and the one sentence a regulator reads;
//! * `runtime`: the run's timings;
//! * `run-figures`: the images the run wrote.

use maud::{DOCTYPE, Markup, PreEscaped, html};

use crate::frame::Approach;
use serde_json::Value;

use super::compare::{BOTH, Comparison, DIRECT_ONLY, MATCH_PITCHES, SLIDE_ONLY};
use super::html::{ASYMP, MIDDOT, NBSP, SUP2, TIMES, cite, fmt_num, png_uri, svg_empty, utc_date};
use super::run::Run;
use super::verify::{Verdict, Verification, escape_pointer, scalars, verify_label};
use super::views::{ANGLE_COLOUR, Figure, Views, composite_colour, ramp_len};

/// The border colour of the main image: a blue no part shading or ramp
/// colour takes, so the image can be found in a screenshot of the page.
pub const MAIN_BORDER: [u8; 3] = [0, 90, 181];

/// The file name the report cites the run's summary as.
pub(crate) const SUMMARY: &str = crate::output::SUMMARY_JSON;

/// Everything the page is made of.
pub(crate) struct Inputs<'a> {
    /// The run.
    pub run: &'a Run,
    /// The interactive 3D view's figure ([`super::view3d`]).
    pub view3d: Markup,
    /// The verification directories, in the order given.
    pub verifications: &'a [Verification],
    /// The rendered views, already PNG-encoded alongside.
    pub views: &'a Views,
    /// PNG of [`Views::side`], [`Views::oblique`] and each small multiple,
    /// in that order.
    pub pngs: &'a [Vec<u8>],
    /// Images the run wrote (file name, bytes).
    pub run_figures: &'a [(String, Vec<u8>)],
    /// The comparison with a run of the other approach, with the PNG of
    /// each of its figures.
    pub comparison: Option<(&'a Comparison, &'a [Vec<u8>])>,
    /// The comparison with an earlier revision of the part (`--compare`
    /// given a run of the same approach), with its picture's PNG.
    pub revision: Option<(&'a super::diff::RevisionDiff, &'a [u8])>,
}

/// The version of this build, as the page names it.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The whole page. The template writes no whitespace of its own: the line
/// breaks (`"\n"`) are the page's, one after each block, so that its
/// source reads line by line.
pub(crate) fn document(inputs: &Inputs) -> String {
    let run = inputs.run;
    let s = &run.summary;
    let j = &run.summary_json;
    let file_name = std::path::Path::new(&s.input_file).file_name().map_or_else(
        || s.input_file.clone(),
        |n| n.to_string_lossy().into_owned(),
    );
    let [br, bg, bb] = MAIN_BORDER;
    let style = format!("{STYLE}img.main {{ border: 5px solid rgb({br}, {bg}, {bb}); }}\n");
    html! {
        (DOCTYPE) "\n"
        html lang="en" {
            "\n"
            head {
                "\n"
                meta charset="utf-8";
                "\n"
                meta name="generator" content={ "kneeform " (VERSION) };
                "\n"
                title { "Knee-form collision evidence: " (file_name) }
                "\n"
                // CSS is not HTML text: written as it is.
                style { (PreEscaped(style)) }
                "\n"
            }
            "\n"
            body {
                "\n"
                header {
                    h1 { "Knee-form collision evidence" }
                    "\n"
                    p class="subtitle" {
                        (cite(SUMMARY, j, "/input_file")) " " (MIDDOT)
                        " UN Regulation No." (NBSP) "21 knee-form "
                        (approach_words(s.approach)) " "
                        (MIDDOT) " kneeform " (cite(SUMMARY, j, "/kneeform_version")) " " (MIDDOT)
                        " run of " (utc_date(s.run_unix_time))
                    }
                }
                "\n"
                @if let Some((d, png)) = inputs.revision {
                    (revision_section(d, png))
                }
                (result_section(inputs))
                @if let Some((c, pngs)) = inputs.comparison {
                    (compare_section(run, c, pngs))
                }
                (part_section(run))
                (method_section(run))
                (per_angle_section(inputs))
                (accuracy_section(inputs.verifications))
                (resolution_section(inputs))
                (runtime_section(run))
                (run_figures_section(inputs.run_figures))
                footer {
                    "Written by kneeform " (VERSION) " from the run directory "
                    (run.dir.display().to_string())
                    ". Every value marked with a source comes from the run's files ("
                    code { "data-src" } " gives the file and JSON pointer)."
                }
                "\n"
            }
            "\n"
        }
        "\n"
    }
    .into_string()
}

const STYLE: &str = "
body { font-family: 'DejaVu Sans', Verdana, Arial, sans-serif; color: #1a1a1a; max-width: 1180px; margin: 16px auto; padding: 0 12px; font-size: 14px; line-height: 1.4; }
h1 { font-size: 24px; margin: 0 0 4px 0; }
h2 { font-size: 18px; border-bottom: 1px solid #999; padding-bottom: 2px; margin-top: 28px; }
h3 { font-size: 15px; margin: 16px 0 6px 0; }
.subtitle { color: #444; margin: 0 0 12px 0; }
figure { margin: 8px 0 16px 0; break-inside: avoid; }
figcaption { font-size: 12px; color: #333; margin-top: 4px; }
img.view { display: block; max-width: 100%; height: auto; }
img.plot { max-width: 100%; height: auto; border: 1px solid #ccc; }
.multiples { display: grid; grid-template-columns: repeat(3, 1fr); gap: 10px; }
.multiples img { border: 1px solid #bbb; width: 100%; height: auto; }
table { border-collapse: collapse; margin: 6px 0 12px 0; break-inside: auto; }
tr { break-inside: avoid; }
th, td { border: 1px solid #bbb; padding: 2px 8px; text-align: left; vertical-align: top; }
td.num, th.num { text-align: right; font-variant-numeric: tabular-nums; }
code, .mono { font-family: 'DejaVu Sans Mono', monospace; font-size: 12px; word-break: break-all; }
.assumed { background: #fff3c4; border: 1px solid #c9a100; padding: 1px 6px; font-weight: bold; }
.pass { background: #dff3df; border: 2px solid #2e7d32; color: #1b5e20; padding: 4px 10px; font-weight: bold; display: inline-block; }
.fail { background: #fde0dc; border: 2px solid #c62828; color: #b71c1c; padding: 4px 10px; font-weight: bold; display: inline-block; }
.check { background: #f4f4f4; border-left: 4px solid #777; padding: 4px 10px; }
.unknown { background: #eee; border: 2px solid #777; padding: 4px 10px; font-weight: bold; display: inline-block; }
.inconclusive { background: #fff3c4; border: 2px solid #c9a100; color: #5d4500; padding: 4px 10px; font-weight: bold; display: inline-block; }
.warnings { background: #fff8e1; border-left: 4px solid #c9a100; padding: 4px 10px; margin: 6px 0; }
.warnings ul { margin: 2px 0; padding-left: 20px; }
.missing { color: #999; font-style: italic; }
.note { color: #333; font-size: 13px; }
.headline { font-size: 16px; }
footer { margin-top: 32px; font-size: 11px; color: #555; border-top: 1px solid #999; padding-top: 4px; }
* { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
table.csv-print { display: none; }
/* On screen a wide table (verify.csv's 27 columns) scrolls in its own box, not the page. */
@media screen {
  table.csv { display: block; overflow-x: auto; max-width: 100%; }
  table.csv caption { text-align: left; position: sticky; left: 0; max-width: 1150px; }
}
@page { size: A4; margin: 12mm; }
@media print {
  table.metrics { width: 100%; max-width: 100%; }
  table.metrics th, table.metrics td { overflow-wrap: anywhere; }
  table.csv { width: 100%; max-width: 100%; font-size: 6pt; }
  table.csv th, table.csv td { padding: 0 2px; overflow-wrap: anywhere; }
  table.csv:has(+ table.csv-print) { display: none; }
  table.csv-print { display: table; width: 100%; max-width: 100%; font-size: 5.5pt; margin: 2px 0 4px 0; }
  table.csv-print caption { text-align: left; font-size: 7pt; }
  table.csv-print th, table.csv-print td { padding: 0 2px; overflow-wrap: anywhere; }
  body { max-width: none; margin: 0; padding: 0; font-size: 10pt; }
  h2 { break-after: avoid; margin-top: 0; }
  section + section { break-before: page; }
  figure, table.compact, .verdict, svg { break-inside: avoid; }
  img, svg { max-width: 100%; height: auto; }
  img { max-height: 230mm; width: auto; object-fit: contain; }
  thead { display: table-header-group; }
  tr, th, td { break-inside: avoid; }
  a { color: inherit; text-decoration: none; }
  .view3d { display: none; }
}
.axes { position: relative; display: inline-block; margin: 22px 0 40px 64px; max-width: calc(100% - 70px); line-height: 0; }
.axes img.main { max-width: 100%; box-sizing: border-box; }
.axes svg.axes-overlay { position: absolute; left: 5px; top: 5px; width: calc(100% - 10px); height: calc(100% - 10px); overflow: visible; pointer-events: none; line-height: normal; }
.view3d canvas { display: block; max-width: 100%; height: auto; border: 1px solid #bbb; cursor: grab; touch-action: none; }
";

/// The approach in words.
fn approach_words(approach: Approach) -> &'static str {
    match approach {
        Approach::Slide => "push-and-slide (Inui, Gunji and Umezu)",
        Approach::Direct => {
            "direct approach (the knee-form moved in -x until it first touches the part; Inui et al.'s predecessor method)"
        }
    }
}

/// The file the report cites the compared run's summary as.
const COMPARE_SUMMARY: &str = "compare/summary.json";

fn compare_section(run: &Run, c: &Comparison, pngs: &[Vec<u8>]) -> Markup {
    let (slide, direct, slide_file, direct_file) = match run.summary.approach {
        Approach::Slide => (run, &c.other, SUMMARY, COMPARE_SUMMARY),
        Approach::Direct => (&c.other, run, COMPARE_SUMMARY, SUMMARY),
    };
    let swatch = |rgb: [u8; 3], text: &str| {
        let [r, g, b] = rgb;
        html! {
            span style={ "display:inline-block;width:12px;height:12px;background:rgb(" (r) "," (g) "," (b) ")" } {}
            " " (text) " "
        }
    };
    let slide_only_area = c.slide_only as f64 * c.slide_pitch * c.slide_pitch;
    let direct_only_area = c.direct_only as f64 * c.direct_pitch * c.direct_pitch;
    let captions = [
        "Face on, as push-and-slide sees the part (along its push).",
        "Obliquely from behind the direct approach's knee-form (from +x, beside the analysed side, above).",
    ];
    html! {
        section id="compare" {
            "\n"
            h2 { "Direct approach and push-and-slide" }
            "\n"
            p {
                "The same part analysed both ways: push-and-slide ("
                code { (slide.dir.display().to_string()) } ") and the direct approach ("
                code { (direct.dir.display().to_string()) }
                "), in which the knee-form moves in -x until it first touches the part. The direct approach cannot reach a surface behind one it touches first (the paper's Figure 2): a depression behind a protrusion."
            }
            "\n"
            table class="compact" id="compare-table" {
                "\n"
                tr { th { "approach" } th class="num" { "composite nodes" } th class="num" { "area (mm" (SUP2) ")" } th class="num" { "pitch (mm)" } }
                "\n"
                tr {
                    td { "push-and-slide" }
                    td class="num" { (cite(slide_file, &slide.summary_json, "/composite_nodes")) }
                    td class="num" { (cite(slide_file, &slide.summary_json, "/composite_area_mm2")) }
                    td class="num" { (cite(slide_file, &slide.summary_json, "/pitch_mm")) }
                }
                "\n"
                tr {
                    td { "direct approach" }
                    td class="num" { (cite(direct_file, &direct.summary_json, "/composite_nodes")) }
                    td class="num" { (cite(direct_file, &direct.summary_json, "/composite_area_mm2")) }
                    td class="num" { (cite(direct_file, &direct.summary_json, "/pitch_mm")) }
                }
                "\n"
                tr id="slide-only" {
                    td { "struck by push-and-slide only: what the direct approach misses" }
                    td class="num" { (c.slide_only) }
                    td class="num" { (fmt_num(slide_only_area)) }
                    td class="num" { (fmt_num(c.slide_pitch)) }
                }
                "\n"
                tr id="direct-only" {
                    td { "touched by the direct approach only" }
                    td class="num" { (c.direct_only) }
                    td class="num" { (fmt_num(direct_only_area)) }
                    td class="num" { (fmt_num(c.direct_pitch)) }
                }
                "\n"
            }
            "\n"
            p class="headline" {
                "The direct approach misses " b { (fmt_num(slide_only_area)) " mm" (SUP2) }
                " that push-and-slide strikes (" (c.slide_only) " of its nodes lie farther than "
                (fmt_num(c.match_mm)) " mm from every first-contact point of the direct approach)."
            }
            "\n"
            p class="note" {
                "A node counts as found by both when a colliding node of the other run lies within "
                (fmt_num(MATCH_PITCHES)) " pitches (of the coarser run) of it, in 3-d: the two grids sample the part in different frames. Computed from both runs' "
                code { "composite.csv" } "; each area is its run's own (nodes " (TIMES) " pitch" (SUP2) ", projected across its grid)."
            }
            "\n"
            @for (k, (figure, png)) in c.figures.iter().zip(pngs).enumerate() {
                figure {
                    "\n"
                    (image_tag(figure, png, &format!("compare-view-{k}"), "view", false))
                    "\n"
                    figcaption {
                        (captions[k.min(1)]) " "
                        (swatch(SLIDE_ONLY, "push-and-slide only"))
                        (swatch(DIRECT_ONLY, "direct approach only"))
                        (swatch(BOTH, "both"))
                        "; grey: neither."
                    }
                    "\n"
                }
                "\n"
            }
        }
        "\n"
    }
}

fn result_section(inputs: &Inputs) -> Markup {
    let run = inputs.run;
    let s = &run.summary;
    let j = &run.summary_json;
    let views = inputs.views;
    let n = ramp_len(run);
    let direct = s.approach == Approach::Direct;
    let side_word = match (direct, s.side) {
        (true, _) => "seen along the knee's motion (from +x, looking -x)",
        (false, crate::Side::Left) => {
            "from -y (the left side's outside), vehicle front (-x) on the left"
        }
        (false, crate::Side::Right) => {
            "from +y (the right side's outside), vehicle front (-x) on the right"
        }
    };
    let strikes = if direct {
        "whose knee-form, moving in -x, first touches the point (the direct approach)"
    } else {
        "whose sliding knee-form strikes the point (the paper's Figure 13)"
    };
    let undecided = super::undecided::Undecided::of(inputs.verifications, run.spec.pitch)
        .filter(|u| !direct && u.runs.nodes > 0);
    html! {
        section id="result" {
            "\n"
            h2 { "1. Colliding area on the part" }
            "\n"
            @for (k, v) in inputs.verifications.iter().enumerate() {
                @if let Some(json) = &v.verify {
                    (verdict_first(k, json, v.verdict(), (run.blind_spots.len(), undecided.as_ref().is_some_and(|u| u.k == k))))
                }
                @if let Some(json) = &v.converge {
                    (converge_first(k, json))
                }
            }
            (warnings_first(inputs))
            @if let Some(check) = &s.sample_check {
                (sample_check(check))
            }
            p id="knee-form-first" {
                "Knee-form: L = " (cite(SUMMARY, j, "/triangle_side_mm")) " mm"
                @if s.triangle_side_assumed {
                    " " span class="assumed" {
                        "ASSUMED default: the regulation's value was not at hand; set it with --triangle-side"
                    }
                } @else {
                    " (given)"
                }
                ", R = " (cite(SUMMARY, j, "/radius_mm")) " mm, W = " (cite(SUMMARY, j, "/thickness_mm")) " mm (section 3)."
            }
            "\n"
            p class="headline" {
                "Area the knee-form can strike at some angle: "
                b { (cite(SUMMARY, j, "/composite_area_mm2")) " mm" (SUP2) }
                " (" (cite(SUMMARY, j, "/composite_nodes")) " grid nodes at "
                (cite(SUMMARY, j, "/pitch_mm")) " mm pitch), over "
                (s.angles_deg.len()) " angles."
            }
            "\n"
            figure {
                "\n"
                div class="axes" {
                    (image_tag(&views.side, &inputs.pngs[0], "main-view", "view main", true))
                    (axes_svg(&views.side.view, if direct { "y" } else { "x" }))
                    @if let Some(u) = &undecided {
                        (u.overlay_svg(run, &views.side.view))
                    }
                    (zone_labels_svg(run, &views.side.view))
                }
                "\n"
                (legend_svg(n))
                "\n"
                figcaption {
                    "The analysed side seen along the push, " (side_word)
                    ", z up. Colour: the number of knee-form angles (of " (n)
                    ") " (strikes) "; grey: never struck. A point is coloured when it lies within half a pitch, in " (if direct { "y" } else { "x" }) " and z, of a colliding grid node of "
                    code { "composite.csv" } "."
                    @if !run.blind_spots.is_empty() {
                        " Magenta: blind spots, grid cells where the part sticks out between the nodes unseen ("
                        code { "blind_spots.csv" } ", section 6)."
                    }
                    @if !s.zones.is_empty() {
                        " Boxed numbers: the largest struck zones' ids (the table below, "
                        code { "zones.csv" } ")."
                    }
                    @if let Some(u) = &undecided {
                        (u.legend())
                    }
                }
                "\n"
            }
            "\n"
            (zones_table(run, undecided.as_ref()))
            "\n"
            figure {
                "\n"
                (image_tag(&views.oblique, &inputs.pngs[1], "oblique-view", "view", false))
                "\n"
                figcaption {
                    "Oblique view from the analysed side, in front of and above the part, with the same colours."
                }
                "\n"
            }
            "\n"
            (inputs.view3d)
        }
        "\n"
    }
}

/// The analysis's own sample check (`summary.json`'s `sample_check`): a
/// few starts against the exact oracle, said as a sample, never as the
/// verdict; flagged when it found the grid beyond its tolerance.
fn sample_check(check: &crate::summary::SampleCheck) -> Markup {
    let class = if check.exceeds_tolerance {
        "fail check"
    } else {
        "check"
    };
    html! {
        p class=(class) id="sample-check" {
            "Measured accuracy of this analysis (a sample, not the evidence: "
            code { "kneeform verify" } " gives that): " (check.line()) "."
            @if check.exceeds_tolerance {
                " The grid's area lies further from the exact knee-form's than its tolerance here: verify this part, or choose a finer pitch."
            }
        }
        "\n"
    }
}

/// The class and word of a verdict.
fn verdict_words(verdict: Verdict) -> (&'static str, &'static str) {
    match verdict {
        Verdict::Pass => ("pass", "PASS"),
        Verdict::Fail => ("fail", "FAIL"),
        Verdict::Inconclusive => ("inconclusive", "INCONCLUSIVE"),
        Verdict::Unknown => ("unknown", "NO VERDICT IN FILE"),
    }
}

/// The verdict of the `k`-th verification, first: its outcome and the
/// sentence a regulator signs (SPEC, "The verdict"): the figure judged
/// against the tolerance at the pitch, the sample, the undecided contacts
/// (with their area, and whether they are `hatched` on the picture) and
/// how far they may move the area's boundary, the cost side, the blind
/// spots (of `blind_cells` flagged) and the knee-form's L, assumed or
/// given; then, on FAIL, the
/// figures beyond the tolerance with their mechanism and the worst start
/// (diagnostics). Section 5 has the tables. `blind_cells` is the run's
/// flagged blind spots.
fn verdict_first(
    k: usize,
    json: &Value,
    verdict: Verdict,
    (blind_cells, hatched): (usize, bool),
) -> Markup {
    let file = verify_label(k, "verify.json");
    let c = |p: &str| cite(&file, json, p);
    let (class, word) = verdict_words(verdict);
    let failing: Vec<(usize, &Value)> = json
        .get("failures")
        .and_then(Value::as_array)
        .map(|f| {
            f.iter()
                .enumerate()
                .filter(|(_, f)| f.get("fails_verdict") == Some(&Value::Bool(true)))
                .collect()
        })
        .unwrap_or_default();
    let assumed = json.get("triangle_side_assumed") == Some(&Value::Bool(true));
    html! {
        p class={ (class) " verdict" } id={ "verdict-first-" (k) } {
            (word) " (verification " (k + 1) "): "
            @match verdict {
                Verdict::Pass => {
                    "every decided exact strike away from blind spots lies within "
                    (c("/area_miss_decided_mm")) " mm of the grid's colliding area (the analysis's, every start's strikes; worst angle), within the tolerance of "
                }
                Verdict::Fail => {
                    "a decided exact strike away from blind spots lies "
                    (c("/area_miss_decided_mm")) " mm (\u{2014}: infinite, no grid strike at that angle) from the grid's colliding area (the analysis's, every start's strikes; worst angle), beyond the tolerance of "
                }
                _ => {
                    "no claim: " (c("/outcome_reason")) ". The tolerance asked was "
                }
            }
            (c("/tolerance_mm")) " mm, at pitch " (c("/pitch_mm")) " mm. Sample: "
            (c("/counts/pairs")) " start-angle pairs (starts " (c("/starts")) ", "
            (json.get("angles_deg").and_then(Value::as_array).map_or(0, Vec::len))
            " angles) against the exact oracle, " (c("/counts/exact_strikes_decided"))
            " decided exact strikes. Undecided: " (c("/counts/exact_undecided"))
            " exact contacts (either answer is right at this pitch)"
            @if json.get("undecided_area_mm2").is_some_and(Value::is_number) {
                " at " (c("/undecided_nodes/nodes")) " nodes of the verified grid, an area of "
                (c("/undecided_area_mm2")) " mm" (SUP2)
                @if hatched {
                    " (hatched on the picture below)"
                }
            }
            ", which may move the area's boundary by up to "
            (c("/area_distance_mm")) " mm (the all-strikes area distance). Cost: the grid's area reaches "
            (c("/area_false_alarm_decided_mm")) " mm beyond the exact one (the decided area false-alarm distance). Blind spots: "
            (c("/counts/blind_pairs")) " pairs touched one of the " (blind_cells)
            " grid cells flagged (features narrower than the pitch, section 6). Knee-form L = "
            (c("/knee_form_mm/0")) " mm"
            @if assumed {
                " " span class="assumed" { "ASSUMED default: set it with --triangle-side" }
            } @else {
                " (given)"
            }
            ". (" code { "verify.json" } " " code { "outcome" } " = " (c("/outcome")) ".)"
            " What is computed and what each figure means: " code { "docs/method.md" }
            " (section 16, the verdict) of kneeform " (c("/kneeform_version")) "."
        }
        "\n"
        @if !failing.is_empty() {
            p class="headline" {
                "Figures beyond the tolerance (diagnostics; the outcome judges the area miss distance alone): "
                @for (n, (i, _)) in failing.iter().enumerate() {
                    @if n > 0 { "; " }
                    code { (c(&format!("/failures/{i}/metric"))) } " "
                    (c(&format!("/failures/{i}/value"))) " mm ("
                    (c(&format!("/failures/{i}/mechanism"))) ")"
                }
                @if json.pointer("/worst_starts/0").is_some() {
                    ". Worst start: x = " (c("/worst_starts/0/x")) ", z = " (c("/worst_starts/0/z"))
                    " mm at " (c("/worst_starts/0/angle_deg")) " degrees, "
                    code { (c("/worst_starts/0/metric")) } " = " (c("/worst_starts/0/value")) " mm"
                }
                ". Mechanisms: sampling (the grid's error at this pitch: shown by refinement against the same exact trace, or a touch briefer than the pitch), rim, oracle-failure, unexplained (README, \"When verify fails\")."
            }
            "\n"
        }
    }
}

/// Every warning a signature needs, first: the analysis's
/// (`summary.json`'s `warnings`), each verification's and each
/// convergence study's (their JSON's `warnings`), each cited.
fn warnings_first(inputs: &Inputs) -> Markup {
    let j = &inputs.run.summary_json;
    let mut cited: Vec<Markup> = Vec::new();
    // A warning given by several files (the part's size, by the analysis
    // and its verification) is shown once, cited from the first.
    let mut said: Vec<Value> = Vec::new();
    let mut of = |file: String, json: &Value| {
        let n = json
            .get("warnings")
            .and_then(Value::as_array)
            .map_or(0, Vec::len);
        for w in 0..n {
            let pointer = format!("/warnings/{w}");
            let text = json.pointer(&pointer);
            if text.is_some_and(|t| said.contains(t)) {
                continue;
            }
            said.extend(text.cloned());
            cited.push(cite(&file, json, &pointer));
        }
    };
    of(SUMMARY.to_string(), j);
    for (k, v) in inputs.verifications.iter().enumerate() {
        if let Some(json) = &v.verify {
            of(verify_label(k, "verify.json"), json);
        }
        if let Some(json) = &v.converge {
            of(verify_label(k, "converge.json"), json);
        }
    }
    html! {
        @if !cited.is_empty() {
            div class="warnings" id="warnings-first" {
                b { "Warnings (" (cited.len()) "):" }
                ul {
                    @for w in &cited {
                        li { (w) }
                    }
                }
            }
            "\n"
        }
    }
}

/// Each convergence study's outcome per pitch, first: the pitch it
/// recommends and why the finer or coarser ones are not.
fn converge_first(k: usize, json: &Value) -> Markup {
    let file = verify_label(k, "converge.json");
    let c = |p: &str| cite(&file, json, p);
    let n = json
        .get("verdicts")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    html! {
        @if n > 0 {
            p class="check" id={ "converge-first-" (k) } {
                "Convergence study (verification " (k + 1) "), at a tolerance of "
                (c("/tolerance_mm")) " mm: "
                @for v in 0..n {
                    @if v > 0 { "; " }
                    (c(&format!("/verdicts/{v}/pitch_mm"))) " mm "
                    (c(&format!("/verdicts/{v}/outcome")))
                }
                ". Recommended pitch (the coarsest PASS): " (c("/recommended_pitch_mm")) " mm."
            }
            "\n"
        }
    }
}

/// An `<img>` of a rendered view; for the side views (`mapping`), its
/// pixel ↔ (x, z) mapping in data attributes: pixel `(c, r)` has its centre
/// at `x = x-sign * (u-left + (c + 0.5) * mm-per-px)`,
/// `z = v-top - (r + 0.5) * mm-per-px` (mm, part frame).
fn image_tag(figure: &Figure, png: &[u8], id: &str, class: &str, mapping: bool) -> Markup {
    let v = mapping.then_some(&figure.view);
    html! {
        img id=(id) class=(class) width=(figure.image.width) height=(figure.image.height)
            alt=(id) data-u-left=[v.map(|v| v.u_left)] data-v-top=[v.map(|v| v.v_top)]
            data-mm-per-px=[v.map(|v| v.mm_per_px)] data-x-sign=[v.map(|v| v.camera.right[0])]
            src=(png_uri(png));
    }
}

/// The main image's axes: mm ticks on its lower and left edges, drawn
/// over the image (an SVG of the image's pixel size laid on it; its
/// labels reach out into the wrapper's margin), so they scale with it.
/// `horizontal` names the image's horizontal coordinate (`x`, or `y` for
/// the direct approach); its sign follows the camera (the right side's
/// x runs leftwards).
fn axes_svg(view: &super::render::View, horizontal: &str) -> Markup {
    let (w, h) = (view.width as f64, view.height as f64);
    let sign = view.horizontal_sign();
    let mm = view.mm_per_px;
    // The horizontal coordinate at pixel edge `c` is `sign * (u_left + c mm)`.
    let h_at = |c: f64| sign * (view.u_left + c * mm);
    let (h0, h1) = (h_at(0.0).min(h_at(w)), h_at(0.0).max(h_at(w)));
    let (z0, z1) = (view.v_top - h * mm, view.v_top);
    let step = tick_step((h1 - h0).max(z1 - z0) / 10.0);
    let ticks = |lo: f64, hi: f64| -> Vec<f64> {
        let first = (lo / step).ceil() as i64;
        let last = (hi / step).floor() as i64;
        (first..=last).map(|k| k as f64 * step).collect()
    };
    let label = |v: f64| fmt_num(if v == 0.0 { 0.0 } else { v });
    html! {
        svg class="axes-overlay" viewBox=(format!("0 0 {w} {h}")) role="img"
            aria-label={ "axes: " (horizontal) " and z in mm" } {
            @for v in ticks(h0, h1) {
                @let c = (sign * v - view.u_left) / mm;
                (svg_empty("line", &[("x1", &format!("{c:.1}")), ("x2", &format!("{c:.1}")), ("y1", &format!("{h:.1}")), ("y2", &format!("{:.1}", h + 7.0)), ("stroke", &"#333")]))
                text x=(format!("{c:.1}")) y=(format!("{:.1}", h + 21.0)) font-size="13" text-anchor="middle" { (label(v)) }
            }
            text x=(format!("{:.1}", w)) y=(format!("{:.1}", h + 37.0)) font-size="13" text-anchor="end" {
                (horizontal) " (mm, vehicle frame)"
            }
            @for v in ticks(z0, z1) {
                @let r = (view.v_top - v) / mm;
                (svg_empty("line", &[("x1", &"-7"), ("x2", &"0"), ("y1", &format!("{r:.1}")), ("y2", &format!("{r:.1}")), ("stroke", &"#333")]))
                text x="-10" y=(format!("{:.1}", r + 4.5)) font-size="13" text-anchor="end" { (label(v)) }
            }
            text x="-10" y="-6" font-size="13" text-anchor="end" { "z (mm)" }
        }
    }
}

/// The knee-form's cross-section to scale (SPEC, "The knee-form"): the
/// rounded triangle at angle 0 and at +20 degrees (dashed), the reference
/// point, L, R, the direction of the slide, and a strip showing W.
fn knee_form_svg(l: f64, r: f64, w: f64) -> Markup {
    let h = l * 3f64.sqrt() / 2.0;
    let tri = [[0.0, 0.0], [h, l / 2.0], [h, -l / 2.0]];
    let rotate = |[x, z]: [f64; 2], deg: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        [x * c - z * s, x * s + z * c]
    };
    // The outline of T (+) D_R: for each outward direction, the furthest
    // vertex plus R along it.
    let outline = |deg: f64| -> Vec<[f64; 2]> {
        let t = tri.map(|v| rotate(v, deg));
        (0..360)
            .map(|k| {
                let (nz, nx) = (k as f64).to_radians().sin_cos();
                let v = t
                    .iter()
                    .max_by(|a, b| (a[0] * nx + a[1] * nz).total_cmp(&(b[0] * nx + b[1] * nz)))
                    .expect("three vertices");
                [v[0] + r * nx, v[1] + r * nz]
            })
            .collect()
    };
    let (flat, raised) = (outline(0.0), outline(20.0));
    let all = flat.iter().chain(&raised);
    let (x0, x1) = all
        .clone()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[0]), b.max(p[0]))
        });
    let (z0, z1) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
        (a.min(p[1]), b.max(p[1]))
    });
    // 300 px for the taller of the two extents; room for labels around.
    let scale = 300.0 / (x1 - x0).max(z1 - z0).max(1e-9);
    let (left, top) = (150.0, 40.0);
    let px = |[x, z]: [f64; 2]| [left + (x - x0) * scale, top + (z1 - z) * scale];
    let path = |points: &[[f64; 2]]| {
        let mut d = String::new();
        for (k, p) in points.iter().enumerate() {
            let [a, b] = px(*p);
            d.push_str(&format!("{}{a:.1},{b:.1} ", if k == 0 { "M" } else { "L" }));
        }
        d.push('Z');
        d
    };
    let [rx, ry] = px([0.0, 0.0]);
    let [b1x, b1y] = px(tri[1]);
    let [b2x, b2y] = px(tri[2]);
    let [rr_x, rr_y] = px([tri[1][0] + r, tri[1][1]]);
    let width = left + (x1 - x0) * scale + 230.0;
    let height = top + (z1 - z0) * scale + 60.0;
    // The thickness strip: W along y to the same scale, beside the section.
    let (sx, sy) = (left + (x1 - x0) * scale + 60.0, top + 20.0);
    let (sw, sh) = ((w * scale).min(150.0), (x1 - x0) * scale * 0.5);
    let f = |v: f64| format!("{v:.1}");
    html! {
        svg class="knee-form" width=(f(width)) height=(f(height)) viewBox=(format!("0 0 {} {}", f(width), f(height)))
            role="img" aria-label="the knee-form's cross-section with L, R, W and the reference point" {
            (svg_empty("path", &[("d", &path(&raised)), ("fill", &"none"), ("stroke", &"#888"), ("stroke-dasharray", &"6 4")]))
            (svg_empty("path", &[("d", &path(&flat)), ("fill", &"#e8eef8"), ("stroke", &"#1a1a1a"), ("stroke-width", &"1.5")]))
            (svg_empty("path", &[("d", &format!("M{rx:.1},{ry:.1} L{b1x:.1},{b1y:.1} L{b2x:.1},{b2y:.1} Z")), ("fill", &"none"), ("stroke", &"#555"), ("stroke-width", &"0.8")]))
            (svg_empty("circle", &[("cx", &f(rx)), ("cy", &f(ry)), ("r", &"4"), ("fill", &"#c62828")]))
            text x=(f(rx - 8.0)) y=(f(ry - 10.0)) font-size="12" text-anchor="end" fill="#c62828" { "reference point" }
            text x=(f(b1x + 8.0)) y=(f(0.5 * (b1y + b2y))) font-size="12" { "L = " (fmt_num(l)) " mm" }
            (svg_empty("line", &[("x1", &f(b1x)), ("y1", &f(b1y)), ("x2", &f(rr_x)), ("y2", &f(rr_y)), ("stroke", &"#1a1a1a")]))
            text x=(f(rr_x + 4.0)) y=(f(rr_y + 4.0)) font-size="12" { "R = " (fmt_num(r)) " mm" }
            text x=(f(b1x - 40.0)) y=(f(top - 8.0)) font-size="12" fill="#666" { "+20" (PreEscaped("&deg;")) ": back raised" }
            (svg_empty("path", &[("d", &format!("M{:.1},{:.1} l-70,0 m0,0 l10,-5 m-10,5 l10,5", rx - 20.0, height - 20.0)), ("stroke", &"#1a1a1a"), ("fill", &"none"), ("stroke-width", &"1.5")]))
            text x=(f(rx - 20.0)) y=(f(height - 6.0)) font-size="12" text-anchor="end" { "slides in -x" }
            text x=(f(left)) y="16" font-size="12" { "x (right), z (up)" }
            (svg_empty("rect", &[("x", &f(sx)), ("y", &f(sy)), ("width", &f(sw)), ("height", &f(sh)), ("fill", &"#e8eef8"), ("stroke", &"#1a1a1a")]))
            text x=(f(sx + 0.5 * sw)) y=(f(sy + sh + 16.0)) font-size="12" text-anchor="middle" { "W = " (fmt_num(w)) " mm" }
            text x=(f(sx + 0.5 * sw)) y=(f(sy + sh + 30.0)) font-size="12" text-anchor="middle" { "along the push (y)" }
        }
    }
}

/// A tick step of 1, 2 or 5 times a power of ten, at least `raw` (mm).
fn tick_step(raw: f64) -> f64 {
    let raw = raw.max(1e-9);
    let decade = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|s| *s >= raw * (1.0 - 1e-12))
        .unwrap_or(10.0 * decade)
}

/// The composite's colour ramp as an SVG bar, one swatch per count.
fn legend_svg(n: usize) -> Markup {
    let (w, bar_h) = (600.0, 18.0);
    let sw = w / n as f64;
    let mut ticks = vec![1, n];
    if n > 2 {
        ticks.insert(1, n.div_ceil(2));
    }
    ticks.dedup();
    html! {
        svg class="legend" width="660" height="62" viewBox="0 0 660 62" role="img" aria-label="legend" {
            "\n"
            text x="10" y="13" font-size="12" { "number of angles striking the point" }
            "\n"
            @for c in 1..=n {
                @let [r, g, b] = composite_colour(c as u16, n);
                (svg_empty("rect", &[
                    ("x", &format!("{:.2}", 10.0 + (c - 1) as f64 * sw)),
                    ("y", &"20"),
                    ("width", &format!("{:.2}", sw + 0.3)),
                    ("height", &bar_h),
                    ("fill", &format!("rgb({r},{g},{b})")),
                ]))
                "\n"
            }
            @for c in ticks {
                text x=(format!("{:.2}", 10.0 + (c as f64 - 0.5) * sw)) y="54" font-size="12"
                    text-anchor="middle" { (c) }
                "\n"
            }
        }
    }
}

/// A row of a two-column table: a label and its value.
fn row(label: &str, value: Markup) -> Markup {
    html! { tr { th { (label) } td { (value) } } "\n" }
}

fn part_section(run: &Run) -> Markup {
    let j = &run.summary_json;
    let files = &run.summary.files;
    let c = |p: &str| cite(SUMMARY, j, p);
    let corner = |name: &str| {
        html! {
            @for k in 0..3 {
                @if k > 0 { ", " }
                (c(&format!("/{name}/{k}")))
            }
        }
    };
    html! {
        section id="part" {
            "\n"
            h2 { "2. Part" }
            "\n"
            table class="compact" {
                "\n"
                (row("File", html! { code { (c("/input_file")) } }))
                @if files.is_empty() {
                    (row("SHA-256", html! { code { (c("/sha256")) } }))
                }
                (row("Re-read for this report", html! {
                    code { (run.part_path.display().to_string()) } " (SHA-256 matches the run's)"
                }))
                (row("Triangles in the file", c("/triangles")))
                (row("Bodies read (every `solid` block of an ASCII STL)", c("/bodies")))
                (row("Degenerate triangles (zero area, skipped)", c("/degenerate_triangles")))
                (row("Bounding box, min x, y, z (mm)", corner("bbox_min")))
                (row("Bounding box, max x, y, z (mm)", corner("bbox_max")))
                (row("Units", html! { "file units " (TIMES) " " (c("/scale")) " = mm" }))
                (row("Analysed side", c("/side")))
                @if run.summary.frame.is_some() {
                    (row("Frame (--frame)", html! {
                        code { (c("/frame/given")) }
                        ": the part's axes in vehicle coordinates; the pictures are drawn in vehicle coordinates, the CSV, STL and PLY files are in the part's"
                    }))
                }
            }
            "\n"
            @if !files.is_empty() {
                p { "The part is an assembly of these files; each colliding node is the file's whose surface set its height (the first file listed where two set the same height):" }
                "\n"
                table class="compact" {
                    "\n"
                    tr { th { "file" } th { "SHA-256" } th { "triangles" } th { "colliding nodes" } th { "colliding area (mm" (SUP2) ")" } th { "" } }
                    "\n"
                    @for (k, f) in files.iter().enumerate() {
                        tr {
                            td { code { (c(&format!("/files/{k}/path"))) } }
                            td { code { (c(&format!("/files/{k}/sha256"))) } }
                            td { (c(&format!("/files/{k}/triangles"))) }
                            td { (c(&format!("/files/{k}/colliding_nodes"))) }
                            td { (c(&format!("/files/{k}/colliding_area_mm2"))) }
                            td { @if f.ignored { "ignored (--ignore): not in the height grid" } }
                        }
                        "\n"
                    }
                }
                "\n"
            }
        }
        "\n"
    }
}

fn method_section(run: &Run) -> Markup {
    let s = &run.summary;
    let j = &run.summary_json;
    let c = |p: &str| cite(SUMMARY, j, p);
    let mm = |p: &str| html! { (c(p)) " mm" };
    html! {
        section id="method" {
            "\n"
            h2 { "3. Knee-form and analysis" }
            "\n"
            figure {
                (knee_form_svg(s.triangle_side_mm, s.radius_mm, s.thickness_mm))
                figcaption {
                    "The knee-form's cross-section in the x-z plane (to scale): an equilateral triangle of side L rounded by R, its reference point the centre of the front corner's rounding; it is extruded over the thickness W along the push. Solid: angle 0; dashed: +20 degrees, which raises the back (negative angles lower it). It slides in -x, towards the vehicle front."
                }
            }
            "\n"
            table class="compact" {
                "\n"
                (row("Triangle side L", html! {
                    (c("/triangle_side_mm")) " mm"
                    @if s.triangle_side_assumed {
                        " " span class="assumed" {
                            "ASSUMED default: the regulation's value was not at hand; set it with --triangle-side"
                        }
                    } @else {
                        " (given)"
                    }
                }))
                (row("Rounding radius R", mm("/radius_mm")))
                (row("Thickness W", mm("/thickness_mm")))
                (row("Grid pitch", mm("/pitch_mm")))
                (row("Grid origin x, z", html! {
                    (c("/grid_origin/0")) ", " (c("/grid_origin/1")) " mm"
                }))
                (row("Grid size", html! {
                    (c("/grid_size/0")) " " (TIMES) " " (c("/grid_size/1")) " nodes ("
                    (c("/sampled_nodes")) " with part under them)"
                }))
                (row("Angles (degrees)", html! {
                    (c("/angles_deg")) " (" (s.angles_deg.len()) " angles)"
                }))
                (row("Approach", html! {
                    (c("/approach")) ": " (approach_words(s.approach))
                }))
                @if s.approach == Approach::Direct {
                    (row("Deflection threshold", html! {
                        (c("/deflection_deg")) " degrees: recorded, not used (the direct approach's knee-form does not slide; every first-contact point within e0 is in the area)"
                    }))
                    (row("Direct frame", html! {
                        "the grid's columns are the part's y (analysis frame), its depth -x: the grid origin below is (y, z)"
                    }))
                } @else {
                    (row("Deflection threshold", html! {
                        (c("/deflection_deg")) " degrees (sigma = tan delta = " (c("/sigma"))
                        "; deflection measured as " (c("/rate"))
                        @if s.window_mm.is_some() {
                            ": the knee-form's drop over the last " (c("/window_mm"))
                            " mm of its travel against sigma times that window"
                        }
                        "): a point the knee-form meets is a strike only when the surface there turns it aside by more than this angle"
                    }))
                }
                (row("Rounding tolerance e0", html! {
                    (c("/e0_mm")) " mm (absorbs floating-point rounding only)"
                }))
                (row("Side", c("/side")))
                (row("Algorithm", c("/algorithm")))
                (row("Software", html! { "kneeform " (c("/kneeform_version")) }))
                (row("Run date", html! {
                    (utc_date(s.run_unix_time)) " (" (c("/run_unix_time")) " s since 1970)"
                }))
            }
            "\n"
        }
        "\n"
    }
}

fn per_angle_section(inputs: &Inputs) -> Markup {
    let run = inputs.run;
    let j = &run.summary_json;
    let [r, g, b] = ANGLE_COLOUR;
    let index_of = |angle: &f64| {
        run.summary
            .angles_deg
            .iter()
            .position(|a| a == angle)
            .unwrap_or(0)
    };
    let columns = [
        "angle_deg",
        "placed_starts",
        "colliding_nodes",
        "colliding_area_mm2",
    ];
    html! {
        section id="per-angle" {
            "\n"
            h2 { "4. Colliding area per angle" }
            "\n"
            figure {
                "\n"
                div class="multiples" {
                    "\n"
                    @for (k, (angle, figure)) in inputs.views.per_angle.iter().enumerate() {
                        @let index = index_of(angle);
                        div {
                            (image_tag(figure, &inputs.pngs[2 + k], &format!("angle-view-{k}"), "view", true))
                            div class="note" {
                                "angle " (cite(SUMMARY, j, &format!("/per_angle/{index}/angle_deg")))
                                " degrees: "
                                (cite(SUMMARY, j, &format!("/per_angle/{index}/colliding_area_mm2")))
                                " mm" (SUP2)
                            }
                        }
                        "\n"
                    }
                }
                "\n"
                figcaption {
                    "The analysed side at single knee-form angles (the paper's Figure 12): in "
                    span style=(format!("color: rgb({r},{g},{b}); font-weight: bold")) { "red" }
                    ", the points that angle strikes (" code { "composite.csv" } "'s " code { "angle_mask" } ")."
                }
                "\n"
            }
            "\n"
            (area_chart_svg(run))
            table class="per-angle" {
                "\n"
                tr {
                    th class="num" { "angle (deg)" }
                    th class="num" { "placed starts" }
                    th class="num" { "colliding nodes" }
                    th class="num" { "colliding area (mm" (SUP2) ")" }
                }
                "\n"
                @for k in 0..run.summary.per_angle.len() {
                    tr {
                        @for f in columns {
                            td class="num" { (cite(SUMMARY, j, &format!("/per_angle/{k}/{f}"))) }
                        }
                    }
                    "\n"
                }
            }
            "\n"
        }
        "\n"
    }
}

/// Colliding area against angle, as an SVG line chart.
fn area_chart_svg(run: &Run) -> Markup {
    let pts: Vec<(f64, f64)> = run
        .summary
        .per_angle
        .iter()
        .map(|a| (a.angle_deg, a.colliding_area_mm2))
        .collect();
    let (w, h) = (640.0, 240.0);
    let (left, right, top, bottom) = (70.0, 20.0, 20.0, 40.0);
    let (a_lo, a_hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    let (a_lo, a_hi) = if a_lo < a_hi {
        (a_lo, a_hi)
    } else {
        (a_lo - 1.0, a_lo + 1.0)
    };
    let area_hi = pts.iter().map(|p| p.1).fold(0.0, f64::max);
    let area_hi = if area_hi > 0.0 { area_hi } else { 1.0 };
    let px = |a: f64| left + (a - a_lo) / (a_hi - a_lo) * (w - left - right);
    let py = |v: f64| h - bottom - v / area_hi * (h - top - bottom);
    let y0 = h - bottom;
    let axis = |x1: f64, y1: f64, x2: f64, y2: f64| {
        svg_empty(
            "line",
            &[
                ("x1", &x1),
                ("y1", &y1),
                ("x2", &x2),
                ("y2", &y2),
                ("stroke", &"#333"),
            ],
        )
    };
    let line: Vec<String> = pts
        .iter()
        .map(|&(a, v)| format!("{:.2},{:.2}", px(a), py(v)))
        .collect();
    let one = |v: f64| format!("{v:.1}");
    let two = |v: f64| format!("{v:.2}");
    let mid_y = top + 0.5 * (h - top - bottom);
    html! {
        figure {
            "\n"
            svg class="chart" width=(w) height=(h) viewBox={ "0 0 " (w) " " (h) } role="img"
                aria-label="colliding area per angle" {
                "\n"
                (axis(left, y0, w - right, y0))
                "\n"
                (axis(left, top, left, y0))
                "\n"
                @for (v, anchor_y) in [(0.0, py(0.0)), (area_hi, py(area_hi))] {
                    text x=(one(left - 6.0)) y=(one(anchor_y + 4.0)) font-size="11" text-anchor="end" {
                        (fmt_num(v))
                    }
                    "\n"
                }
                @for a in [a_lo, a_hi] {
                    text x=(one(px(a))) y=(one(h - bottom + 16.0)) font-size="11" text-anchor="middle" {
                        (fmt_num(a))
                    }
                    "\n"
                }
                text x=(one(left + 0.5 * (w - left - right))) y=(one(h - 6.0)) font-size="12"
                    text-anchor="middle" { "angle (degrees)" }
                "\n"
                text x="14" y=(one(mid_y)) font-size="12" transform={ "rotate(-90 14 " (one(mid_y)) ")" }
                    text-anchor="middle" { "area (mm" (PreEscaped("&#178;")) ")" }
                "\n"
                (svg_empty("polyline", &[
                    ("fill", &"none"),
                    ("stroke", &"rgb(190,85,20)"),
                    ("stroke-width", &"1.5"),
                    ("points", &line.join(" ")),
                ]))
                "\n"
                @for &(a, v) in &pts {
                    (svg_empty("circle", &[
                        ("cx", &two(px(a))),
                        ("cy", &two(py(v))),
                        ("r", &"2.2"),
                        ("fill", &"rgb(190,85,20)"),
                    ]))
                    "\n"
                }
            }
            "\n"
            figcaption {
                "Colliding area per angle (" code { (SUMMARY) } ", " code { "per_angle" } ")."
            }
            "\n"
        }
        "\n"
    }
}

fn accuracy_section(verifications: &[Verification]) -> Markup {
    html! {
        section id="accuracy" {
            "\n"
            h2 { "5. Accuracy" }
            "\n"
            @if verifications.is_empty() {
                p class="unknown verdict" {
                    "Not verified: no verification run was given to this report, so the accuracy of the grid result against the exact oracle is not shown here. Run "
                    code { "kneeform verify" } " and " code { "kneeform converge" }
                    " and pass their directories to " code { "kneeform report" } "."
                }
                "\n"
            }
            @for (k, v) in verifications.iter().enumerate() {
                h3 { "Verification run " (k + 1) ": " code { (v.dir.display().to_string()) } }
                "\n"
                @if let Some(json) = &v.verify {
                    (verify_block(k, json, v.verdict()))
                }
                @if let Some(json) = &v.converge {
                    (converge_block(k, json))
                }
                @for (name, png) in &v.figures {
                    figure {
                        img class="plot" alt=(name) src=(png_uri(png));
                        figcaption { code { (name) } }
                    }
                    "\n"
                }
                @for (name, text) in [("verify.csv", &v.verify_csv), ("converge.csv", &v.converge_csv)] {
                    @if let Some(text) = text {
                        (csv_table(name, text))
                    }
                }
            }
        }
        "\n"
    }
}

fn verify_block(k: usize, json: &Value, verdict: Verdict) -> Markup {
    let file = verify_label(k, "verify.json");
    let c = |p: &str| cite(&file, json, p);
    let tolerance = json.get("tolerance_mm").and_then(Value::as_f64);
    let decided = json.get("area_distance_decided_mm").is_some();
    let (class, word) = verdict_words(verdict);
    let rest: Vec<(String, String, &Value)> = ["area_iou", "counts", "timings"]
        .iter()
        .filter_map(|key| json.get(*key).map(|v| (*key, v)))
        .flat_map(|(key, v)| scalars(v, &format!("/{key}"), key))
        .collect();
    html! {
        p class={ (class) " verdict" } id={ "verdict-" (k) } {
            (word) ": the decided area miss distance " (c("/area_miss_decided_mm"))
            " mm against a tolerance of " (c("/tolerance_mm")) " mm at pitch "
            (c("/pitch_mm")) " mm (" code { "verify.json" } " " code { "outcome" } " = "
            (c("/outcome")) ", " code { "pass" } " = " (c("/pass")) ")"
        }
        "\n"
        @if json.get("verdict").is_some_and(|v| v.as_str().is_some_and(|v| !v.is_empty())) {
            p class="headline" {
                "Misses (safety) and false alarms (cost) apart, each figure beyond the tolerance with its mechanism (blind: downstream of a flagged blind spot; level-error: the grid's level error, on the safe side; undecided; oracle-failure; unexplained): "
                (c("/verdict"))
            }
            "\n"
        }
        @if decided {
            p class="headline" {
                "Area distance (decided strikes: the grid's colliding area against the exact one, both ways, in xz): "
                b { (c("/area_distance_decided_mm")) " mm" }
                "; over all strikes, undecided included: " (c("/area_distance_mm"))
                " mm. Deflection threshold " (c("/deflection_deg")) " degrees; "
                (c("/counts/exact_undecided"))
                " exact contacts undecided (rate within the tie band: " (c("/tie_band_rule")) ")."
            }
            "\n"
            p {
                "The area IoU below (" (c("/area_iou"))
                ") compares the exact strikes snapped to their nearest nodes with the grid's colliding nodes: it cannot see a difference under half a pitch, so an IoU of 1 beside an area distance near the pitch is no contradiction; the area distance is the figure to read."
            }
            "\n"
        }
        @if let Some(Value::Object(metrics)) = json.get("metrics") {
            table class="metrics" {
                "\n"
                tr {
                    th { "metric (mm)" }
                    @for f in ["max", "p95", "mean", "n"] {
                        th class="num" { (f) }
                    }
                    th { "judged" }
                }
                "\n"
                @for (name, m) in metrics {
                    @let base = format!("/metrics/{}", escape_pointer(name));
                    tr {
                        td { (name) }
                        @for f in ["max", "p95", "mean", "n"] {
                            td class="num" { (c(&format!("{base}/{f}"))) }
                        }
                        // The outcome judges one figure, the decided area
                        // miss distance; every other metric is a diagnostic
                        // shown beside it (SPEC, "The verdict"), never
                        // marked as failing a verdict it does not decide.
                        @match (m.get("max").and_then(Value::as_f64), tolerance) {
                            _ if name.as_str() != JUDGED_METRIC => {
                                td { "diagnostic" }
                            }
                            (Some(max), Some(tol)) if max.abs() <= tol => {
                                td class="pass-cell" { "within tolerance" }
                            }
                            (Some(_), Some(_)) => td class="fail-cell" { b { "beyond tolerance" } },
                            _ => td { "—" },
                        }
                    }
                    "\n"
                }
            }
            "\n"
        }
        @if !rest.is_empty() {
            table class="compact" {
                "\n"
                @for (label, pointer, _) in &rest {
                    (row(label, c(pointer)))
                }
            }
            "\n"
        }
    }
}

/// The metric of `verify.json` the outcome judges.
const JUDGED_METRIC: &str = "area_miss_distance_decided";

fn converge_block(k: usize, json: &Value) -> Markup {
    let file = verify_label(k, "converge.json");
    let c = |p: &str| cite(&file, json, p);
    html! {
        p class="headline" {
            "Convergence study: recommended pitch " b { (c("/recommended_pitch_mm")) " mm" }
            " for a tolerance of " (c("/tolerance_mm"))
            " mm; predicted full analysis time at that pitch " (c("/predicted_full_time_s"))
            " s; pitches studied: " (c("/pitches_mm")) " mm."
        }
        "\n"
        @if let Some(Value::Object(fits)) = json.get("fits") {
            table class="compact" {
                "\n"
                tr { th { "metric" } th class="num" { "alpha (order)" } th class="num" { "C" } }
                "\n"
                @for name in fits.keys() {
                    @let base = format!("/fits/{}", escape_pointer(name));
                    tr {
                        td {
                            "error " (ASYMP) " C " (MIDDOT) " pitch" sup { "alpha" } ": " (name)
                        }
                        @if fits.get(name).is_some_and(Value::is_null) {
                            td colspan="2" {
                                "no order: exact (at most rounding, 1e-9 mm) at every pitch, or above it at fewer than two"
                            }
                        } @else {
                            td class="num" { (c(&format!("{base}/alpha"))) }
                            td class="num" { (c(&format!("{base}/c"))) }
                        }
                    }
                    "\n"
                }
            }
            "\n"
        }
    }
}

/// Rows of a CSV the report shows at most; a longer file shows its worst
/// rows and is attached whole.
const SHOWN_ROWS: usize = 20;

/// The columns a `verify.csv` row is ranked by, worst first: the largest
/// absolute value among them (an empty cell counts 0).
const RANKED_BY: [&str; 5] = [
    "miss_distance_decided",
    "false_alarm_distance_unexplained",
    "first_contact_error_decided",
    "push_error",
    // `converge.csv`'s: each metric's largest value at each pitch.
    "max",
];

/// A CSV file as a table, its cells as written in the file. A file of more
/// than [`SHOWN_ROWS`] rows shows its header and the [`SHOWN_ROWS`] rows
/// largest by [`RANKED_BY`] (in file order where equal), and is attached
/// whole as a download inside the page: a verification of 6,100
/// start-angle pairs once printed as 100 pages.
fn csv_table(name: &str, text: &str) -> Markup {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut records: Vec<csv::StringRecord> = reader.records().flatten().collect();
    let header = if records.is_empty() {
        csv::StringRecord::new()
    } else {
        records.remove(0)
    };
    let total = records.len();
    let columns: Vec<usize> = RANKED_BY
        .iter()
        .filter_map(|c| header.iter().position(|h| h == *c))
        .collect();
    let key = |r: &csv::StringRecord| -> f64 {
        columns
            .iter()
            .filter_map(|&k| r.get(k)?.parse::<f64>().ok())
            .map(f64::abs)
            .fold(0.0, |m, v| if v > m || v.is_nan() { v } else { m })
    };
    let shown: Vec<&csv::StringRecord> = if total > SHOWN_ROWS && !columns.is_empty() {
        let mut ranked: Vec<(usize, f64)> = records
            .iter()
            .enumerate()
            .map(|(k, r)| (k, key(r)))
            .collect();
        ranked.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        ranked
            .iter()
            .take(SHOWN_ROWS)
            .map(|&(k, _)| &records[k])
            .collect()
    } else {
        records.iter().take(SHOWN_ROWS).collect()
    };
    html! {
        table class="csv" {
            caption {
                code { (name) }
                @if total > SHOWN_ROWS {
                    @if columns.is_empty() {
                        ": the first " (SHOWN_ROWS) " of " (total) " rows"
                    } @else {
                        ": the " (SHOWN_ROWS) " of " (total) " rows with the largest "
                        (columns.iter().map(|&k| &header[k]).collect::<Vec<_>>().join(", "))
                    }
                    "; every row in the attached file: "
                    a download=(name) href={ "data:text/csv;base64," (super::html::base64(text.as_bytes())) } {
                        "download " (name)
                    }
                }
            }
            "\n"
            tr {
                @for f in &header {
                    th class="num" { (f) }
                }
            }
            "\n"
            @for record in &shown {
                tr {
                    @for f in *record {
                        td class="num" { (f) }
                    }
                }
                "\n"
            }
        }
        "\n"
        // In print, a wide table (verify.csv's 27 columns) lost its last
        // columns past the page's edge: it is printed instead as parts
        // of a few columns each, every part with the key columns first.
        @let parts = printed_parts(header.len());
        @if parts.len() > 1 {
            @for (k, part) in parts.iter().enumerate() {
                table class="csv-print" {
                    caption {
                        code { (name) } ", columns " (part[PRINTED_KEYS] + 1) " to " (part[part.len() - 1] + 1)
                        " of " (header.len()) " (printed part " (k + 1) " of " (parts.len()) ")"
                        @if shown.len() > PRINTED_ROWS {
                            ": the first " (PRINTED_ROWS) " of the " (shown.len()) " rows shown on screen"
                        }
                    }
                    tr {
                        @for &c in part {
                            th class="num" { (header.get(c).unwrap_or("")) }
                        }
                    }
                    @for record in shown.iter().take(PRINTED_ROWS) {
                        tr {
                            @for &c in part {
                                td class="num" { (record.get(c).unwrap_or("")) }
                            }
                        }
                    }
                }
                "\n"
            }
        }
    }
}

/// The rows a printed part of a CSV table holds: the first of those
/// shown (the largest, where the table is ranked), so that a table
/// printed in parts takes about the page it took in one.
const PRINTED_ROWS: usize = 10;

/// The columns a printed part of a CSV table repeats first (verify.csv's
/// `i, j, angle_deg`: which pair a row is).
const PRINTED_KEYS: usize = 3;

/// The columns a printed part holds besides its keys: as many as fit an
/// A4 page's width at the print stylesheet's size.
const PRINTED_COLUMNS: usize = 8;

/// The printed parts of a table of `columns` columns ([`csv_table`]):
/// each the key columns and the next [`PRINTED_COLUMNS`]; one part, the
/// whole table, when it fits.
fn printed_parts(columns: usize) -> Vec<Vec<usize>> {
    if columns <= PRINTED_KEYS + PRINTED_COLUMNS {
        return vec![(0..columns).collect()];
    }
    (PRINTED_KEYS..columns)
        .step_by(PRINTED_COLUMNS)
        .map(|start| {
            (0..PRINTED_KEYS)
                .chain(start..(start + PRINTED_COLUMNS).min(columns))
                .collect()
        })
        .collect()
}

/// Section 6: what the grid cannot see, how the pitch was chosen, and the
/// sentence a regulator reads.
fn resolution_section(inputs: &Inputs) -> Markup {
    let run = inputs.run;
    let j = &run.summary_json;
    let blind = &run.blind_spots;
    // The accuracy at this pitch: the figure a verification's outcome
    // judges (its decided area miss distance), where it passed, else the
    // pitch study's at the chosen pitch. A FAIL or INCONCLUSIVE
    // verification claims no bound: page one says why.
    let verified = inputs.verifications.iter().enumerate().find_map(|(k, v)| {
        let json = v.verify.as_ref()?;
        (v.verdict() == Verdict::Pass).then_some(())?;
        json.get("area_miss_decided_mm")?.as_f64()?;
        Some(cite(
            &verify_label(k, "verify.json"),
            json,
            "/area_miss_decided_mm",
        ))
    });
    let verified_no_claim = inputs
        .verifications
        .iter()
        .any(|v| v.verify.is_some() && v.verdict() != Verdict::Pass);
    let study_len = j
        .pointer("/pitch_study/study")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let studied = (study_len > 0)
        .then(|| {
            let pointer = format!(
                "/pitch_study/study/{}/exact_area_distance_mm",
                study_len - 1
            );
            j.pointer(&pointer)?.as_f64()?;
            Some(cite(SUMMARY, j, &pointer))
        })
        .flatten();
    let features = blind_features(blind);
    let places: Vec<String> = features
        .iter()
        .take(6)
        .map(|f| {
            let span = |lo: f64, hi: f64| {
                if hi - lo < 1.0 {
                    format!("{lo:.1}")
                } else {
                    format!("{lo:.0}..{hi:.0}")
                }
            };
            if f[2].is_finite() {
                format!(
                    "x = {}, y = {}, z = {}",
                    span(f[0], f[1]),
                    span(f[2], f[3]),
                    span(f[4], f[5])
                )
            } else {
                format!("x = {}, z = {}", span(f[0], f[1]), span(f[4], f[5]))
            }
        })
        .collect();
    let met = blind.iter().filter(|b| b.met_angles > 0).count();
    let finest = blind
        .iter()
        .map(|b| b.resolving_pitch_mm)
        .fold(f64::INFINITY, f64::min);
    let worst: Vec<&super::run::BlindRow> = {
        let mut v: Vec<&super::run::BlindRow> = blind.iter().collect();
        v.sort_by(|a, b| b.depth_mm.total_cmp(&a.depth_mm));
        v.truncate(12);
        v
    };
    html! {
        section id="resolution" {
            "\n"
            h2 { "6. Resolution" }
            "\n"
            p class="headline" {
                "At this pitch (" (cite(SUMMARY, j, "/pitch_mm")) " mm), "
                @if let Some(x) = &verified {
                    "every decided exact strike away from blind spots lies within " b { (x) " mm" } " of the grid's colliding area (a verification's PASS)"
                } @else if verified_no_claim {
                    "the verification claims no bound on the grid's area (its outcome, on page one, is not PASS)"
                } @else if let Some(x) = &studied {
                    "every decided exact strike away from blind spots lies within " b { (x) " mm" } " of the grid's colliding area on the pitch study's sampled starts"
                } @else {
                    "the distance of the grid's strikes to the exact ones is not measured here (no verification run given)"
                }
                "; " (features.len()) " features narrower than the pitch, sticking out more than "
                (cite(SUMMARY, j, "/blind_depth_mm")) " mm between the nodes ("
                (cite(SUMMARY, j, "/blind_spots")) " grid cells), were flagged"
                @if !places.is_empty() {
                    " at " (places.join("; "))
                    @if features.len() > places.len() { "; and " (features.len() - places.len()) " more" }
                    " (mm)"
                }
                "."
            }
            "\n"
            @if !blind.is_empty() {
                p {
                    (met) " of these cells the knee-form meets at some angle (their strikes are missing from the colliding area above); a pitch of "
                    (fmt_num(finest)) " mm resolves every one (a node lands on each wherever it lies). The deepest, from "
                    code { "blind_spots.csv" } ":"
                }
                "\n"
                table class="compact" {
                    "\n"
                    tr { th { "x (mm)" } th { "y (mm)" } th { "z (mm)" } th { "depth missed (mm)" } th { "width (mm)" } th { "resolving pitch (mm)" } th { "angles meeting it" } }
                    "\n"
                    @for b in &worst {
                        tr { td { (fmt_num(b.x)) } td { (b.y.map_or(String::from("-"), fmt_num)) } td { (fmt_num(b.z)) } td { (fmt_num(b.depth_mm)) } td { (fmt_num(b.width_mm)) } td { (fmt_num(b.resolving_pitch_mm)) } td { (b.met_angles) } }
                        "\n"
                    }
                }
                "\n"
            }
            @if study_len > 0 {
                p {
                    "The pitch was chosen by a pitch study for a tolerance of "
                    (cite(SUMMARY, j, "/pitch_study/tolerance_mm")) " mm: "
                    (cite(SUMMARY, j, "/pitch_study/reason")) "."
                }
                "\n"
                table class="compact" {
                    "\n"
                    tr { th { "pitch (mm)" } th { "decided area miss distance (mm)" } th { "change from the coarser grid (mm)" } th { "predicted analysis (s)" } th { "memory (GiB)" } th { "meets" } }
                    "\n"
                    @for k in 0..study_len {
                        @let c = |f: &str| cite(SUMMARY, j, &format!("/pitch_study/study/{k}/{f}"));
                        tr { td { (c("pitch_mm")) } td { (c("exact_area_distance_mm")) } td { (c("grid_change_mm")) } td { (c("predicted_s")) } td { (c("memory_gib")) } td { (c("meets")) } }
                        "\n"
                    }
                }
                "\n"
            }
        }
        "\n"
    }
}

/// The blind spots grouped into features (cells touching, corners
/// included), each as its lowest points' extent `[x_lo, x_hi, z_lo, z_hi]`
/// (mm), largest first.
fn blind_features(blind: &[super::run::BlindRow]) -> Vec<[f64; 6]> {
    let index: std::collections::HashMap<(usize, usize), usize> = blind
        .iter()
        .enumerate()
        .map(|(k, b)| ((b.i, b.j), k))
        .collect();
    let mut feature = vec![usize::MAX; blind.len()];
    let mut out: Vec<([f64; 6], usize)> = Vec::new();
    for start in 0..blind.len() {
        if feature[start] != usize::MAX {
            continue;
        }
        let id = out.len();
        // x, y and z, each from lowest to highest; y stays infinite in
        // files of versions that wrote no `y`.
        let mut extent = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut cells = 0;
        let mut stack = vec![start];
        feature[start] = id;
        while let Some(k) = stack.pop() {
            let b = &blind[k];
            let y = b.y.map_or([f64::INFINITY, f64::NEG_INFINITY], |y| [y, y]);
            extent = [
                extent[0].min(b.x),
                extent[1].max(b.x),
                extent[2].min(y[0]),
                extent[3].max(y[1]),
                extent[4].min(b.z),
                extent[5].max(b.z),
            ];
            cells += 1;
            for (di, dj) in [
                (-1, -1),
                (-1, 0),
                (-1, 1),
                (0, -1),
                (0, 1),
                (1, -1),
                (1, 0),
                (1, 1),
            ] {
                let (Some(i), Some(j)) = (b.i.checked_add_signed(di), b.j.checked_add_signed(dj))
                else {
                    continue;
                };
                if let Some(&n) = index.get(&(i, j))
                    && feature[n] == usize::MAX
                {
                    feature[n] = id;
                    stack.push(n);
                }
            }
        }
        out.push((extent, cells));
    }
    out.sort_by_key(|f| std::cmp::Reverse(f.1));
    out.into_iter().map(|(e, _)| e).collect()
}

fn runtime_section(run: &Run) -> Markup {
    let j = &run.summary_json;
    let labels = [
        ("read_s", "Reading and hashing the part"),
        ("sample_s", "Sampling the height grid"),
        ("push_slide_s", "Push and slide, every angle"),
        ("blind_s", "Finding the blind spots"),
        ("check_s", "The sample check against the exact oracle"),
        ("write_s", "Writing the result files"),
        ("total_s", "Total"),
    ];
    // The stages in pipeline order, then any the file adds.
    let stages: Vec<(&str, &str)> = match j.get("timings") {
        Some(Value::Object(t)) => labels
            .iter()
            .filter(|(k, _)| t.contains_key(*k))
            .copied()
            .chain(
                t.keys()
                    .filter(|k| !labels.iter().any(|(l, _)| l == k))
                    .map(|k| (k.as_str(), k.as_str())),
            )
            .collect(),
        _ => Vec::new(),
    };
    html! {
        section id="runtime" {
            "\n"
            h2 { "7. Runtime" }
            "\n"
            table class="compact" {
                "\n"
                @for (key, label) in stages {
                    (row(label, html! {
                        (cite(SUMMARY, j, &format!("/timings/{}", escape_pointer(key)))) " s"
                    }))
                }
                (row("Worker threads", cite(SUMMARY, j, "/threads")))
            }
            "\n"
        }
        "\n"
    }
}

fn run_figures_section(figures: &[(String, Vec<u8>)]) -> Markup {
    html! {
        @if !figures.is_empty() {
            section id="run-figures" {
                "\n"
                h2 { "8. Figures written by the run" }
                "\n"
                @for (name, png) in figures {
                    figure {
                        img class="plot" alt=(name) src=(png_uri(png));
                        figcaption { code { (name) } " (the grid as the engine saw it)" }
                    }
                    "\n"
                }
            }
            "\n"
        }
    }
}

/// Zones labelled on the face-on view, largest first.
const LABELLED_ZONES: usize = 12;
/// Zones listed in the report's table, largest first (`zones.csv` lists
/// them all).
const TABLED_ZONES: usize = 15;

/// The largest zones' ids ([`crate::zones`], from `summary.json`) at their
/// centroids on the face-on view `view`, as an SVG overlay on its picture;
/// specks are left out (the table names them).
fn zone_labels_svg(run: &super::run::Run, view: &super::render::View) -> Markup {
    let (w, h) = (view.width as f64, view.height as f64);
    let sign = view.horizontal_sign();
    let direct = run.summary.approach == Approach::Direct;
    let labels: Vec<(usize, f64, f64)> = run
        .summary
        .zones
        .iter()
        .filter(|z| !z.speck)
        .take(LABELLED_ZONES)
        .filter_map(|z| {
            let v = run.frame.to_vehicle(z.centroid);
            let across = if direct { v[1] } else { v[0] };
            let c = (sign * across - view.u_left) / view.mm_per_px;
            let r = (view.v_top - v[2]) / view.mm_per_px;
            ((0.0..=w).contains(&c) && (0.0..=h).contains(&r)).then_some((z.id, c, r))
        })
        .collect();
    html! {
        @if !labels.is_empty() {
            svg class="axes-overlay" viewBox=(format!("0 0 {w} {h}")) role="img"
                aria-label="the largest struck zones' ids" {
                @for (id, c, r) in labels {
                    @let width = 10.0 + 8.0 * id.to_string().len() as f64;
                    (svg_empty("rect", &[("x", &format!("{:.1}", c - width / 2.0)), ("y", &format!("{:.1}", r - 9.0)), ("width", &format!("{width:.1}")), ("height", &"18"), ("fill", &"white"), ("fill-opacity", &"0.85"), ("stroke", &"#222")]))
                    text x=(format!("{c:.1}")) y=(format!("{:.1}", r + 5.0)) font-size="13" text-anchor="middle" { (id) }
                }
            }
        }
    }
}

/// The struck zones' table (the largest [`TABLED_ZONES`], from
/// `summary.json`'s `zones`); a run of an earlier version says it has
/// none listed.
fn zones_table(run: &super::run::Run, undecided: Option<&super::undecided::Undecided>) -> Markup {
    let s = &run.summary;
    let j = &run.summary_json;
    let specks = s.zones.iter().filter(|z| z.speck).count();
    let touched = undecided.and_then(|u| u.zones_touched(run));
    html! {
        @if s.zones.is_empty() {
            @if s.composite_nodes > 0 {
                p class="note" { "This run lists no struck zones (a run of an earlier version): analyse it again for " code { "zones.csv" } "." }
            }
        } @else {
            p {
                b { "Struck zones: " } (s.zones.len()) " connected areas of the composite (8-connected nodes), "
                (specks) " of them specks under " (crate::zones::SPECK_NODES) " nodes, each listed beside the zone nearest it; the "
                (s.zones.len().min(TABLED_ZONES)) " largest below, all in " code { "zones.csv" } ". Coordinates in mm, the part's own."
                @if let (Some(u), Some(t)) = (undecided, &touched) {
                    " An undecided boundary touches a zone when a node of the zone is on or next to (8-adjacent) one of verification "
                    (u.k + 1) "'s undecided nodes (hatched above): "
                    (t.iter().filter(|&&b| b).count()) " of the " (t.len()) " zones."
                }
            }
            "\n"
            table class="compact" id="zones-table" {
                tr {
                    th { "zone" } th { "area (mm" (SUP2) ")" } th { "centroid x, y, z" } th { "angles striking it (degrees)" } th { "most angles at a node" } th { "blind spot touches it" }
                    @if touched.is_some() { th { "undecided boundary touches it" } }
                    th { "speck beside zone" }
                }
                @for (k, z) in s.zones.iter().enumerate().take(TABLED_ZONES) {
                    @let at = |field: &str| cite(SUMMARY, j, &format!("/zones/{k}/{field}"));
                    tr {
                        td { (at("id")) }
                        td { (at("area_mm2")) }
                        td { (at("centroid/0")) ", " (at("centroid/1")) ", " (at("centroid/2")) }
                        td { (at("angle_runs")) }
                        td { (at("max_count")) }
                        td { (at("touches_blind_spot")) }
                        @if let Some(t) = &touched {
                            td class="undecided-touch" { (if t[k] { "yes" } else { "no" }) }
                        }
                        td { @if z.beside.is_some() { (at("beside")) } @else { "-" } }
                    }
                }
            }
            "\n"
        }
    }
}

/// What changed from an earlier revision of the part (`report RUN
/// --compare EARLIER_RUN`, [`super::diff`]): first on the page, since a
/// designer comparing revisions reads it first.
fn revision_section(d: &super::diff::RevisionDiff, png: &[u8]) -> Markup {
    use super::diff::{NodeState, ZoneChange};
    let cell = d.cell_mm2();
    let area = |s: NodeState| fmt_num(d.count(s) as f64 * cell);
    let changed: Vec<&super::diff::ZoneDiff> = d
        .zones
        .iter()
        .filter(|z| z.change != ZoneChange::Unchanged)
        .collect();
    let word = |c: ZoneChange| match c {
        ZoneChange::Appeared => "appeared",
        ZoneChange::Vanished => "vanished",
        ZoneChange::Grew => "grew",
        ZoneChange::Shrank => "shrank",
        ZoneChange::Unchanged => "unchanged",
    };
    let ids = |v: &[usize]| {
        v.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    html! {
        section id="revision" {
            "\n"
            h2 { "Changes from the earlier revision" }
            "\n"
            p class="headline" {
                "Against " code { (d.a_dir.display()) } " (part " code { (d.a.input_file) } "): struck only in the earlier revision "
                b { (area(NodeState::OnlyA)) " mm" (SUP2) } ", only in this one "
                b { (area(NodeState::OnlyB)) " mm" (SUP2) } ", in both " (area(NodeState::Both)) " mm" (SUP2)
                "; " (changed.len()) " zones changed. " (d.mapping) " (the earlier revision's grid, as "
                code { "kneeform diff" } " compares them)."
            }
            "\n"
            @if !changed.is_empty() {
                table class="compact" id="revision-table" {
                    tr { th { "change" } th { "area before (mm" (SUP2) ")" } th { "area now (mm" (SUP2) ")" } th { "change (mm" (SUP2) ")" } th { "around x, z (mm)" } th { "zones before" } th { "zones now" } }
                    @for z in changed.iter().take(20) {
                        tr {
                            td { (word(z.change)) }
                            td { (fmt_num(z.area_a_mm2)) }
                            td { (fmt_num(z.area_b_mm2)) }
                            td { (fmt_num(z.change_mm2)) }
                            td { (fmt_num(z.centroid_xz[0])) ", " (fmt_num(z.centroid_xz[1])) }
                            td { (ids(&z.a_zones)) }
                            td { (ids(&z.b_zones)) }
                        }
                    }
                }
                "\n"
            }
            figure {
                img class="view" id="revision-view" alt="nodes struck only before, only now, and in both"
                    src={ "data:image/png;base64," (super::html::base64(png)) };
                figcaption {
                    "The earlier revision's grid face on, x to the right and z up, one square per node: orange struck only before, blue only now, purple in both, grey in neither."
                }
            }
            "\n"
        }
        "\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A long `verify.csv` shows its header and its 20 worst rows, ranked
    /// by the largest decided figure, and carries the whole file as a
    /// download; a short one shows every row.
    #[test]
    fn a_long_csv_shows_its_worst_rows_and_attaches_the_file() {
        let mut text = String::from("i,j,miss_distance_decided,push_error\n");
        for k in 0..50 {
            // Row k's worst figure is k (the push error, negative, on odd
            // rows), so rows 30..49 are the worst 20.
            let (miss, push) = if k % 2 == 0 {
                (format!("{k}"), String::new())
            } else {
                ("0.5".into(), format!("-{k}"))
            };
            text += &format!("{k},{},{miss},{push}\n", k + 100);
        }
        let html = csv_table("verify.csv", &text).into_string();
        assert_eq!(html.matches("<tr>").count(), 1 + SHOWN_ROWS, "{html}");
        for k in 0..50 {
            let cell = format!("<td class=\"num\">{}</td>", k + 100);
            assert_eq!(html.contains(&cell), k >= 30, "row {k}");
        }
        let attached = format!(
            "data:text/csv;base64,{}",
            super::super::html::base64(text.as_bytes())
        );
        assert!(html.contains(&attached));
        assert!(html.contains("the 20 of 50 rows"), "{html}");
        let short: String = text.lines().take(11).map(|l| format!("{l}\n")).collect();
        let html = csv_table("verify.csv", &short).into_string();
        assert_eq!(html.matches("<tr>").count(), 11);
        assert!(!html.contains("download"));
    }

    /// The numbers of an SVG attribute `name` in `svg`, in order.
    fn attribute_values(svg: &str, name: &str) -> Vec<f64> {
        svg.match_indices(&format!(" {name}=\""))
            .filter_map(|(at, m)| {
                let rest = &svg[at + m.len()..];
                rest[..rest.find('"')?].parse().ok()
            })
            .collect()
    }

    /// Issue 24, item 3: the knee-form is drawn to scale with the run's
    /// L, R and W: the outline at angle 0 is `L sqrt(3) / 2 + 2 R` wide
    /// and `L + 2 R` tall (SPEC), and its labels give the three values.
    #[test]
    fn the_knee_form_is_drawn_to_scale_with_its_dimensions() {
        for (l, r, w) in [(200.0, 60.0, 120.0), (190.0, 35.0, 80.0)] {
            let svg = knee_form_svg(l, r, w).into_string();
            for label in [
                format!("L = {l} mm"),
                format!("R = {r} mm"),
                format!("W = {w} mm"),
            ] {
                assert!(svg.contains(&label), "{label} missing");
            }
            // The second path is the outline at angle 0 (the first is the
            // raised one, dashed).
            let d = svg.split(" d=\"").nth(2).expect("the outline");
            let d = &d[..d.find('"').unwrap()];
            let points: Vec<[f64; 2]> = d
                .trim_end_matches('Z')
                .split_whitespace()
                .map(|p| {
                    let (a, b) = p[1..].split_once(',').unwrap();
                    [a.parse().unwrap(), b.parse().unwrap()]
                })
                .collect();
            let extent = |k: usize| {
                let v = points.iter().map(|p| p[k]);
                v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
            };
            let ratio = extent(0) / extent(1);
            let expected = (l * 3f64.sqrt() / 2.0 + 2.0 * r) / (l + 2.0 * r);
            assert!(
                (ratio - expected).abs() < 0.01 * expected,
                "{ratio} against {expected}"
            );
            assert!(svg.contains("reference point") && svg.contains("slides in -x"));
        }
    }

    /// Issue 24, item 3: the main image's mm ticks sit where the image's
    /// pixel mapping puts their values, for a left side (x to the right)
    /// and a right side (x to the left).
    #[test]
    fn the_axes_ticks_sit_at_their_coordinates() {
        use super::super::render::{Camera, View};
        use nalgebra::Vector3;
        for sign in [1.0, -1.0] {
            let view = View {
                camera: Camera::looking(Vector3::new(0.0, sign, 0.0), Vector3::z()),
                u_left: -10.0,
                v_top: 40.0,
                mm_per_px: 0.5,
                width: 200,
                height: 100,
            };
            assert_eq!(view.camera.right[0], sign);
            let svg = axes_svg(&view, "x").into_string();
            // The ticks' labels and their x (the first line's, per tick).
            let labels: Vec<f64> = svg
                .split("text-anchor=\"middle\">")
                .skip(1)
                .map(|t| t[..t.find('<').unwrap()].parse().unwrap())
                .collect();
            let xs: Vec<f64> = attribute_values(&svg, "x1");
            assert!(labels.len() >= 5, "{svg}");
            for (v, c) in labels.iter().zip(&xs) {
                // The horizontal coordinate at pixel edge c is sign * (u_left + c mm).
                assert!(
                    (sign * (-10.0 + c * 0.5) - v).abs() < 0.05 + 1e-9,
                    "{v} at {c}"
                );
            }
            // z ticks: row r holds z = v_top - r mm.
            assert!(svg.contains("z (mm)") && svg.contains("x (mm, vehicle frame)"));
        }
        assert_eq!(tick_step(9.0), 10.0);
        assert_eq!(tick_step(10.0), 10.0);
        assert_eq!(tick_step(11.0), 20.0);
        assert_eq!(tick_step(0.3), 0.5);
    }
}
