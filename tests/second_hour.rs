//! The second hour of a new user (issue 24): what a safety engineer trips
//! on after the first run, one test per item.

use std::path::Path;

use crate::cli::kneeform;
use crate::util::{scenario, scratch_dir};

/// Runs `kneeform batch` on `manifest`, asserting that it succeeds.
fn batch_ok(manifest: &Path) {
    let o = kneeform(&["batch", &manifest.display().to_string()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The summary.json of the run in `dir`.
fn summary(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Item 12: `[defaults] args` were appended to an item's own, so a flag
/// in both (`--deflection` here, `--pitch` by name in one and in `args`
/// in the other) failed the item. The item's own value wins.
#[test]
fn a_batch_item_s_own_flag_replaces_the_defaults() {
    let dir = scratch_dir("second-hour-batch-defaults");
    std::fs::copy(scenario("bump"), dir.join("bump.toml")).unwrap();
    let manifest = dir.join("manifest.toml");
    std::fs::write(
        &manifest,
        r#"[defaults]
pitch = 8
angles = "0"
args = ["--deflection", "0.5", "--window", "4"]

[[item]]
part = "bump.toml"
out = "runs/own"
args = ["--deflection", "3", "--pitch=4"]

[[item]]
part = "bump.toml"
out = "runs/defaults"
"#,
    )
    .unwrap();
    batch_ok(&manifest);
    let own = summary(&dir.join("runs/own"));
    assert_eq!(own["deflection_deg"], 3.0, "{own}");
    assert_eq!(own["pitch_mm"], 4.0, "{own}");
    assert_eq!(
        own["window_mm"], 4.0,
        "the defaults' other flags stay: {own}"
    );
    let defaults = summary(&dir.join("runs/defaults"));
    assert_eq!(defaults["deflection_deg"], 0.5, "{defaults}");
    assert_eq!(defaults["pitch_mm"], 8.0, "{defaults}");
}
