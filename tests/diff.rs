//! `kneeform diff` (issue 43, item 2) on two revisions of a scenario,
//! where the geometry says what changed: a bump moved 40 mm in x leaves
//! its old place (a zone vanished there) for its new one (a zone
//! appeared); a rib added far from the bump adds a zone along the rib and
//! leaves the bump's unchanged. Runs that differ in what they compute are
//! refused.

use std::path::Path;

use crate::cli::kneeform;
use crate::util::{ok, scratch_dir};

/// A part: a flat wall 600 x 900 mm at a 2 mm tessellation with the
/// scenario `features` (TOML `[[feature]]` tables).
fn part(dir: &Path, name: &str, features: &str) -> String {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!("description = \"{name}\"\n[extent]\nx = [-300, 300]\nz = [-450, 450]\nstep = 2\n{features}"),
    )
    .unwrap();
    path.display().to_string()
}

fn bump(x: f64) -> String {
    format!("[[feature]]\nkind = \"bump\"\ncenter = [{x}, 0]\nradius = 40\nheight = 10\n")
}

/// `analyze` at 4 mm and three angles into `dir/out`, plus `extra` flags.
fn analyse(dir: &Path, part: &str, out: &str, extra: &[&str]) -> String {
    let out = dir.join(out).display().to_string();
    let mut args = vec![
        "analyze",
        part,
        "--pitch",
        "4",
        "--angles=-30,0,30",
        "--no-check",
    ];
    args.extend_from_slice(extra);
    args.extend(["--out", &out]);
    ok(kneeform(&args), "analyze");
    out
}

fn diff_json(dir: &Path, a: &str, b: &str) -> serde_json::Value {
    let out = dir.join("diff").display().to_string();
    ok(kneeform(&["diff", a, b, "--out", &out]), "diff");
    serde_json::from_slice(&std::fs::read(dir.join("diff/diff.json")).unwrap()).unwrap()
}

fn zones_of(json: &serde_json::Value, change: &str) -> Vec<serde_json::Value> {
    json["zones"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|z| z["change"] == change)
        .cloned()
        .collect()
}

/// The bump (radius 40 mm) struck within its disc grown by a pitch: moved
/// from x = 0 to x = 40, its zone vanishes around the old centre and one
/// appears around the new, 40 mm further in x.
#[test]
fn a_moved_bump_vanishes_where_it_was_and_appears_where_it_is() {
    let dir = scratch_dir("diff-moved");
    let a = analyse(&dir, &part(&dir, "a", &bump(0.0)), "a", &[]);
    let b = analyse(&dir, &part(&dir, "b", &bump(40.0)), "b", &[]);
    let json = diff_json(&dir, &a, &b);
    let (vanished, appeared) = (zones_of(&json, "vanished"), zones_of(&json, "appeared"));
    assert_eq!((vanished.len(), appeared.len()), (1, 1), "{json:#}");
    let x = |z: &serde_json::Value| z["centroid_xz"][0].as_f64().unwrap();
    let zc = |z: &serde_json::Value| z["centroid_xz"][1].as_f64().unwrap();
    assert!(x(&vanished[0]).abs() < 44.0 && zc(&vanished[0]).abs() < 44.0);
    assert!((x(&appeared[0]) - 40.0).abs() < 44.0 && zc(&appeared[0]).abs() < 44.0);
    // The same bump, the same grid: the zone moved by the bump's 40 mm.
    assert!(
        (x(&appeared[0]) - x(&vanished[0]) - 40.0).abs() <= 4.0,
        "{json:#}"
    );
    assert_eq!(vanished[0]["area_a_mm2"], appeared[0]["area_b_mm2"]);
    assert!(dir.join("diff/diff.png").is_file() && dir.join("diff/diff_zones.csv").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A rib 12 mm wide at its foot (a tent profile), 5 mm proud, along z
/// from 100 to 300 at x = -100, added to the part with the bump at z =
/// -300: the knee-form meets the rib's rear (+x) flank, rising far more
/// steeply than the threshold, at every angle, a new zone along the rib.
/// No footprint spans both (the knee-form is at most 2 (L/2 + R) = 320 mm
/// tall in z at these angles; 360 mm lie between the bump's disc and the
/// rib), so the bump's zone is unchanged.
#[test]
fn an_added_rib_appears_and_the_bump_is_unchanged() {
    let dir = scratch_dir("diff-rib");
    let bump = "[[feature]]\nkind = \"bump\"\ncenter = [0, -300]\nradius = 40\nheight = 10\n";
    let rib = "[[feature]]\nkind = \"rib\"\nfrom = [-100, 100]\nto = [-100, 300]\nwidth = 12\nheight = 5\n";
    let a = analyse(&dir, &part(&dir, "a", bump), "a", &[]);
    let b = analyse(&dir, &part(&dir, "b", &(bump.to_string() + rib)), "b", &[]);
    let json = diff_json(&dir, &a, &b);
    let appeared = zones_of(&json, "appeared");
    assert_eq!(appeared.len(), 1, "{json:#}");
    let [x, z] = [0, 1].map(|k| appeared[0]["centroid_xz"][k].as_f64().unwrap());
    assert!((x + 100.0).abs() <= 6.0 + 4.0, "{x}");
    assert!((100.0 - 4.0..=300.0 + 4.0).contains(&z), "{z}");
    let unchanged = zones_of(&json, "unchanged");
    assert_eq!(unchanged.len(), 1, "{json:#}");
    assert!(zones_of(&json, "vanished").is_empty() && zones_of(&json, "grew").is_empty());
    assert_eq!(json["only_a_nodes"], 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs under different strike rules are not two revisions of a part:
/// refused in one line, exit 2, nothing written.
#[test]
fn runs_computed_differently_are_refused() {
    let dir = scratch_dir("diff-refused");
    let p = part(&dir, "a", &bump(0.0));
    let a = analyse(&dir, &p, "a", &[]);
    let b = analyse(&dir, &p, "b", &["--deflection", "1"]);
    let out = dir.join("diff");
    let run = kneeform(&["diff", &a, &b, "--out", &out.display().to_string()]);
    let stderr = crate::cli::said(&run);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("deflection_deg"), "{stderr}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `report RUN --compare EARLIER_RUN` with a run of the same approach
/// opens the page with what changed: the moved bump's zone vanished from
/// where it was and appeared where it is, before section 1.
#[test]
fn the_report_opens_with_the_changes_from_an_earlier_revision() {
    let dir = scratch_dir("diff-report");
    let a = analyse(&dir, &part(&dir, "a", &bump(0.0)), "a", &[]);
    let b = analyse(&dir, &part(&dir, "b", &bump(40.0)), "b", &[]);
    let page = dir.join("report.html").display().to_string();
    ok(
        kneeform(&["report", &b, "--compare", &a, "--out", &page]),
        "report --compare",
    );
    let page = std::fs::read_to_string(&page).unwrap();
    let (revision, result) = (
        page.find("<section id=\"revision\"").expect("the changes"),
        page.find("<section id=\"result\"").expect("section 1"),
    );
    assert!(revision < result, "the changes come first");
    let table = &page[revision..result];
    assert!(table.contains("<td>vanished</td>") && table.contains("<td>appeared</td>"));
    assert!(table.contains("id=\"revision-view\""));
    std::fs::remove_dir_all(&dir).unwrap();
}
