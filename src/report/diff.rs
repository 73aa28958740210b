//! Two revisions of a part compared (`kneeform diff RUN_A RUN_B`, issue
//! 43, item 2): which nodes only A strikes, only B, and both, and which
//! struck zones appeared, vanished, grew or shrank.
//!
//! **One grid, A's.** The two runs may differ in part, pitch or extent, so
//! B is mapped onto A's grid: each node of A takes the largest composite
//! count of B's nodes whose cell (half B's pitch either way in x and z)
//! holds it, the report's painting rule (`NodeCounts::at`). A node of A
//! outside B's grid is not struck by B. Where B is finer, a node of A is
//! struck by B when any B node of its cell is; where B is coarser, each
//! B node stands for its whole cell. The runs must agree on what was
//! computed: knee-form, strike rule, level, side, frame, approach and
//! angles (their `summary.json` values equal), else the comparison is
//! refused, since a change of any would show as a change of the part.
//!
//! **Zones** ([`crate::zones`]) are found on A's grid in both composites;
//! a zone of A and one of B are the same place when they share at least
//! half of the smaller one's nodes, and the places joined so are one
//! group (a zone that split or merged is one group). A group with no A
//! zone **appeared**, with no B zone **vanished**, otherwise it **grew**,
//! **shrank** or is **unchanged** by its node count. A zone that moved by
//! more than half its size is one that vanished and one that appeared.

use std::path::{Path, PathBuf};

use crate::grid::GridSpec;
use crate::summary::Summary;

use super::error::ReportError;
use super::run::RunTables;

/// The `summary.json` keys two compared runs must agree on: what the
/// knee-form is, how a strike is decided, where the part is and which
/// angles were analysed.
pub const SAME_KEYS: [&str; 13] = [
    "triangle_side_mm",
    "radius_mm",
    "thickness_mm",
    "deflection_deg",
    "sigma",
    "e0_mm",
    "rate",
    "window_mm",
    "level",
    "side",
    "frame",
    "approach",
    "angles_deg",
];

/// Where a node of A's grid stands in the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeState {
    /// Struck by neither run.
    Neither,
    /// Struck by A only.
    OnlyA,
    /// Struck by B only (mapped onto A's grid).
    OnlyB,
    /// Struck by both.
    Both,
}

/// What happened to a group of zones from A to B.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ZoneChange {
    /// In B only.
    Appeared,
    /// In A only.
    Vanished,
    /// In both, larger in B.
    Grew,
    /// In both, smaller in B.
    Shrank,
    /// In both, the same node count.
    Unchanged,
}

/// One group of overlapping zones of A and B.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ZoneDiff {
    /// What happened.
    pub change: ZoneChange,
    /// The ids of A's zones in the group (as A's `zones.csv` numbers them:
    /// largest first).
    pub a_zones: Vec<usize>,
    /// The ids of B's zones in the group, numbered as zones of B mapped
    /// onto A's grid (largest first).
    pub b_zones: Vec<usize>,
    /// The group's area in A (mm^2, A's cells).
    pub area_a_mm2: f64,
    /// The group's area in B mapped onto A's grid (mm^2, A's cells).
    pub area_b_mm2: f64,
    /// `area_b_mm2 - area_a_mm2`.
    pub change_mm2: f64,
    /// The mean of the group's nodes, in the analysis frame's x and z
    /// (mm; the part's own x and z unless the runs have a `--frame`).
    pub centroid_xz: [f64; 2],
}

/// Two runs compared on A's grid.
#[derive(Debug)]
pub struct RevisionDiff {
    /// Run A's directory.
    pub a_dir: PathBuf,
    /// Run B's directory.
    pub b_dir: PathBuf,
    /// A's summary.
    pub a: Summary,
    /// B's summary.
    pub b: Summary,
    /// A's grid, the comparison's.
    pub spec: GridSpec,
    /// Per node of A's grid, row-major by z.
    pub state: Vec<NodeState>,
    /// The zone groups: vanished and shrunk first, then appeared and
    /// grown, each by decreasing size of change, then unchanged.
    pub zones: Vec<ZoneDiff>,
    /// How B was mapped, in words (for the files and the page).
    pub mapping: String,
}

impl RevisionDiff {
    /// Nodes in `state`.
    pub fn count(&self, state: NodeState) -> usize {
        self.state.iter().filter(|&&s| s == state).count()
    }

