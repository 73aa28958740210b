//! The report's 3D view as a CAD colour map (issue 43, item 3): inside the
//! canvas the vehicle axes, the colour legend, a scale bar and the largest
//! zones' ids; a pick names its zone; and a part too large for the page
//! (over 400,000 triangles) is drawn simplified, saying so, instead of not
//! at all. Checked in headless Chromium (skipped where it is not
//! installed; CI installs it).

use std::path::Path;

use crate::cli::kneeform_in;
use crate::util::{headless, ok, scratch_dir};

/// The page's DOM once its scripts have run (virtual time: image decoding
/// is waited for).
fn dom(page: &Path, dir: &Path) -> Option<String> {
    let args = [
        "--virtual-time-budget=30000".to_string(),
        "--dump-dom".to_string(),
    ];
    let out = headless(page, dir, "3D view check", &args)?;
    Some(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The value of attribute `name` of the 3D view's figure.
fn figure_attribute<'a>(dom: &'a str, name: &str) -> Option<&'a str> {
    let start = dom.find("<figure class=\"view3d\"")?;
    let open = &dom[start..start + dom[start..].find('>')?];
    let at = open.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&open[at..at + open[at..].find('"')?])
}

/// A bump tessellated into more than 400,000 triangles: the view draws its
/// face towards the knee-form simplified (and says so), paints the struck
/// flank, draws axes, legend, scale bar and the zone's id, and a click on
/// a point struck at every angle names zone 1; the page stays under 5 MB.
#[test]
fn a_part_over_the_page_s_budget_is_drawn_simplified_with_its_overlay() {
    let dir = scratch_dir("view3d-large");
    ok(
        kneeform_in(
            &dir,
            &[
                "scenario",
                "bump",
                "--triangles",
                "450000",
                "--out",
                "part.stl",
            ],
        ),
        "scenario",
    );
    ok(
        kneeform_in(
            &dir,
            &[
                "analyze",
                "part.stl",
                "--pitch",
                "4",
                "--angles=-30,0,30",
                "--no-check",
                "--out",
                "run",
            ],
        ),
        "analyze",
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("run/summary.json")).unwrap()).unwrap();
    let triangles = summary["triangles"].as_u64().unwrap();
    assert!(triangles > 400_000, "{triangles} triangles");
    ok(
        kneeform_in(&dir, &["report", "run", "--out", "report.html"]),
        "report",
    );
    let size = std::fs::metadata(dir.join("report.html")).unwrap().len();
    assert!(size < 5_000_000, "the report is {size} bytes");
    let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(
        page.contains("Simplified:"),
        "the caption says what was simplified"
    );
    let probe = include_str!("view3d_probe.html");
    std::fs::write(
        dir.join("probe.html"),
        page.replace("</body>", &format!("{probe}</body>")),
    )
    .unwrap();
    let Some(dom) = dom(&dir.join("probe.html"), &dir) else {
        return;
    };
    assert_eq!(figure_attribute(&dom, "data-state"), Some("drawn"));
    assert_eq!(
        figure_attribute(&dom, "data-simplified"),
        Some(triangles.to_string().as_str())
    );
    assert_eq!(
        figure_attribute(&dom, "data-overlay"),
        Some("axes legend scale-bar zones:1")
    );
    let coloured: usize = figure_attribute(&dom, "data-coloured-pixels")
        .and_then(|v| v.parse().ok())
        .expect("coloured pixels counted");
    assert!(coloured > 100, "{coloured} painted pixels");
    let start = dom.find("view3d-pick").expect("the readout");
    let readout = &dom[start..start + dom[start..].find("</p>").unwrap()];
    assert!(readout.contains("in zone 1 (zones.csv)"), "{readout}");
    assert!(readout.contains("struck at 3 of 3 angles"), "{readout}");
    std::fs::remove_dir_all(&dir).unwrap();
}
