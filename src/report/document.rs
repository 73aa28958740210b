//! The report as one self-contained HTML page: images inline as `data:`
//! URIs, charts and legends as inline SVG, a print stylesheet, no script
//! and no network.
//!
//! Sections, in order (each a `<section>` with this id):
//!
//! * `result`: the analysed side painted with the composite (the main
//!   image, `#main-view`), its legend, and the oblique view;
//! * `part`: the part's identity (file, SHA-256, triangles, bounding box,
//!   units);
//! * `method`: the knee-form (the assumed triangle side called out), grid,
//!   angles, side, software version and run date;
//! * `per-angle`: small multiples at -30, 0 and +30 degrees, a chart and a
//!   table of the colliding area per angle;
//! * `accuracy`: each verification run's metrics against its tolerance
//!   with the verdict, the convergence study and its recommended pitch;
//! * `runtime`: the run's timings;
//! * `run-figures`: the images the run wrote.

use std::fmt::Write as _;

use serde_json::Value;

use super::html::{cite, escape, fmt_num, png_uri, utc_date};
use super::run::Run;
use super::verify::{Verdict, Verification, escape_pointer, scalars};
use super::views::{ANGLE_COLOUR, Figure, Views, composite_colour, ramp_len};

/// The border colour of the main image: a blue no part shading or ramp
/// colour takes, so the image can be found in a screenshot of the page.
pub const MAIN_BORDER: [u8; 3] = [0, 90, 181];

/// The file name the report cites the run's summary as.
pub const SUMMARY: &str = "summary.json";

/// The citation prefix of the `k`-th verification directory's files.
pub fn verify_label(k: usize, file: &str) -> String {
    format!("verify[{k}]/{file}")
}

/// Everything the page is made of.
pub struct Inputs<'a> {
    /// The run.
    pub run: &'a Run,
    /// The verification directories, in the order given.
    pub verifications: &'a [Verification],
    /// The rendered views, already PNG-encoded alongside.
    pub views: &'a Views,
    /// PNG of [`Views::side`], [`Views::oblique`] and each small multiple,
    /// in that order.
    pub pngs: &'a [Vec<u8>],
    /// Images the run wrote (file name, bytes).
    pub run_figures: &'a [(String, Vec<u8>)],
}