    /// The area of one cell of A's grid (mm^2).
    pub fn cell_mm2(&self) -> f64 {
        self.spec.pitch * self.spec.pitch
    }
}

/// Reads the runs in `a_dir` and `b_dir` (`analyze` output directories:
/// `summary.json`, `composite.csv`) and compares them on A's grid.
pub fn diff_runs(a_dir: &Path, b_dir: &Path) -> Result<RevisionDiff, ReportError> {
    let RunTables {
        summary: a,
        json: a_json,
        composite: a_counts,
        ..
    } = RunTables::read(a_dir)?;
    let RunTables {
        summary: b,
        json: b_json,
        composite: b_counts,
        ..
    } = RunTables::read(b_dir)?;
    for key in SAME_KEYS {
        if a_json.get(key) != b_json.get(key) {
            return Err(ReportError::Inconsistent {
                path: b_dir.join(crate::output::SUMMARY_JSON),
                reason: format!(
                    "its {key} is {}, run A's {}: two revisions are compared only under the same knee-form, strike rule, side, frame and angles",
                    shown(b_json.get(key)),
                    shown(a_json.get(key))
                ),
            });
        }
    }
    let spec = a_counts.spec;
    let mut b_on_a = vec![0u16; spec.len()];
    for j in 0..spec.nz {
        for i in 0..spec.nx {
            if let Some((c, _)) = b_counts.at(spec.x(i), spec.z(j)) {
                b_on_a[j * spec.nx + i] = c;
            }
        }
    }
    let state: Vec<NodeState> = a_counts
        .count
        .iter()
        .zip(&b_on_a)
        .map(|(&ca, &cb)| match (ca > 0, cb > 0) {
            (false, false) => NodeState::Neither,
            (true, false) => NodeState::OnlyA,
            (false, true) => NodeState::OnlyB,
            (true, true) => NodeState::Both,
        })
        .collect();
    let zones = zone_groups(&a_counts.count, &b_on_a, spec);
    let mapping = format!(
        "B ({} mm pitch, {} x {} nodes) mapped onto A's grid ({} mm, {} x {}): each node of A takes the largest count of B's nodes within half B's pitch in x and in z",
        b_counts.spec.pitch, b_counts.spec.nx, b_counts.spec.nz, spec.pitch, spec.nx, spec.nz
    );
    Ok(RevisionDiff {
        a_dir: a_dir.to_path_buf(),
        b_dir: b_dir.to_path_buf(),
        a,
        b,
        spec,
        state,
        zones,
        mapping,
    })
}

/// A JSON value as a message shows it ("absent" for none).
fn shown(v: Option<&serde_json::Value>) -> String {
    v.map_or_else(|| "absent".into(), ToString::to_string)
}

