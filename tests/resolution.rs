//! Blind spots: the grid must say where it cannot see the part (issue
//! "show where the grid is blind"), and stay quiet on smooth parts.

use kneeform::blind::BlindSpot;
use kneeform::{Analysis, Setup, Side};

use crate::util::scenario_file;

/// The blind spots of a scenario at `pitch`, angles -30, 0 and 30.
fn blind_spots(name: &str, pitch: f64) -> Vec<BlindSpot> {
    let setup = Setup {
        pitch,
        angles: vec![-30.0, 0.0, 30.0],
        ..Setup::default()
    };
    Analysis::of_file(&scenario_file(name), 1.0, Side::Left, &setup, &())
        .unwrap()
        .blind_spots
}

#[test]
fn thin_ribs_are_blind_spots_where_no_node_lands_on_them() {
    // scenarios/thin-rib.toml: two tents 0.6 mm wide at the foot and 5 mm
    // proud, one across the slide (crest x = 10.3, z in -100..100), one
    // along it (crest z = 40.3, x in -250..-50). Nodes sit on multiples of
    // the pitch, so at 4, 2 and 1 mm the nearest node columns are x = 10
    // (the foot, 0.3 mm from the crest: height 0) and the next; no node
    // lands on the proud part of either rib.
    for pitch in [4.0, 2.0, 1.0] {
        let spots = blind_spots("thin-rib", pitch);
        let across: Vec<&BlindSpot> = spots
            .iter()
            .filter(|s| (s.x - 10.3).abs() <= pitch && (-100.0..=100.0).contains(&s.z))
            .collect();
        let along: Vec<&BlindSpot> = spots
            .iter()
            .filter(|s| (s.z - 40.3).abs() <= pitch && (-250.0..=-50.0).contains(&s.x))
            .collect();
        // Every cell row (column) the rib crosses is flagged: its length
        // over the pitch, give or take the cells at its ends.
        assert!(
            across.len() as f64 >= 200.0 / pitch - 2.0,
            "{pitch} mm: {} cells on the rib across",
            across.len()
        );
        assert!(
            along.len() as f64 >= 200.0 / pitch - 2.0,
            "{pitch} mm: {} cells on the rib along",
            along.len()
        );
        assert_eq!(across.len() + along.len(), spots.len(), "{pitch} mm");
        for s in across.iter().chain(&along) {
            // The tent's crest is 5 mm proud of the nodes around it.
            assert!(s.depth_missed_mm > 4.9 && s.depth_missed_mm <= 5.0, "{s:?}");
            // No larger than the rib's 0.6 mm width, and a nested pitch.
            assert!(s.resolving_pitch_mm <= 0.6, "{s:?}");
            let halvings = (pitch / s.resolving_pitch_mm).log2();
            assert!((halvings - halvings.round()).abs() < 1e-9, "{s:?}");
            // The sliding knee-form meets a 5 mm rib on a flat wall.
            assert!(!s.met_angles_deg.is_empty(), "{s:?}");
        }
    }
}

#[test]
fn smooth_parts_have_no_blind_spot() {
    for name in ["flat-wall", "ramp", "wave", "growing-wave", "tilted-wave"] {
        for pitch in [4.0, 2.0, 1.0] {
            let spots = blind_spots(name, pitch);
            assert!(
                spots.is_empty(),
                "{name} at {pitch} mm: {:?}",
                spots.first()
            );
        }
    }
}

#[test]
fn the_consoles_thin_rib_is_met_at_the_default_pitch() {
    // scenarios/console.toml: a rib 0.6 mm wide, 5 mm proud, crest at
    // x = 1000.3 from z = 60 to 330; the default pitch's nodes (multiples
    // of 1.24 mm) are at x = 999.72 and 1000.96, both off its crest by
    // more than its 0.3 mm half-width.
    let pitch = Setup::default().pitch;
    let spots = blind_spots("console", pitch);
    let rib: Vec<&BlindSpot> = spots
        .iter()
        .filter(|s| (s.x - 1000.3).abs() <= pitch && (60.0..=330.0).contains(&s.z))
        .collect();
    assert!(
        rib.len() as f64 >= 270.0 / pitch - 2.0,
        "{} cells",
        rib.len()
    );
    assert!(rib.iter().all(|s| !s.met_angles_deg.is_empty()));
}

