//! Struck zones (issue 43, item 1) on parts whose zones follow from their
//! geometry: three separated bumps give three zones, each on its bump's
//! rear flank and struck at every angle; the README console's largest zone
//! holds as many nodes as a flood fill of the composite from its first
//! node finds, and its area is their cells'.

use std::collections::VecDeque;

use kneeform::{Analysis, Setup, Side};

use crate::util::scratch_dir;

/// Three cos^2 bumps 10 mm proud, radius 40 mm, 200 mm apart in z at
/// x = 0, on a flat wall: a knee-form sliding in -x meets each one's rear
/// (+x) flank, which rises towards it far more steeply than the 0.5
/// degree threshold (its slope reaches pi * 10 / 80 = 0.39), at every
/// angle; the flat wall is never struck (a start on it is pushed to the
/// wall, and once lifted over a bump the knee-form stays at the bump's
/// level, which only falls). Hence three zones, one per bump, each inside
/// its bump's disc grown by a pitch, struck at every analysed angle. (A
/// slanted knee-form also strikes some of a bump's front flank, off its
/// centre line: its leading edge meets those rows before the bump's top.)
#[test]
fn three_separated_bumps_give_three_zones_struck_at_every_angle() {
    let dir = scratch_dir("three-bumps");
    let toml = dir.join("three-bumps.toml");
    let mut text = String::from(
        "description = \"three bumps\"\n[extent]\nx = [-300, 300]\nz = [-350, 350]\nstep = 2\n",
    );
    let centres_z = [-200.0, 0.0, 200.0];
    for z in centres_z {
        text +=
            &format!("[[feature]]\nkind = \"bump\"\ncenter = [0, {z}]\nradius = 40\nheight = 10\n");
    }
    std::fs::write(&toml, text).unwrap();
    let setup = Setup {
        pitch: 4.0,
        angles: vec![-30.0, 0.0, 30.0],
        ..Setup::default()
    };
    let analysis = Analysis::of_file(&toml, 1.0, Side::Left, &setup, &()).unwrap();
    let zones: Vec<_> = analysis.zones().into_iter().filter(|z| !z.speck).collect();
    assert_eq!(zones.len(), 3, "{zones:#?}");
    let mut found: Vec<f64> = Vec::new();
    for z in &zones {
        let [x, _, zc] = z.centroid;
        let bump = centres_z
            .iter()
            .copied()
            .find(|c| (zc - c).abs() < 40.0)
            .unwrap_or_else(|| panic!("zone {} at z = {zc} is on no bump", z.id));
        // The bump's disc, grown by a pitch.
        let reach = 40.0 + setup.pitch;
        assert!(x.abs() < reach, "zone {} at x = {x}", z.id);
        assert!(z.bbox_min[0] >= -reach && z.bbox_max[0] <= reach, "{z:?}");
        assert!((z.bbox_min[2] - bump).abs() <= reach && (z.bbox_max[2] - bump).abs() <= reach);
        assert_eq!(z.angle_runs, "-30 to 30", "zone {}", z.id);
        assert_eq!(z.max_count, 3);
        found.push(bump);
    }
    found.sort_by(f64::total_cmp);
    assert_eq!(found, centres_z);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The README console at its default pitch: the largest zone is the
/// 8-connected set of colliding nodes a flood fill (written here, apart
/// from the library's) reaches from the zone's first node, and its area is
/// those nodes' cells, `p^2` each.
#[test]
fn the_console_s_largest_zone_is_a_flood_fill_of_the_composite() {
    let console =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/console_side.stl");
    let setup = Setup {
        angles: vec![-30.0, 0.0, 30.0],
        ..Setup::default()
    };
    let analysis = Analysis::of_file(&console, 1.0, Side::Left, &setup, &()).unwrap();
    let zones = analysis.zones();
    let largest = &zones[0];
    let spec = analysis.grid.spec;
    let (nx, nz) = (spec.nx, spec.nz);
    let c = &analysis.composite;
    // Every struck node of the composite, filled from each one not yet
    // reached: the fills are the zones, the largest fill the largest zone.
    let mut seen = vec![false; c.len()];
    let mut sizes = Vec::new();
    for start in 0..c.len() {
        if c[start] == 0 || seen[start] {
            continue;
        }
        let mut size = 0usize;
        let mut queue = VecDeque::from([start]);
        seen[start] = true;
        while let Some(n) = queue.pop_front() {
            size += 1;
            let (i, j) = ((n % nx) as i64, (n / nx) as i64);
            for dj in -1..=1 {
                for di in -1..=1 {
                    let (a, b) = (i + di, j + dj);
                    if (di, dj) == (0, 0) || a < 0 || b < 0 || a >= nx as i64 || b >= nz as i64 {
                        continue;
                    }
                    let m = b as usize * nx + a as usize;
                    if c[m] > 0 && !seen[m] {
                        seen[m] = true;
                        queue.push_back(m);
                    }
                }
            }
        }
        sizes.push(size);
    }
    sizes.sort_unstable_by(|a, b| b.cmp(a));
    assert_eq!(zones.len(), sizes.len());
    assert_eq!(largest.nodes, sizes[0]);
    assert_eq!(largest.area_mm2, sizes[0] as f64 * spec.pitch * spec.pitch);
    let total: usize = zones.iter().map(|z| z.nodes).sum();
    assert_eq!(total, analysis.composite_nodes());
}

/// `analyze` writes `zones.csv`, one row per zone as `summary.json`'s
/// `zones` holds them, and names the largest in its closing lines.
#[test]
fn analyze_writes_zones_csv_beside_the_summary() {
    let dir = scratch_dir("zones-cli");
    let out = dir.join("run");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_kneeform"))
        .args(["analyze", &crate::util::scenario("switch-boss")])
        .args(["--pitch", "4", "--angles=-30,0,30", "--no-check", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let run = crate::util::ok(run, "analyze");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let zones = summary["zones"].as_array().unwrap();
    assert!(!zones.is_empty());
    let mut csv = csv::Reader::from_path(out.join("zones.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = csv.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), zones.len());
    for (row, zone) in rows.iter().zip(zones) {
        assert_eq!(row[0].parse::<u64>().unwrap(), zone["id"].as_u64().unwrap());
        assert_eq!(
            row[1].parse::<u64>().unwrap(),
            zone["nodes"].as_u64().unwrap()
        );
        assert_eq!(&row[12], zone["angle_runs"].as_str().unwrap());
    }
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("kneeform:   zone 1: "), "{stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The report lists the zones (a table of the largest, cited from
/// `summary.json`) and boxes the largest ones' ids on the face-on view.
#[test]
fn the_report_tables_the_zones_and_labels_them_on_the_part() {
    let dir = scratch_dir("zones-report");
    let out = dir.join("run");
    let bin = env!("CARGO_BIN_EXE_kneeform");
    let run = std::process::Command::new(bin)
        .args(["analyze", &crate::util::scenario("switch-boss")])
        .args([
            "--pitch",
            "4",
            "--angles=-30,0,30",
            "--no-check",
            "--report",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    crate::util::ok(run, "analyze --report");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let zones = summary["zones"].as_array().unwrap();
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    let table = page.find("id=\"zones-table\"").expect("the zones' table");
    let table = &page[table..table + page[table..].find("</table>").unwrap()];
    assert_eq!(table.matches("<tr>").count(), 1 + zones.len().min(15));
    assert!(table.contains("data-src=\"summary.json#/zones/0/area_mm2\""));
    let labels = page
        .find("aria-label=\"the largest struck zones' ids\"")
        .expect("the labels");
    let labels = &page[labels..labels + page[labels..].find("</svg>").unwrap()];
    let non_specks = zones.iter().filter(|z| z["speck"] == false).count();
    assert_eq!(labels.matches("<text").count(), non_specks.min(12));
    std::fs::remove_dir_all(&dir).unwrap();
}