/// The whole page.
pub fn document(inputs: &Inputs) -> String {
    let run = inputs.run;
    let s = &run.summary;
    let j = &run.summary_json;
    let mut out = String::new();
    let file_name = std::path::Path::new(&s.input_file).file_name().map_or_else(
        || s.input_file.clone(),
        |n| n.to_string_lossy().into_owned(),
    );
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"generator\" content=\"kneeform {}\">\n\
         <title>Knee-form collision evidence: {}</title>\n<style>{STYLE}img.main {{ border: 5px solid rgb({}, {}, {}); }}\n</style>\n</head>\n<body>\n",
        env!("CARGO_PKG_VERSION"),
        escape(&file_name),
        MAIN_BORDER[0],
        MAIN_BORDER[1],
        MAIN_BORDER[2],
    );
    let _ = write!(
        out,
        "<header><h1>Knee-form collision evidence</h1>\n<p class=\"subtitle\">{} &middot; UN Regulation No.&nbsp;21 knee-form push-and-slide (Inui, Gunji and Umezu) &middot; kneeform {} &middot; run of {}</p></header>\n",
        cite(SUMMARY, j, "/input_file"),
        cite(SUMMARY, j, "/kneeform_version"),
        escape(&utc_date(s.run_unix_time)),
    );
    result_section(&mut out, inputs);
    part_section(&mut out, run);
    method_section(&mut out, run);
    per_angle_section(&mut out, inputs);
    accuracy_section(&mut out, inputs.verifications);
    runtime_section(&mut out, run);
    run_figures_section(&mut out, inputs.run_figures);
    let _ = write!(
        out,
        "<footer>Written by kneeform {} from the run directory {}. Every value marked with a source comes from the run's files (<code>data-src</code> gives the file and JSON pointer).</footer>\n</body>\n</html>\n",
        env!("CARGO_PKG_VERSION"),
        escape(&run.dir.display().to_string())
    );
    out
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
.unknown { background: #eee; border: 2px solid #777; padding: 4px 10px; font-weight: bold; display: inline-block; }
.missing { color: #999; font-style: italic; }
.note { color: #333; font-size: 13px; }
.headline { font-size: 16px; }
footer { margin-top: 32px; font-size: 11px; color: #555; border-top: 1px solid #999; padding-top: 4px; }
* { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
@page { size: A4; margin: 12mm; }
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 10pt; }
  h2 { break-after: avoid; }
  section { break-before: auto; }
  figure, table.compact, .verdict { break-inside: avoid; }
  a { color: inherit; text-decoration: none; }
}
";

fn result_section(out: &mut String, inputs: &Inputs) {
    let run = inputs.run;
    let s = &run.summary;
    let j = &run.summary_json;
    let views = inputs.views;
    let n = ramp_len(run);
    let side_word = match s.side {
        crate::Side::Left => "from -y (the left side's outside), vehicle front (-x) on the left",
        crate::Side::Right => "from +y (the right side's outside), vehicle front (-x) on the right",
    };
    let _ = write!(
        out,
        "<section id=\"result\">\n<h2>1. Colliding area on the part</h2>\n\
         <p class=\"headline\">Area the knee-form can strike at some angle: <b>{} mm&sup2;</b> ({} grid nodes at {} mm pitch), over {} angles.</p>\n",
        cite(SUMMARY, j, "/composite_area_mm2"),
        cite(SUMMARY, j, "/composite_nodes"),
        cite(SUMMARY, j, "/pitch_mm"),
        s.angles_deg.len(),
    );
    let _ = write!(
        out,
        "<figure>\n{}\n{}\n<figcaption>The analysed side seen along the push, {side_word}, z up. Colour: the number of knee-form angles (of {n}) whose sliding knee-form strikes the point (the paper's Figure 13); grey: never struck. A point is coloured when it lies within half a pitch, in x and z, of a colliding grid node of <code>composite.csv</code>.</figcaption>\n</figure>\n",
        image_tag(&views.side, &inputs.pngs[0], "main-view", "view main", true),
        legend_svg(n),
    );
    let _ = write!(
        out,
        "<figure>\n{}\n<figcaption>Oblique view from the analysed side, in front of and above the part, with the same colours.</figcaption>\n</figure>\n</section>\n",
        image_tag(
            &views.oblique,
            &inputs.pngs[1],
            "oblique-view",
            "view",
            false
        ),
    );
}

/// An `<img>` of a rendered view; for the side views (`mapping`), its
/// pixel ↔ (x, z) mapping in data attributes: pixel `(c, r)` has its centre
/// at `x = x-sign * (u-left + (c + 0.5) * mm-per-px)`,
/// `z = v-top - (r + 0.5) * mm-per-px` (mm, part frame).
fn image_tag(figure: &Figure, png: &[u8], id: &str, class: &str, mapping: bool) -> String {
    let v = &figure.view;
    let map = if mapping {
        format!(
            " data-u-left=\"{}\" data-v-top=\"{}\" data-mm-per-px=\"{}\" data-x-sign=\"{}\"",
            v.u_left, v.v_top, v.mm_per_px, v.camera.right[0]
        )
    } else {
        String::new()
    };
    format!(
        "<img id=\"{id}\" class=\"{class}\" width=\"{}\" height=\"{}\" alt=\"{id}\"{map} src=\"{}\">",
        figure.image.width,
        figure.image.height,
        png_uri(png)
    )
}

/// The composite's colour ramp as an SVG bar, one swatch per count.
fn legend_svg(n: usize) -> String {
    let (w, bar_h) = (600.0, 18.0);
    let sw = w / n as f64;
    let mut svg = String::from(
        "<svg class=\"legend\" width=\"660\" height=\"62\" viewBox=\"0 0 660 62\" role=\"img\" aria-label=\"legend\">\n<text x=\"10\" y=\"13\" font-size=\"12\">number of angles striking the point</text>\n",
    );
    for c in 1..=n {
        let [r, g, b] = composite_colour(c as u16, n);
        let _ = writeln!(
            svg,
            "<rect x=\"{:.2}\" y=\"20\" width=\"{:.2}\" height=\"{bar_h}\" fill=\"rgb({r},{g},{b})\"/>",
            10.0 + (c - 1) as f64 * sw,
            sw + 0.3
        );
    }
    let mut ticks = vec![1, n];
    if n > 2 {
        ticks.insert(1, n.div_ceil(2));
    }
    ticks.dedup();
    for c in ticks {
        let _ = writeln!(
            svg,
            "<text x=\"{:.2}\" y=\"54\" font-size=\"12\" text-anchor=\"middle\">{c}</text>",
            10.0 + (c as f64 - 0.5) * sw
        );
    }
    svg.push_str("</svg>");
    svg
}

fn row(out: &mut String, label: &str, value: &str) {
    let _ = writeln!(out, "<tr><th>{label}</th><td>{value}</td></tr>");
}

fn part_section(out: &mut String, run: &Run) {
    let j = &run.summary_json;
    let c = |p: &str| cite(SUMMARY, j, p);
    out.push_str("<section id=\"part\">\n<h2>2. Part</h2>\n<table class=\"compact\">\n");
    row(out, "File", &format!("<code>{}</code>", c("/input_file")));
    row(out, "SHA-256", &format!("<code>{}</code>", c("/sha256")));
    row(
        out,
        "Re-read for this report",
        &format!(
            "<code>{}</code> (SHA-256 matches the run's)",
            escape(&run.part_path.display().to_string())
        ),
    );
    row(out, "Triangles in the file", &c("/triangles"));
    row(
        out,
        "Degenerate triangles (zero area, skipped)",
        &c("/degenerate_triangles"),
    );
    row(
        out,
        "Bounding box, min x, y, z (mm)",
        &(0..3)
            .map(|k| c(&format!("/bbox_min/{k}")))
            .collect::<Vec<_>>()
            .join(", "),
    );
    row(
        out,
        "Bounding box, max x, y, z (mm)",
        &(0..3)
            .map(|k| c(&format!("/bbox_max/{k}")))
            .collect::<Vec<_>>()
            .join(", "),
    );
    row(
        out,
        "Units",
        &format!("file units &times; {} = mm", c("/scale")),
    );
    row(out, "Analysed side", &c("/side"));
    out.push_str("</table>\n</section>\n");
}

fn method_section(out: &mut String, run: &Run) {
    let s = &run.summary;
    let j = &run.summary_json;
    let c = |p: &str| cite(SUMMARY, j, p);
    out.push_str(
        "<section id=\"method\">\n<h2>3. Knee-form and analysis</h2>\n<table class=\"compact\">\n",
    );
    let l = if s.triangle_side_assumed {
        format!(
            "{} mm <span class=\"assumed\">ASSUMED default: the regulation's value was not at hand; set it with --triangle-side</span>",
            c("/triangle_side_mm")
        )
    } else {
        format!("{} mm (given)", c("/triangle_side_mm"))
    };
    row(out, "Triangle side L", &l);
    row(out, "Rounding radius R", &format!("{} mm", c("/radius_mm")));
    row(out, "Thickness W", &format!("{} mm", c("/thickness_mm")));
    row(out, "Grid pitch", &format!("{} mm", c("/pitch_mm")));
    row(
        out,
        "Grid origin x, z",
        &format!("{}, {} mm", c("/grid_origin/0"), c("/grid_origin/1")),
    );
    row(
        out,
        "Grid size",
        &format!(
            "{} &times; {} nodes ({} with part under them)",
            c("/grid_size/0"),
            c("/grid_size/1"),
            c("/sampled_nodes")
        ),
    );
    row(
        out,
        "Angles (degrees)",
        &format!("{} ({} angles)", c("/angles_deg"), s.angles_deg.len()),
    );
    row(
        out,
        "Deflection threshold",
        &format!(
            "{} degrees (sigma = tan delta = {}; rate estimated as {}): a point the knee-form meets is a strike only when the surface there turns it aside by more than this angle",
            c("/deflection_deg"),
            c("/sigma"),
            c("/rate")
        ),
    );
    row(
        out,
        "Rounding tolerance e0",
        &format!("{} mm (absorbs floating-point rounding only)", c("/e0_mm")),
    );
    row(out, "Side", &c("/side"));
    row(out, "Algorithm", &c("/algorithm"));
    row(
        out,
        "Software",
        &format!("kneeform {}", c("/kneeform_version")),
    );
    row(
        out,
        "Run date",
        &format!(
            "{} ({} s since 1970)",
            escape(&utc_date(s.run_unix_time)),
            c("/run_unix_time")
        ),
    );
    out.push_str("</table>\n</section>\n");
}

fn per_angle_section(out: &mut String, inputs: &Inputs) {
    let run = inputs.run;
    let j = &run.summary_json;
    let [r, g, b] = ANGLE_COLOUR;
    out.push_str("<section id=\"per-angle\">\n<h2>4. Colliding area per angle</h2>\n");
    let _ = write!(out, "<figure>\n<div class=\"multiples\">\n");
    for (k, (angle, figure)) in inputs.views.per_angle.iter().enumerate() {
        let index = run
            .summary
            .angles_deg
            .iter()
            .position(|a| a == angle)
            .unwrap_or(0);
        let _ = writeln!(
            out,
            "<div>{}<div class=\"note\">angle {} degrees: {} mm&sup2;</div></div>",
            image_tag(
                figure,
                &inputs.pngs[2 + k],
                &format!("angle-view-{k}"),
                "view",
                true
            ),
            cite(SUMMARY, j, &format!("/per_angle/{index}/angle_deg")),
            cite(
                SUMMARY,
                j,
                &format!("/per_angle/{index}/colliding_area_mm2")
            ),
        );
    }
    let _ = write!(
        out,
        "</div>\n<figcaption>The analysed side at single knee-form angles (the paper's Figure 12): in <span style=\"color: rgb({r},{g},{b}); font-weight: bold\">red</span>, the points that angle strikes (<code>colliding_points.csv</code>).</figcaption>\n</figure>\n"
    );
    out.push_str(&area_chart_svg(run));
    out.push_str(
        "<table class=\"per-angle\">\n<tr><th class=\"num\">angle (deg)</th><th class=\"num\">placed starts</th><th class=\"num\">colliding nodes</th><th class=\"num\">colliding area (mm&sup2;)</th></tr>\n",
    );
    for k in 0..run.summary.per_angle.len() {
        let _ = writeln!(
            out,
            "<tr>{}</tr>",
            [
                "angle_deg",
                "placed_starts",
                "colliding_nodes",
                "colliding_area_mm2"
            ]
            .map(|f| format!(
                "<td class=\"num\">{}</td>",
                cite(SUMMARY, j, &format!("/per_angle/{k}/{f}"))
            ))
            .concat()
        );
    }
    out.push_str("</table>\n</section>\n");
}

/// Colliding area against angle, as an SVG line chart.
fn area_chart_svg(run: &Run) -> String {
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
    let mut svg = format!(
        "<figure>\n<svg class=\"chart\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" role=\"img\" aria-label=\"colliding area per angle\">\n\
         <line x1=\"{left}\" y1=\"{y0}\" x2=\"{x1}\" y2=\"{y0}\" stroke=\"#333\"/>\n\
         <line x1=\"{left}\" y1=\"{top}\" x2=\"{left}\" y2=\"{y0}\" stroke=\"#333\"/>\n",
        y0 = h - bottom,
        x1 = w - right,
    );
    for (v, anchor_y) in [(0.0, py(0.0)), (area_hi, py(area_hi))] {
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"end\">{}</text>",
            left - 6.0,
            anchor_y + 4.0,
            fmt_num(v)
        );
    }
    for a in [a_lo, a_hi] {
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\">{}</text>",
            px(a),
            h - bottom + 16.0,
            fmt_num(a)
        );
    }
    let _ = writeln!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\" text-anchor=\"middle\">angle (degrees)</text>\n<text x=\"14\" y=\"{:.1}\" font-size=\"12\" transform=\"rotate(-90 14 {:.1})\" text-anchor=\"middle\">area (mm&#178;)</text>",
        left + 0.5 * (w - left - right),
        h - 6.0,
        top + 0.5 * (h - top - bottom),
        top + 0.5 * (h - top - bottom),
    );
    let line: Vec<String> = pts
        .iter()
        .map(|&(a, v)| format!("{:.2},{:.2}", px(a), py(v)))
        .collect();
    let _ = writeln!(
        svg,
        "<polyline fill=\"none\" stroke=\"rgb(190,85,20)\" stroke-width=\"1.5\" points=\"{}\"/>",
        line.join(" ")
    );
    for &(a, v) in &pts {
        let _ = writeln!(
            svg,
            "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"2.2\" fill=\"rgb(190,85,20)\"/>",
            px(a),
            py(v)
        );
    }
    svg.push_str("</svg>\n<figcaption>Colliding area per angle (<code>summary.json</code>, <code>per_angle</code>).</figcaption>\n</figure>\n");
    svg
}