#[test]
fn the_pitch_chosen_for_a_tolerance_passes_verify_there() {
    use kneeform::harness::{self, AutoPitch, StartSelection, TieBand, VerifyOptions};
    // Smooth parts: the grid strikes the node in front of each exact
    // contact, so the decided area distance is just under one pitch
    // (results/README.md); a 1 mm tolerance needs a pitch of 1 mm.
    let angles = vec![-30.0, 0.0, 30.0];
    for name in ["wave", "depression"] {
        let input = kneeform::read_part(&scenario_file(name), 1.0, Side::Left).unwrap();
        let setup = Setup {
            angles: angles.clone(),
            ..Setup::default()
        };
        let auto = AutoPitch {
            tolerance: 1.0,
            budget_s: AutoPitch::DEFAULT_BUDGET_S,
            selection: StartSelection::default_for(1),
        };
        let choice = harness::choose_pitch(&input, &setup, &auto, &()).unwrap();
        // Issue 39: the study judges the decided area miss distance alone,
        // as verify does (the false alarms it also judged kept the wave at
        // 1 mm); the wave's is within 1 mm at 2 mm.
        assert!(choice.pitch_mm <= 2.0, "{name}: {choice:?}");
        assert!(choice.study.last().unwrap().meets);
        // verify on other starts than the study's (another seed), at the
        // chosen pitch.
        let options = VerifyOptions {
            selection: StartSelection::default_for(2),
            tie_band_per_mm: TieBand::DEFAULT_PER_MM,
            tolerance: 1.0,
            budget_s: None,
        };
        let at_choice = Setup {
            pitch: choice.pitch_mm,
            ..setup.clone()
        };
        let verified = harness::verify(&input, &at_choice, &options, &()).unwrap();
        let d = verified.summary.area_miss_decided_mm;
        assert!(
            d.is_some_and(|d| d <= 1.0),
            "{name} at {} mm: {d:?}",
            choice.pitch_mm
        );
    }
}

