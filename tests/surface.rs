//! SPEC v4's surface level (`--level surface`): the engine's masks against
//! a brute force transcribed from SPEC that evaluates everything
//! (`util::brute_force_surface`), on seeded random grids, rough and
//! gentle, at several angles, deflection thresholds and windows from below
//! a pitch to several pitches; on each grid and angle the surface level
//! strikes differently from the node level, so the level is what is
//! tested.

use kneeform::strike::Level;
use kneeform::{EngineOptions, GridFootprint, HeightGrid, KneeForm, StrikeRule, colliding_masks};

use crate::util::{SEEDS, brute_force_surface, mask_diff, random_grid_quantised};

/// A knee-form a few pitches across, so that brute force stays quick.
const TINY: KneeForm = KneeForm {
    triangle_side: 9.0,
    radius: 3.0,
    thickness: 120.0,
};

fn masks(grid: &HeightGrid, angle: f64, rule: StrikeRule) -> kneeform::AngleMask {
    let fp = GridFootprint::new(&TINY, angle, &grid.spec);
    let options = EngineOptions {
        rule,
        ..EngineOptions::default()
    };
    colliding_masks(grid, std::slice::from_ref(&fp), &options, &|| {}).remove(0)
}

/// Every case: the engine equals brute force (mask and placed starts);
/// on every grid and angle the surface level strikes differently from
/// the node level under some of the rules.
fn check(pitch: f64, quantum: f64) {
    let mut struck = 0;
    for &seed in &SEEDS[..2] {
        let grid = random_grid_quantised(seed, 26, 20, pitch, quantum);
        for angle in [-30.0, 17.0] {
            let mut differs = 0;
            for (deflection, window) in [(0.0, 0.6 * pitch), (0.5, 5.0), (3.0, 4.5 * pitch)] {
                let node = StrikeRule::new(deflection, StrikeRule::DEFAULT_E0).with_window(window);
                let rule = node.with_level(Level::Surface);
                let at = format!(
                    "seed {seed:#x}, pitch {pitch}, quantum {quantum}, angle {angle}, \
                     deflection {deflection}, window {window}"
                );
                let got = masks(&grid, angle, rule);
                let (want, placed) =
                    brute_force_surface(&grid, &TINY, angle, (rule.e0, rule.sigma, rule.window));
                assert_eq!(
                    got.mask,
                    want,
                    "{at}: {}",
                    mask_diff(&grid, &got.mask, &want)
                );
                assert_eq!(got.placed, placed, "{at}");
                let by_node = masks(&grid, angle, node);
                differs += usize::from(got.mask != by_node.mask);
                struck += got.colliding;
            }
            assert!(
                differs > 0,
                "seed {seed:#x}, pitch {pitch}, angle {angle}: the level changed nothing"
            );
        }
    }
    assert!(struck > 100, "{struck}");
}

#[test]
fn the_surface_level_equals_brute_force_on_rough_grids() {
    check(1.0, 0.5);
}

#[test]
fn the_surface_level_equals_brute_force_on_gentle_grids() {
    check(0.7, 0.001);
}

/// `--level surface` end to end: `analyze` and `verify` record the level
/// they ran (`node` by default) and the surface level strikes otherwise
/// than the node level on the bump; asked with what it has no form for
/// (`--rate x-slope`, `--algorithm paper`, `--approach direct`) it is
/// refused in one line naming `--level`.
#[test]
fn the_level_is_a_flag_recorded_by_every_run_and_refused_where_it_has_no_form() {
    let dir = crate::util::scratch_dir("surface-level-cli");
    let bump = crate::util::scenario("bump");
    let small = [
        "--pitch",
        "4",
        "--angles=-10,0",
        "--triangle-side",
        "40",
        "--radius",
        "12",
    ];
    let out = |name: &str| dir.join(name).display().to_string();
    let analyze = |level: &str| {
        let o = out(&format!("analyze-{level}"));
        let mut args = vec![
            "analyze",
            bump.as_str(),
            "--out",
            o.as_str(),
            "--level",
            level,
        ];
        args.extend(small);
        crate::util::ok(crate::cli::kneeform(&args), "analyze");
        let text = std::fs::read_to_string(dir.join(format!("analyze-{level}/summary.json")))
            .expect("summary.json");
        serde_json::from_str::<serde_json::Value>(&text).expect("JSON")
    };
    let (node, surface) = (analyze("node"), analyze("surface"));
    assert_eq!(node["level"], "node");
    assert_eq!(surface["level"], "surface");
    assert_ne!(
        node["per_angle"], surface["per_angle"],
        "the level changed no strike"
    );
    let v = out("verify");
    let mut args = vec![
        "verify",
        bump.as_str(),
        "--out",
        v.as_str(),
        "--level",
        "surface",
        "--starts",
        "6",
        "--tolerance",
        "10",
    ];
    args.extend(small);
    let verify = crate::cli::kneeform(&args);
    // A study written: PASS, FAIL or INCONCLUSIVE (scattered starts are).
    assert!(
        matches!(verify.status.code(), Some(0 | 1 | 3)),
        "{}",
        String::from_utf8_lossy(&verify.stderr)
    );
    let text = std::fs::read_to_string(dir.join("verify/verify.json")).expect("verify.json");
    let json: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(json["level"], "surface", "{text}");
    for (flag, value) in [
        ("--rate", "x-slope"),
        ("--algorithm", "paper"),
        ("--approach", "direct"),
    ] {
        let o = out("refused");
        let mut args = vec!["analyze", bump.as_str(), "--out", o.as_str()];
        args.extend(small);
        args.extend(["--level", "surface", flag, value]);
        let run = crate::cli::kneeform(&args);
        crate::cli::assert_clean_failure(&run, &dir.join("refused"), flag);
        let stderr = crate::cli::said(&run);
        assert!(stderr.contains("--level"), "{flag}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