fn accuracy_section(out: &mut String, verifications: &[Verification]) {
    out.push_str("<section id=\"accuracy\">\n<h2>5. Accuracy</h2>\n");
    if verifications.is_empty() {
        out.push_str("<p class=\"unknown verdict\">Not verified: no verification run was given to this report, so the accuracy of the grid result against the exact oracle is not shown here. Run <code>kneeform verify</code> and <code>kneeform converge</code> and pass their directories to <code>kneeform report</code>.</p>\n</section>\n");
        return;
    }
    for (k, v) in verifications.iter().enumerate() {
        let _ = writeln!(
            out,
            "<h3>Verification run {}: <code>{}</code></h3>",
            k + 1,
            escape(&v.dir.display().to_string())
        );
        if let Some(json) = &v.verify {
            verify_block(out, k, json, v.verdict());
        }
        if let Some(json) = &v.converge {
            converge_block(out, k, json);
        }
        for (name, png) in &v.figures {
            let _ = writeln!(
                out,
                "<figure><img class=\"plot\" alt=\"{name}\" src=\"{}\"><figcaption><code>{name}</code></figcaption></figure>",
                png_uri(png)
            );
        }
        for (name, text) in [
            ("verify.csv", &v.verify_csv),
            ("converge.csv", &v.converge_csv),
        ] {
            if let Some(text) = text {
                csv_table(out, name, text);
            }
        }
    }
    out.push_str("</section>\n");
}