/// The zone groups of `a` and `b` (counts on one grid, `spec`).
fn zone_groups(a: &[u16], b: &[u16], spec: GridSpec) -> Vec<ZoneDiff> {
    let (za, zb) = (
        crate::zones::components(a, spec.nx, spec.nz),
        crate::zones::components(b, spec.nx, spec.nz),
    );
    // Union-find over A's zones (0..na) and B's (na..na+nb), joined where
    // they share a node.
    let (na, nb) = (za.len(), zb.len());
    let mut parent: Vec<usize> = (0..na + nb).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    let mut label_a = vec![usize::MAX; a.len()];
    for (k, nodes) in za.iter().enumerate() {
        for &n in nodes {
            label_a[n] = k;
        }
    }
    let mut shared: std::collections::BTreeMap<(usize, usize), usize> = Default::default();
    for (k, nodes) in zb.iter().enumerate() {
        for &n in nodes {
            if label_a[n] != usize::MAX {
                *shared.entry((label_a[n], k)).or_default() += 1;
            }
        }
    }
    for ((ka, kb), common) in shared {
        // The same place: they share at least half of the smaller one.
        if 2 * common >= za[ka].len().min(zb[kb].len()) {
            let (ra, rb) = (root(&mut parent, ka), root(&mut parent, na + kb));
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    let cell = spec.pitch * spec.pitch;
    let mut groups: std::collections::BTreeMap<usize, (Vec<usize>, Vec<usize>)> =
        Default::default();
    for k in 0..na + nb {
        let r = root(&mut parent, k);
        let g = groups.entry(r).or_default();
        if k < na {
            g.0.push(k)
        } else {
            g.1.push(k - na)
        }
    }
    let mut out: Vec<ZoneDiff> = groups
        .into_values()
        .map(|(ka, kb)| {
            let nodes_a: usize = ka.iter().map(|&k| za[k].len()).sum();
            let nodes_b: usize = kb.iter().map(|&k| zb[k].len()).sum();
            let (mut sx, mut sz, mut n) = (0.0, 0.0, 0usize);
            for &node in ka
                .iter()
                .flat_map(|&k| &za[k])
                .chain(kb.iter().flat_map(|&k| &zb[k]))
            {
                sx += spec.x(node % spec.nx);
                sz += spec.z(node / spec.nx);
                n += 1;
            }
            let change = match (nodes_a, nodes_b) {
                (0, _) => ZoneChange::Appeared,
                (_, 0) => ZoneChange::Vanished,
                (x, y) if y > x => ZoneChange::Grew,
                (x, y) if y < x => ZoneChange::Shrank,
                _ => ZoneChange::Unchanged,
            };
            ZoneDiff {
                change,
                a_zones: ka.iter().map(|k| k + 1).collect(),
                b_zones: kb.iter().map(|k| k + 1).collect(),
                area_a_mm2: nodes_a as f64 * cell,
                area_b_mm2: nodes_b as f64 * cell,
                change_mm2: (nodes_b as f64 - nodes_a as f64) * cell,
                centroid_xz: [sx / n as f64, sz / n as f64],
            }
        })
        .collect();
    let order = |c: ZoneChange| match c {
        ZoneChange::Vanished | ZoneChange::Shrank => 0,
        ZoneChange::Appeared | ZoneChange::Grew => 1,
        ZoneChange::Unchanged => 2,
    };
    out.sort_by(|x, y| {
        order(x.change)
            .cmp(&order(y.change))
            .then(y.change_mm2.abs().total_cmp(&x.change_mm2.abs()))
            .then(x.a_zones.cmp(&y.a_zones))
            .then(x.b_zones.cmp(&y.b_zones))
    });
    out
}

/// The colours of [`write_diff`]'s picture: A only, B only, both (the
/// report's comparison colours), and struck by neither.
const COLOURS: [[u8; 3]; 4] = [
    super::compare::SLIDE_ONLY,
    super::compare::DIRECT_ONLY,
    super::compare::BOTH,
    [225, 225, 225],
];

/// The files [`write_diff`] writes.
pub const DIFF_FILES: [&str; 4] = ["diff.json", "diff_nodes.csv", "diff_zones.csv", "diff.png"];

/// Writes `diff` into the directory `dir` (a staged output directory):
/// `diff.json` (the runs, the mapping, the counts and areas, the zone
/// groups), `diff_nodes.csv` (every node of A's grid struck by either:
/// `i, j, x, z, state`), `diff_zones.csv` (one row per zone group) and
/// `diff.png` (A's grid face on, x to the right and z up, one square per
/// node: A only orange, B only blue, both purple, neither grey).
pub fn write_diff(dir: &Path, diff: &RevisionDiff) -> Result<(), ReportError> {
    let io = |path: PathBuf| move |source: std::io::Error| ReportError::Io { path, source };
    let spec = diff.spec;
    let cell = diff.cell_mm2();
    let counts = [NodeState::OnlyA, NodeState::OnlyB, NodeState::Both].map(|s| diff.count(s));
    let json = serde_json::json!({
        "kneeform_version": env!("CARGO_PKG_VERSION"),
        "run_a": diff.a_dir.display().to_string(),
        "run_b": diff.b_dir.display().to_string(),
        "part_a": diff.a.input_file,
        "part_b": diff.b.input_file,
        "sha256_a": diff.a.sha256,
        "sha256_b": diff.b.sha256,
        "pitch_mm": spec.pitch,
        "mapping": diff.mapping,
        "same_keys": SAME_KEYS,
        "only_a_nodes": counts[0],
        "only_b_nodes": counts[1],
        "both_nodes": counts[2],
        "only_a_area_mm2": counts[0] as f64 * cell,
        "only_b_area_mm2": counts[1] as f64 * cell,
        "both_area_mm2": counts[2] as f64 * cell,
        "zones": diff.zones,
    });
    let path = dir.join(DIFF_FILES[0]);
    let text = crate::output::json_text(&json).expect("JSON of plain values");
    std::fs::write(&path, text).map_err(io(path.clone()))?;

    let path = dir.join(DIFF_FILES[1]);
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(&path)?;
        csv.write_record(["i", "j", "x", "z", "state"])?;
        for (n, s) in diff.state.iter().enumerate() {
            let word = match s {
                NodeState::Neither => continue,
                NodeState::OnlyA => "a",
                NodeState::OnlyB => "b",
                NodeState::Both => "both",
            };
            let (i, j) = (n % spec.nx, n / spec.nx);
            let um = crate::output::micrometres;
            csv.write_record([
                i.to_string(),
                j.to_string(),
                um(spec.x(i)),
                um(spec.z(j)),
                word.into(),
            ])?;
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(|e| io(path.clone())(e.into()))?;

    let path = dir.join(DIFF_FILES[2]);
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(&path)?;
        csv.write_record([
            "change",
            "a_zones",
            "b_zones",
            "area_a_mm2",
            "area_b_mm2",
            "change_mm2",
            "x",
            "z",
        ])?;
        let ids = |v: &[usize]| {
            v.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(";")
        };
        let um = crate::output::micrometres;
        for g in &diff.zones {
            csv.write_record([
                serde_json::to_value(g.change)
                    .ok()
                    .and_then(|v| v.as_str().map(String::from))
                    .unwrap_or_default(),
                ids(&g.a_zones),
                ids(&g.b_zones),
                um(g.area_a_mm2),
                um(g.area_b_mm2),
                um(g.change_mm2),
                um(g.centroid_xz[0]),
                um(g.centroid_xz[1]),
            ])?;
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(|e| io(path.clone())(e.into()))?;

    let path = dir.join(DIFF_FILES[3]);
    std::fs::write(&path, picture_png(diff)?).map_err(io(path.clone()))?;
    Ok(())
}

/// [`write_diff`]'s picture as PNG bytes (`diff.png`, and the report's
/// page).
pub(super) fn picture_png(diff: &RevisionDiff) -> Result<Vec<u8>, ReportError> {
    let (width, height, rgb) = picture(diff);
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&rgb))
        .map_err(|e| ReportError::Io {
            path: PathBuf::from("diff.png"),
            source: std::io::Error::other(e),
        })?;
    Ok(bytes)
}

/// The picture's pixels: each node a square of `scale` pixels (at least
/// one; small grids enlarged to about 800 pixels across), x to the right,
/// z up.
fn picture(diff: &RevisionDiff) -> (u32, u32, Vec<u8>) {
    let spec = diff.spec;
    let scale = (800 / spec.nx.max(1)).clamp(1, 8);
    let (w, h) = (spec.nx * scale, spec.nz * scale);
    let mut rgb = vec![0u8; w * h * 3];
    for (n, s) in diff.state.iter().enumerate() {
        let colour = match s {
            NodeState::OnlyA => COLOURS[0],
            NodeState::OnlyB => COLOURS[1],
            NodeState::Both => COLOURS[2],
            NodeState::Neither => COLOURS[3],
        };
        let (i, j) = (n % spec.nx, n / spec.nx);
        for dy in 0..scale {
            let row = (spec.nz - 1 - j) * scale + dy;
            for dx in 0..scale {
                let at = (row * w + i * scale + dx) * 3;
                rgb[at..at + 3].copy_from_slice(&colour);
            }
        }
    }
    (w as u32, h as u32, rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_zones_group_and_lone_ones_appear_or_vanish() {
        let spec = GridSpec::explicit(0.0, 0.0, 8, 3, 1.0);
        // Row-major, nx = 8, one row used: A strikes columns 0-1 and 4-5,
        // B columns 1-3 (sharing half of A's first: grew by one) and 7 (new);
        // A's columns 4-5 vanish.
        let mut a = vec![0u16; spec.len()];
        let mut b = vec![0u16; spec.len()];
        for i in [0, 1, 4, 5] {
            a[8 + i] = 1;
        }
        for i in [1, 2, 3, 7] {
            b[8 + i] = 1;
        }
        let groups = zone_groups(&a, &b, spec);
        let changes: Vec<(ZoneChange, f64)> =
            groups.iter().map(|g| (g.change, g.change_mm2)).collect();
        assert_eq!(
            changes,
            vec![
                (ZoneChange::Vanished, -2.0),
                (ZoneChange::Appeared, 1.0),
                (ZoneChange::Grew, 1.0),
            ]
        );
        assert_eq!(groups[1].centroid_xz, [7.0, 1.0]);
    }
}
