//! Issue 39: the verdict a regulator can sign. A verification judges the
//! area the user gets and says PASS (exit 0), FAIL (1) or INCONCLUSIVE
//! (3); it never passes on nothing.

use std::path::Path;

use crate::cli::kneeform_in;
use crate::util::{scenario, scratch_dir};

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// "It passes on nothing": a flat wall strikes nothing, and a verification
/// of it was a green PASS (exit 0) with "largest distance 0 mm"; its
/// warning ("a pass here proves only that") was in no file. Now it is
/// INCONCLUSIVE, exit 3, the warning in verify.json; and `converge` on it
/// no longer says "exact at every pitch".
#[test]
fn a_verification_with_nothing_to_miss_is_inconclusive() {
    let dir = scratch_dir("verdict-nothing-to-miss");
    let wall = scenario("flat-wall");
    let o = kneeform_in(
        &dir,
        &["verify", &wall, "--pitch", "8", "--angles=0", "--out", "v"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("kneeform: INCONCLUSIVE at tolerance"), "{err}");
    let v = json(&dir.join("v/verify.json"));
    assert_eq!(v["outcome"], "INCONCLUSIVE");
    assert_eq!(v["pass"], false);
    assert!(
        v["outcome_reason"]
            .as_str()
            .unwrap()
            .contains("no decided exact strike"),
        "{v}"
    );
    assert!(
        v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("strikes nothing")),
        "{v}"
    );
    let o = kneeform_in(
        &dir,
        &[
            "converge",
            &wall,
            "--pitches",
            "8,4",
            "--angles=0",
            "--tolerance",
            "6",
            "--out",
            "c",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(!err.contains("exact at every pitch"), "{err}");
    assert!(err.contains("no error was measured"), "{err}");
    let c = json(&dir.join("c/converge.json"));
    assert_eq!(c["recommended_pitch_mm"], serde_json::Value::Null, "{c}");
    assert_eq!(c["verdicts"][0]["outcome"], "INCONCLUSIVE", "{c}");
}

/// "The README's evidence workflow (`--starts 6`, 17 pairs compared) puts
/// a green PASS on page 1": six scattered starts measure no area, so the
/// verification is INCONCLUSIVE (exit 3) and says why, where it exited 0
/// or 1 before.
#[test]
fn scattered_starts_are_inconclusive() {
    let dir = scratch_dir("verdict-scattered");
    let o = kneeform_in(
        &dir,
        &[
            "verify",
            &scenario("ramp"),
            "--pitch",
            "8",
            "--angles=-30,0,30",
            "--starts",
            "6",
            "--out",
            "v",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    let v = json(&dir.join("v/verify.json"));
    assert_eq!(v["outcome"], "INCONCLUSIVE", "{v}");
    let why = v["outcome_reason"].as_str().unwrap();
    assert!(
        why.contains("decided exact strikes, fewer than the 100")
            || why.contains("a sampled place of 1 start(s)"),
        "{why}"
    );
}

/// `verify --help` said exit 0 "when every decided metric is within
/// --tolerance", while it passed with decided false alarms of 64 mm: it
/// now names the figure judged and the three outcomes.
#[test]
fn verify_help_names_the_figure_judged_and_the_three_outcomes() {
    let o = kneeform_in(Path::new("."), &["verify", "--help"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!out.contains("every decided metric is within"), "{out}");
    for words in ["PASS (exit 0)", "FAIL (exit 1)", "INCONCLUSIVE (exit 3)"] {
        assert!(out.contains(words), "{words}: {out}");
    }
}