#[test]
fn blind_spots_are_written_crossed_and_reported() {
    // The thin ribs at 4 mm, through the command a user runs: the CSV
    // scripts read, the crosses on composite.png, the report's sentence.
    let dir = crate::util::scratch_dir("blind-report");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_kneeform"))
        .current_dir(&dir)
        .args(["analyze"])
        .arg(scenario_file("thin-rib"))
        .args([
            "--pitch",
            "4",
            "--angles=-30,0,30",
            "--out",
            "run",
            "--report",
        ])
        .output()
        .unwrap();
    let stderr = crate::cli::said(&out);
    assert!(out.status.success(), "{stderr}");
    // Loud: the knee-form meets the ribs the grid cannot see.
    assert!(
        stderr.contains("blind spots the knee-form meets"),
        "{stderr}"
    );
    let csv = std::fs::read_to_string(dir.join("run/blind_spots.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    for column in ["x", "z", "depth_missed_mm", "resolving_pitch_mm"] {
        assert!(header.split(',').any(|c| c == column), "{header}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run/summary.json")).unwrap())
            .unwrap();
    let count = summary["blind_spots"].as_u64().unwrap();
    assert_eq!(count as usize, csv.lines().count() - 1);
    assert!(count > 90, "{count}");
    let png = crate::util::Image::decode(&std::fs::read(dir.join("run/composite.png")).unwrap());
    let magenta = kneeform::output::BLIND_COLOUR;
    let crossed = png
        .rgb()
        .iter()
        .filter(|p| **p == [magenta.0, magenta.1, magenta.2])
        .count();
    assert!(crossed > 100, "{crossed} magenta pixels");
    let html = std::fs::read_to_string(dir.join("run/report.html")).unwrap();
    assert!(html.contains("<section id=\"resolution\">"));
    assert!(
        html.contains("2 features narrower than the pitch"),
        "the two ribs are two features"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn blind_spots_are_located_in_the_parts_coordinates_whatever_the_frame() {
    // The thin ribs (scenarios/thin-rib.toml): one at part x = 10.3 +- 0.3
    // for |z| <= 100, one at part z = 40.3 +- 0.3 for x in -250..-50, both
    // 5 mm proud of the wall y = 0 towards -y. A blind spot's lowest point
    // lies on a rib in the part's coordinates, whether the grid was laid in
    // the part's frame, in a vehicle frame turned about y (`z,y,-x`: the
    // grid's x is the part's z), or in the direct approach's frame.
    let dir = crate::util::scratch_dir("blind-frames");
    let on_a_rib = |x: f64, y: f64, z: f64| {
        let tol = 0.3 + 1e-6;
        let across = (x - 10.3).abs() <= tol && z.abs() <= 100.0 + 1e-6;
        let along = (z - 40.3).abs() <= tol && (-250.0 - 1e-6..=-50.0 + 1e-6).contains(&x);
        (across || along) && (-5.0 - 1e-6..=1e-6).contains(&y)
    };
    for (k, extra) in [
        &[][..],
        &["--frame=z,y,-x"][..],
        &["--frame=-y,x,z", "--approach", "direct"][..],
    ]
    .into_iter()
    .enumerate()
    {
        let out_dir = dir.join(format!("run{k}"));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_kneeform"))
            .args(["analyze"])
            .arg(scenario_file("thin-rib"))
            .args(["--pitch", "4", "--angles=0", "--out"])
            .arg(&out_dir)
            .args(extra)
            .output()
            .unwrap();
        crate::util::ok(out, &format!("{extra:?}"));
        let mut csv = csv::Reader::from_path(out_dir.join("blind_spots.csv")).unwrap();
        let headers = csv.headers().unwrap().clone();
        let column = |name: &str| headers.iter().position(|h| h == name).unwrap();
        let (cx, cy, cz) = (column("x"), column("y"), column("z"));
        let mut spots = 0;
        for row in csv.records() {
            let row = row.unwrap();
            let at = |c: usize| row[c].parse::<f64>().unwrap();
            let (x, y, z) = (at(cx), at(cy), at(cz));
            assert!(on_a_rib(x, y, z), "{extra:?}: ({x}, {y}, {z}) is on no rib");
            spots += 1;
        }
        assert!(spots > 20, "{extra:?}: {spots} blind spots");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Issue 39: `converge --tolerance T` and `--pitch auto --tolerance T`
/// judge the same figure on the same starts, so they name the same pitch
/// (on the console, 1 mm at 1 mm: results/README.md). Before, the study
/// judged false alarms too, on scattered starts, and `converge` 0.62 mm
/// where it chose 0.5.
#[test]
fn converge_and_pitch_auto_name_the_same_pitch() {
    use kneeform::harness::{self, AutoPitch, ConvergeOptions, StartSelection, TieBand};
    let input = kneeform::read_part(&scenario_file("wave"), 1.0, Side::Left).unwrap();
    let setup = Setup {
        angles: vec![-30.0, 0.0, 30.0],
        ..Setup::default()
    };
    let auto = AutoPitch {
        tolerance: 1.0,
        budget_s: AutoPitch::DEFAULT_BUDGET_S,
        selection: StartSelection::default_for(1),
    };
    let choice = harness::choose_pitch(&input, &setup, &auto, &()).unwrap();
    // The study's ladder: four tolerances down to half the tolerance.
    let options = ConvergeOptions {
        pitches: vec![4.0, 2.0, 1.0, 0.5],
        selection: StartSelection::default_for(1),
        tie_band_per_mm: TieBand::DEFAULT_PER_MM,
        tolerance: Some(1.0),
        budget_s: None,
    };
    let study = harness::converge(&input, &setup, &options, &()).unwrap();
    let recommended = study.summary.recommended_pitch_mm;
    assert_eq!(recommended, Some(choice.pitch_mm), "{choice:?}");
    // The same figure at every pitch both measured.
    for row in &choice.study {
        let k = options
            .pitches
            .iter()
            .position(|&p| p == row.pitch_mm)
            .unwrap();
        let theirs = study.results[k].comparison.area_miss_decided();
        assert_eq!(row.exact_area_distance_mm, Some(theirs), "{}", row.pitch_mm);
    }
}