fn verify_block(out: &mut String, k: usize, json: &Value, verdict: Verdict) {
    let file = verify_label(k, "verify.json");
    let c = |p: &str| cite(&file, json, p);
    let tolerance = json.get("tolerance_mm").and_then(Value::as_f64);
    let (class, word) = match verdict {
        Verdict::Pass => ("pass", "PASS"),
        Verdict::Fail => ("fail", "FAIL"),
        Verdict::Unknown => ("unknown", "NO VERDICT IN FILE"),
    };
    let _ = writeln!(
        out,
        "<p class=\"{class} verdict\" id=\"verdict-{k}\">{word}: against a tolerance of {} mm at pitch {} mm (<code>verify.json</code> <code>pass</code> = {})</p>",
        c("/tolerance_mm"),
        c("/pitch_mm"),
        c("/pass")
    );
    if json.get("area_distance_decided_mm").is_some() {
        let _ = writeln!(
            out,
            "<p class=\"headline\">Area distance (decided strikes: the grid's colliding area against the exact one, both ways, in xz): <b>{} mm</b>; over all strikes, undecided included: {} mm. Deflection threshold {} degrees; {} exact contacts undecided (rate within the tie band: {}).</p>",
            c("/area_distance_decided_mm"),
            c("/area_distance_mm"),
            c("/deflection_deg"),
            c("/counts/exact_undecided"),
            c("/tie_band_rule")
        );
    }
    if let Some(Value::Object(metrics)) = json.get("metrics") {
        out.push_str("<table class=\"metrics\">\n<tr><th>metric (mm)</th><th class=\"num\">max</th><th class=\"num\">p95</th><th class=\"num\">mean</th><th class=\"num\">n</th><th>max within tolerance</th></tr>\n");
        for (name, m) in metrics {
            // Only decided metrics decide a verdict; the others (all
            // strikes, undecided included) are shown beside them.
            let decides = json.get("area_distance_decided_mm").is_none() || kneeform_decides(name);
            let base = format!("/metrics/{}", escape_pointer(name));
            let cells: String = ["max", "p95", "mean", "n"]
                .map(|f| format!("<td class=\"num\">{}</td>", c(&format!("{base}/{f}"))))
                .concat();
            let within = match (m.get("max").and_then(Value::as_f64), tolerance) {
                _ if !decides => "<td>shown, not a criterion</td>",
                (Some(max), Some(tol)) if max.abs() <= tol => "<td class=\"pass-cell\">yes</td>",
                (Some(_), Some(_)) => "<td class=\"fail-cell\"><b>no</b></td>",
                _ => "<td>—</td>",
            };
            let _ = writeln!(out, "<tr><td>{}</td>{cells}{within}</tr>", escape(name));
        }
        out.push_str("</table>\n");
    }
    let rest: Vec<(String, String, &Value)> = ["area_iou", "counts", "timings"]
        .iter()
        .filter_map(|key| json.get(*key).map(|v| (*key, v)))
        .flat_map(|(key, v)| scalars(v, &format!("/{key}"), key))
        .collect();
    if !rest.is_empty() {
        out.push_str("<table class=\"compact\">\n");
        for (label, pointer, _) in rest {
            row(out, &escape(&label), &c(&pointer));
        }
        out.push_str("</table>\n");
    }
}

/// Whether a metric of `verify.json` is one a verdict rests on.
fn kneeform_decides(name: &str) -> bool {
    crate::harness::DECIDED_METRICS.contains(&name)
}

fn converge_block(out: &mut String, k: usize, json: &Value) {
    let file = verify_label(k, "converge.json");
    let c = |p: &str| cite(&file, json, p);
    let _ = writeln!(
        out,
        "<p class=\"headline\">Convergence study: recommended pitch <b>{} mm</b> for a tolerance of {} mm; predicted full analysis time at that pitch {} s; pitches studied: {} mm.</p>",
        c("/recommended_pitch_mm"),
        c("/tolerance_mm"),
        c("/predicted_full_time_s"),
        c("/pitches_mm")
    );
    if let Some(Value::Object(fits)) = json.get("fits") {
        out.push_str("<table class=\"compact\">\n<tr><th>metric</th><th class=\"num\">alpha (order)</th><th class=\"num\">C</th></tr>\n");
        for name in fits.keys() {
            let base = format!("/fits/{}", escape_pointer(name));
            let _ = writeln!(
                out,
                "<tr><td>error &asymp; C &middot; pitch<sup>alpha</sup>: {}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
                escape(name),
                c(&format!("{base}/alpha")),
                c(&format!("{base}/c"))
            );
        }
        out.push_str("</table>\n");
    }
}

/// A CSV file as a table, its cells as written in the file.
fn csv_table(out: &mut String, name: &str, text: &str) {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    let _ = writeln!(
        out,
        "<table class=\"csv\"><caption><code>{name}</code></caption>"
    );
    for (k, record) in reader.records().flatten().enumerate() {
        let tag = if k == 0 { "th" } else { "td" };
        let cells: String = record
            .iter()
            .map(|f| format!("<{tag} class=\"num\">{}</{tag}>", escape(f)))
            .collect();
        let _ = writeln!(out, "<tr>{cells}</tr>");
    }
    out.push_str("</table>\n");
}

fn runtime_section(out: &mut String, run: &Run) {
    let j = &run.summary_json;
    out.push_str("<section id=\"runtime\">\n<h2>6. Runtime</h2>\n<table class=\"compact\">\n");
    let labels = [
        ("read_s", "Reading and hashing the part"),
        ("sample_s", "Sampling the height grid"),
        ("push_slide_s", "Push and slide, every angle"),
        ("write_s", "Writing the result files"),
        ("total_s", "Total"),
    ];
    if let Some(Value::Object(t)) = j.get("timings") {
        // The stages in pipeline order, then any the file adds.
        let known = labels.iter().filter(|(k, _)| t.contains_key(*k)).copied();
        let others = t
            .keys()
            .filter(|k| !labels.iter().any(|(l, _)| l == k))
            .map(|k| (k.as_str(), k.as_str()));
        for (key, label) in known.chain(others) {
            row(
                out,
                &escape(label),
                &format!(
                    "{} s",
                    cite(SUMMARY, j, &format!("/timings/{}", escape_pointer(key)))
                ),
            );
        }
    }
    row(out, "Worker threads", &cite(SUMMARY, j, "/threads"));
    out.push_str("</table>\n</section>\n");
}

fn run_figures_section(out: &mut String, figures: &[(String, Vec<u8>)]) {
    if figures.is_empty() {
        return;
    }
    out.push_str("<section id=\"run-figures\">\n<h2>7. Figures written by the run</h2>\n");
    for (name, png) in figures {
        let _ = writeln!(
            out,
            "<figure><img class=\"plot\" alt=\"{name}\" src=\"{}\"><figcaption><code>{name}</code> (the grid as the engine saw it)</figcaption></figure>",
            png_uri(png)
        );
    }
    out.push_str("</section>\n");
}
