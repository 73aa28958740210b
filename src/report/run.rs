//! Reading an `analyze` run directory back: `summary.json` (typed, and as
//! raw JSON so the report can cite every number by its JSON pointer), the
//! composite and per-angle masks from `composite.csv` (or an earlier
//! version's `colliding_points.csv`), and the part, re-read
//! from the file the run names and checked against its SHA-256.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::frame::Approach;
use crate::frame::Frame;
use crate::frame::Side;
use crate::grid::GridSpec;
use crate::input::{read_part_bytes, sha256_hex};
use crate::mesh::Part;
use crate::summary::{Summary, SummaryError};

use super::error::ReportError;

/// The counts of one run's grid nodes (composite or one angle's mask) with
/// the heights the run reported, for painting the part.
#[derive(Debug, Clone)]
pub(crate) struct NodeCounts {
    /// The run's grid (part frame x, z; mm).
    pub spec: GridSpec,
    /// Per node, row-major by z (`j * nx + i`): number of angles (or 1/0).
    pub count: Vec<u16>,
    /// Per node, its depth on the grid (mm: vehicle y for push-and-slide,
    /// `-x` for the direct approach, [`GridAxes`]) from the CSV's point;
    /// NaN for nodes not in the file.
    pub y: Vec<f64>,
}

impl NodeCounts {
    fn empty(spec: GridSpec) -> Result<NodeCounts, ReportError> {
        let memory = |e: crate::limits::OutOfMemory| ReportError::Memory {
            what: format!("a {} x {} grid", spec.nx, spec.nz),
            source: e,
        };
        Ok(NodeCounts {
            spec,
            count: crate::limits::try_filled(spec.len(), 0).map_err(memory)?,
            y: crate::limits::try_filled(spec.len(), f64::NAN).map_err(memory)?,
        })
    }

    /// The largest count of the nodes whose cell holds `(x, z)` (mm): nodes
    /// with `|x - x_i| <= p/2` and `|z - z_j| <= p/2`, and their y (part
    /// frame) alongside; `None` when no such node has a count.
    ///
    /// This is the report's rule for painting a surface point: a point is
    /// coloured when it lies within half a pitch, in x and in z, of a
    /// colliding node. The cells are closed within [`CELL_TOL`]: a point
    /// on the border of two cells is in both, whatever the rounding of the
    /// renderer's depth made of it (a face lying on the border, the pocket
    /// floor of `scenarios/pocket-behind-ridge.toml` half a pitch between
    /// the direct grid's node columns, was speckled grey pixel by pixel).
    pub fn at(&self, x: f64, z: f64) -> Option<(u16, f64)> {
        let s = &self.spec;
        let half = 0.5 * s.pitch + CELL_TOL;
        let near = |v: f64, origin: i64, n: usize| {
            let k = (v / s.pitch).round() as i64 - origin;
            (k - 1).max(0)..(k + 2).min(n as i64)
        };
        let mut best: Option<(u16, f64)> = None;
        for j in near(z, s.j_origin, s.nz) {
            let j = j as usize;
            if (z - s.z(j)).abs() > half {
                continue;
            }
            for i in near(x, s.i_origin, s.nx) {
                let i = i as usize;
                let k = j * s.nx + i;
                let c = self.count[k];
                if c > 0 && (x - s.x(i)).abs() <= half && best.is_none_or(|b| c > b.0) {
                    best = Some((c, self.y[k]));
                }
            }
        }
        best
    }

    /// Nodes with a count.
    #[cfg(test)]
    pub fn nodes(&self) -> usize {
        self.count.iter().filter(|&&c| c > 0).count()
    }
}

/// Every node's set of striking angles ([`Run::angle_bits`]).
#[derive(Debug, Clone)]
pub(crate) struct AngleBits {
    /// Bytes per node: `ceil(angles / 8)`.
    pub bytes: usize,
    /// `bytes` per node, row-major by z; bit `a % 8` of byte `a / 8` is
    /// the run's angle `a`.
    pub bits: Vec<u8>,
}

/// What every reader of a run directory needs first: its `summary.json`
/// (as written, parsed and typed, every field checked), the grid, frame
/// and axes it states, and `composite.csv` on that grid, checked against
/// the summary's counts. [`Run::read`] adds the part and the blind spots;
/// a comparison of revisions ([`super::diff`]) needs no more.
pub(super) struct RunTables {
    /// `summary.json`'s text.
    pub text: String,
    /// `summary.json`, as written.
    pub json: serde_json::Value,
    /// `summary.json`, typed.
    pub summary: Summary,
    /// The run's grid.
    pub spec: GridSpec,
    /// The run's `--frame`.
    pub frame: Frame,
    /// How drawn points map to the grid.
    pub axes: GridAxes,
    /// `composite.csv`.
    pub composite: NodeCounts,
}

impl RunTables {
    /// Reads `dir`'s `summary.json` and `composite.csv`.
    pub fn read(dir: &Path) -> Result<RunTables, ReportError> {
        let summary_path = dir.join(crate::output::SUMMARY_JSON);
        let (text, json, summary) = read_summary(&summary_path)?;
        let spec = grid_spec(&summary).ok_or_else(|| ReportError::Inconsistent {
            path: summary_path.clone(),
            reason: format!(
                "grid origin {:?}, size {:?} and pitch {} do not describe a grid",
                summary.grid_origin, summary.grid_size, summary.pitch_mm
            ),
        })?;
        let frame = run_frame(&summary, &summary_path)?;
        let axes = GridAxes {
            approach: summary.approach,
            side: summary.side,
        };
        let composite = read_composite(&crate::output::composite_table(dir), spec, &frame, axes)?;
        check_counts(&summary, &composite).map_err(|reason| ReportError::Inconsistent {
            path: summary_path.clone(),
            reason,
        })?;
        Ok(RunTables {
            text,
            json,
            summary,
            spec,
            frame,
            axes,
            composite,
        })
    }
}

/// A `summary.json` at `path`: its text, its JSON and the typed summary,
/// every field checked ([`Summary::from_json`]).
pub(super) fn read_summary(
    path: &Path,
) -> Result<(String, serde_json::Value, Summary), ReportError> {
    let text = read_text(path)?;
    let json = |source| ReportError::Json {
        path: path.to_path_buf(),
        source,
    };
    let value: serde_json::Value = serde_json::from_str(&text).map_err(json)?;
    let summary = Summary::from_json(&text).map_err(|e| match e {
        SummaryError::Json(source) => json(source),
        e @ SummaryError::Field { .. } => ReportError::Inconsistent {
            path: path.to_path_buf(),
            reason: e.to_string(),
        },
    })?;
    Ok((text, value, summary))
}

/// A run directory, read.
#[derive(Debug)]
pub(crate) struct Run {
    /// The directory.
    pub dir: PathBuf,
    /// `summary.json`, typed.
    pub summary: Summary,
    /// `summary.json`, as written (for citing values by pointer).
    pub summary_json: serde_json::Value,
    /// The run's grid.
    pub spec: GridSpec,
    /// `composite.csv`: angles per node.
    pub composite: NodeCounts,
    /// The part file that was re-read (its SHA-256 matched the run's).
    pub part_path: PathBuf,
    /// The part (an assembly's analysed files merged) in vehicle
    /// coordinates: its own frame mapped by the run's `--frame`, if any
    /// (mm, after the run's scale; not mirrored).
    pub part: Part,
    /// The run's `--frame` (none when it had none).
    pub frame: Frame,
    /// How the drawn part's points map to the run's grid.
    pub axes: GridAxes,
    /// `blind_spots.csv` (empty for runs of versions that wrote none).
    pub blind_spots: Vec<BlindRow>,
}

/// How a point the report draws (vehicle coordinates, mm) maps to a run's
/// grid: for push-and-slide the grid is vehicle x, z with depth y (the
/// side's mirror aside, as ever); for the direct approach
/// ([`crate::direct`]) it is the direct frame, column coordinate the
/// analysed y (vehicle y, mirrored for the right side), depth `-x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GridAxes {
    /// The run's approach.
    pub approach: Approach,
    /// The run's side.
    pub side: Side,
}

impl GridAxes {
    /// `v` (vehicle coordinates, mm) as `[column coordinate, depth, z]` of
    /// the run's grid.
    pub fn grid(&self, v: [f64; 3]) -> [f64; 3] {
        match self.approach {
            Approach::Slide => v,
            Approach::Direct => [self.side.to_part(v[1]), -v[0], v[2]],
        }
    }
}

/// One row of `blind_spots.csv`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BlindRow {
    /// The cell's first corner node.
    pub i: usize,
    /// Its row.
    pub j: usize,
    /// The lowest point's x (mm, the part's coordinates; the analysis
    /// grid's in files of versions before the `y` column).
    pub x: f64,
    /// Its y (mm); `None` in files of versions that wrote none.
    pub y: Option<f64>,
    /// Its z (mm).
    pub z: f64,
    /// Depth missed (mm).
    pub depth_mm: f64,
    /// Width of the proud part (mm).
    pub width_mm: f64,
    /// The pitch resolving it (mm).
    pub resolving_pitch_mm: f64,
    /// How many angles meet it.
    pub met_angles: usize,
}

impl Run {
    /// Reads `dir`. The part is looked for at `part` when given, else at the
    /// run's `input_file` as given (relative to the current directory) and
    /// relative to the run directory's parent; the first file whose SHA-256
    /// is the run's is used ([`crate::input::read_part_bytes`]).
    pub fn read(dir: &Path, part: Option<&Path>) -> Result<Run, ReportError> {
        let summary_path = dir.join(crate::output::SUMMARY_JSON);
        // A run replaced while it is read (`analyze --force` renames a
        // whole new directory into place) would give one run's numbers
        // beside another's pictures: the directory read is the one there
        // before and after, or the report refuses.
        let identity_before = dir_identity(dir);
        let RunTables {
            text,
            json: summary_json,
            summary,
            spec,
            frame,
            axes,
            composite,
        } = RunTables::read(dir)?;
        let (part_path, mut part) = find_parts(dir, part, &summary)?;
        // With a frame, the part is drawn where the analysis put it: in
        // vehicle coordinates (the side's mirror aside, as ever).
        if !frame.is_none() {
            for v in part.triangles.iter_mut().flatten() {
                *v = frame.to_vehicle(*v);
            }
        }
        let blind_path = dir.join("blind_spots.csv");
        let blind_spots = if blind_path.is_file() {
            read_blind_spots(&blind_path, spec)?
        } else {
            Vec::new()
        };
        if dir_identity(dir) != identity_before || read_text(&summary_path).ok() != Some(text) {
            return Err(ReportError::Inconsistent {
                path: dir.to_path_buf(),
                reason: "the run was replaced while the report read it (a run with --force on it?); run the report again".into(),
            });
        }
        Ok(Run {
            dir: dir.to_path_buf(),
            summary,
            summary_json,
            spec,
            composite,
            part_path,
            part,
            frame,
            axes,
            blind_spots,
        })
    }

    /// The colliding masks of `angles` (degrees, each one of the run's),
    /// as counts of 1 with the composite's heights: from the run's angle
    /// sets ([`Run::angle_bits`], bit `a` for the run's angle `a`), or,
    /// for a run of a version that wrote no masks (`bits` is `None`), from
    /// `colliding_points.csv`.
    pub fn angle_masks(
        &self,
        angles: &[f64],
        bits: Option<&AngleBits>,
    ) -> Result<Vec<NodeCounts>, ReportError> {
        let Some(sets) = bits else {
            return self.angle_masks_of_points(angles);
        };
        let run_angles = &self.summary.angles_deg;
        let positions: Vec<usize> = angles
            .iter()
            .map(|a| {
                run_angles
                    .iter()
                    .position(|r| r.to_bits() == a.to_bits())
                    .ok_or_else(|| ReportError::Inconsistent {
                        path: self.dir.join(crate::output::SUMMARY_JSON),
                        reason: format!("angle {a} is not one of the run's"),
                    })
            })
            .collect::<Result<_, _>>()?;
        let mut masks: Vec<NodeCounts> = angles
            .iter()
            .map(|_| NodeCounts::empty(self.spec))
            .collect::<Result<_, _>>()?;
        for (mask, &a) in masks.iter_mut().zip(&positions) {
            for k in 0..self.spec.len() {
                if sets.bits[k * sets.bytes + a / 8] >> (a % 8) & 1 == 1 {
                    mask.count[k] = 1;
                    // The node's row of composite.csv, read once.
                    mask.y[k] = self.composite.y[k];
                }
            }
        }
        Ok(masks)
    }

    /// Every node's set of striking angles, from `composite.csv`'s
    /// `angle_mask`: `bytes` bytes per node (row-major by z, as
    /// [`NodeCounts`]), bit `a % 8` of byte `a / 8` set when the run's
    /// angle `a` strikes the node. `None` for a run of a version that wrote
    /// no masks.
    pub fn angle_bits(&self) -> Result<Option<AngleBits>, ReportError> {
        let composite = crate::output::composite_table(&self.dir);
        if !CsvRows::open(&composite, &[])?.has_column("angle_mask") {
            return Ok(None);
        }
        let mut rows = CsvRows::open(&composite, &["i", "j", "x", "y", "z", "angle_mask"])?;
        let n = self.summary.angles_deg.len();
        let digits = n.div_ceil(4).max(1);
        let bytes = n.div_ceil(8).max(1);
        let len = self.spec.len() * bytes;
        let mut bits = crate::limits::try_filled(len, 0u8).map_err(|e| ReportError::Memory {
            what: format!(
                "the angle sets of a {} x {} grid",
                self.spec.nx, self.spec.nz
            ),
            source: e,
        })?;
        while let Some(row) = rows.next_row()? {
            let (k, _) = rows.node(&row, self.spec, &self.frame, self.axes)?;
            let field = row.get(rows.columns[5]).unwrap_or("");
            let hex = field
                .strip_prefix("0x")
                .filter(|h| h.len() == digits && h.bytes().all(|b| b.is_ascii_hexdigit()))
                .ok_or_else(|| {
                    rows.bad(format!(
                        "angle_mask = {field:?} is not 0x and {digits} hex digits"
                    ))
                })?;
            // Digit d from the right holds angles 4d..4d+4: two digits a byte.
            for (d, digit) in hex.bytes().rev().enumerate() {
                let nibble = char::from(digit).to_digit(16).expect("checked hex") as u8;
                bits[k * bytes + d / 2] |= nibble << (4 * (d % 2));
            }
        }
        Ok(Some(AngleBits { bytes, bits }))
    }

    /// [`Run::angle_masks`] from `colliding_points.csv`, as earlier
    /// versions wrote it by default.
    fn angle_masks_of_points(&self, angles: &[f64]) -> Result<Vec<NodeCounts>, ReportError> {
        let path = self.dir.join("colliding_points.csv");
        let mut masks: BTreeMap<u64, NodeCounts> = angles
            .iter()
            .map(|a| Ok((a.to_bits(), NodeCounts::empty(self.spec)?)))
            .collect::<Result<_, ReportError>>()?;
        let mut rows = CsvRows::open(&path, &["angle_deg", "i", "j", "x", "y", "z"])?;
        while let Some(row) = rows.next_row()? {
            let angle: f64 = rows.parse(&row, 0)?;
            if let Some(mask) = masks.get_mut(&angle.to_bits()) {
                let (k, y) = rows.node(&row, self.spec, &self.frame, self.axes)?;
                mask.count[k] = 1;
                mask.y[k] = y;
            }
        }
        Ok(angles
            .iter()
            .map(|a| masks.remove(&a.to_bits()).expect("one mask per angle"))
            .collect())
    }
}

/// The run's grid, identified by its integer node indices: SPEC puts the
/// nodes on multiples of the pitch, so the origin's index `round(x0 / p)`
/// and the pitch say exactly where every node is. `None` when the summary
/// is not such a grid: a size of zero, a pitch that is not a positive
/// number, or an origin further than `ORIGIN_TOL` (1e-12, relative)
/// from the multiple it rounds to.
///
/// The origin is not compared with `==`: it was written as `p * I0`, and
/// a reader without correctly rounded float parsing may get it back one
/// unit in the last place off (the run at the default 1.24 mm pitch whose
/// origin z is `1.24 * -189 = -234.35999999999999`).
pub fn grid_spec(s: &Summary) -> Option<GridSpec> {
    let p = s.pitch_mm;
    if !(p.is_finite() && p > 0.0) || s.grid_size[0] == 0 || s.grid_size[1] == 0 {
        return None;
    }
    let index = |origin: f64| -> Option<i64> {
        let k = (origin / p).round();
        let on_node = origin.is_finite()
            && k.abs() < 1e15
            && (origin - k * p).abs() <= ORIGIN_TOL * origin.abs().max(p);
        on_node.then_some(k as i64)
    };
    Some(GridSpec {
        pitch: p,
        i_origin: index(s.grid_origin[0])?,
        j_origin: index(s.grid_origin[1])?,
        nx: s.grid_size[0],
        nz: s.grid_size[1],
    })
}

/// How far past half a pitch (mm) a point still lies in a node's cell
/// ([`NodeCounts::at`]): far above the rounding of a rendered surface
/// point (a few units in the last place of its coordinates, about 1e-13
/// mm on a part of a metre), far below a pixel of any view.
pub(crate) const CELL_TOL: f64 = 1e-6;

/// How far (relative to the coordinate, or to the pitch near 0) a grid
/// coordinate read back from a file may be from the node it names: a few
/// units in the last place of an f64 (2.2e-16 each), far below the 1e-6
/// relative spacing of nodes of any grid of fewer than a million nodes.
pub(crate) const ORIGIN_TOL: f64 = 1e-12;

/// Whether the coordinate `v` (mm) read from a run file is the grid
/// coordinate `node` (mm), within [`ORIGIN_TOL`] relative to the larger of
/// the coordinate and `pitch`.
pub(crate) fn same_coordinate(v: f64, node: f64, pitch: f64) -> bool {
    (v - node).abs() <= ORIGIN_TOL * node.abs().max(pitch)
}

/// How far a coordinate of a `composite.csv` with an `angle_mask` may be
/// from its node (mm): it was rounded to 1 um, half a micrometre per
/// coordinate, and through a `--frame` rotation up to sqrt(3) times that
/// in one vehicle coordinate (0.87 um); 1 um bounds both.
pub(crate) const ROUNDED_TOL_MM: f64 = 1e-3;

/// The directory's identity (device and inode), where the system has one.
fn dir_identity(dir: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(dir).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// Whether what `summary` states agrees with the composite drawn from
/// `composite.csv`: its node count, its area (nodes times the pitch
/// squared), every angle's area from its count, and the angles' counts
/// summed against the composite's per-node angle counts. An edited
/// summary (5 nodes stated while 39 are drawn, an area of -1 mm^2) or a
/// mix of two runs is refused, never presented as evidence.
fn check_counts(summary: &Summary, composite: &NodeCounts) -> Result<(), String> {
    let area = |nodes: usize| nodes as f64 * summary.pitch_mm * summary.pitch_mm;
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
    let drawn = composite.count.iter().filter(|&&c| c > 0).count();
    if summary.composite_nodes != drawn {
        return Err(format!(
            "it states {} composite nodes, composite.csv holds {drawn}",
            summary.composite_nodes
        ));
    }
    if !same(summary.composite_area_mm2, area(drawn)) {
        return Err(format!(
            "it states a composite area of {} mm2, its {drawn} nodes at {} mm make {} mm2",
            crate::limits::short(summary.composite_area_mm2),
            crate::limits::short(summary.pitch_mm),
            crate::limits::short(area(drawn))
        ));
    }
    if summary.per_angle.len() != summary.angles_deg.len() {
        return Err(format!(
            "it states {} angles and {} per-angle results",
            summary.angles_deg.len(),
            summary.per_angle.len()
        ));
    }
    for a in &summary.per_angle {
        if a.colliding_nodes > drawn || !same(a.colliding_area_mm2, area(a.colliding_nodes)) {
            return Err(format!(
                "at {} degrees it states {} nodes and {} mm2, beside {drawn} composite nodes",
                a.angle_deg,
                a.colliding_nodes,
                crate::limits::short(a.colliding_area_mm2)
            ));
        }
    }
    let stated: usize = summary.per_angle.iter().map(|a| a.colliding_nodes).sum();
    let counted: usize = composite.count.iter().map(|&c| usize::from(c)).sum();
    if stated != counted {
        return Err(format!(
            "its angles' colliding nodes sum to {stated}, composite.csv's angle counts to {counted}"
        ));
    }
    Ok(())
}

fn read_composite(
    path: &Path,
    spec: GridSpec,
    frame: &Frame,
    axes: GridAxes,
) -> Result<NodeCounts, ReportError> {
    let mut counts = NodeCounts::empty(spec)?;
    let mut rows = CsvRows::open(path, &["i", "j", "x", "y", "z", "angles"])?;
    while let Some(row) = rows.next_row()? {
        let (k, y) = rows.node(&row, spec, frame, axes)?;
        counts.count[k] = rows.parse(&row, 5)?;
        counts.y[k] = y;
    }
    Ok(counts)
}

/// The run's `--frame`, checked as `analyze` checked it.
fn run_frame(summary: &Summary, path: &Path) -> Result<Frame, ReportError> {
    summary
        .frame
        .as_ref()
        .map_or(Ok(Frame::none()), Frame::from_record)
        .map_err(|e| ReportError::Inconsistent {
            path: path.to_path_buf(),
            reason: format!("frame: {e}"),
        })
}

fn read_blind_spots(path: &Path, spec: GridSpec) -> Result<Vec<BlindRow>, ReportError> {
    let mut rows = CsvRows::open(path, &crate::blind::CSV_READ_COLUMNS)?;
    let y_column = rows.headers.iter().position(|h| h == "y");
    let mut out = Vec::new();
    while let Some(row) = rows.next_row()? {
        let (i, j): (usize, usize) = (rows.parse(&row, 0)?, rows.parse(&row, 1)?);
        if i + 1 >= spec.nx || j + 1 >= spec.nz {
            return Err(rows.bad(format!("cell ({i}, {j}) is not a cell of the run's grid")));
        }
        let met = row.get(rows.columns[7]).unwrap_or("");
        out.push(BlindRow {
            i,
            j,
            x: rows.parse(&row, 2)?,
            y: match y_column {
                Some(c) => Some(
                    row.get(c)
                        .and_then(|v| v.parse().ok())
                        .ok_or_else(|| rows.bad("column \"y\": not a number".into()))?,
                ),
                None => None,
            },
            z: rows.parse(&row, 3)?,
            depth_mm: rows.parse(&row, 4)?,
            width_mm: rows.parse(&row, 5)?,
            resolving_pitch_mm: rows.parse(&row, 6)?,
            met_angles: met.split(';').filter(|a| !a.is_empty()).count(),
        });
    }
    Ok(out)
}

/// A CSV file read row by row, its columns located by name.
struct CsvRows {
    path: PathBuf,
    reader: csv::Reader<Box<dyn std::io::Read>>,
    /// Column of each wanted name.
    columns: Vec<usize>,
    names: Vec<String>,
    line: u64,
    headers: csv::StringRecord,
    /// How far a coordinate may be from its node beyond float rounding
    /// (mm): [`ROUNDED_TOL_MM`], the tables' rounding.
    rounding: f64,
}

impl CsvRows {
    fn open(path: &Path, wanted: &[&str]) -> Result<CsvRows, ReportError> {
        let file = crate::limits::open_bounded(path, crate::limits::MAX_RUN_TABLE_BYTES).map_err(
            |source| ReportError::Io {
                path: path.to_path_buf(),
                source,
            },
        )?;
        // A compressed table (`composite.csv.gz`) is read through gzip, at
        // most the same bytes decompressed (a bomb ends there, and the
        // table's rows then disagree with its summary).
        let gzipped = path.extension().is_some_and(|e| e == "gz");
        let file: Box<dyn std::io::Read> = if gzipped {
            Box::new(std::io::Read::take(
                flate2::read::GzDecoder::new(std::io::BufReader::new(file)),
                crate::limits::MAX_RUN_TABLE_BYTES,
            ))
        } else {
            Box::new(file)
        };
        let mut reader = csv::Reader::from_reader(file);
        let bad = |reason: String| ReportError::Inconsistent {
            path: path.to_path_buf(),
            reason,
        };
        let headers = reader.headers().map_err(|e| bad(e.to_string()))?.clone();
        let columns = wanted
            .iter()
            .map(|w| {
                headers
                    .iter()
                    .position(|h| h == *w)
                    .ok_or_else(|| bad(format!("no column {w:?}")))
            })
            .collect::<Result<_, _>>()?;
        Ok(CsvRows {
            path: path.to_path_buf(),
            reader,
            columns,
            names: wanted.iter().map(|w| w.to_string()).collect(),
            line: 1,
            headers,
            // Both tables round their coordinates to 1 um (an earlier
            // version's colliding_points.csv wrote them whole: it passes).
            rounding: ROUNDED_TOL_MM,
        })
    }

    fn has_column(&self, name: &str) -> bool {
        self.headers.iter().any(|h| h == name)
    }

    fn bad(&self, reason: String) -> ReportError {
        ReportError::Inconsistent {
            path: self.path.clone(),
            reason: format!("line {}: {reason}", self.line),
        }
    }

    fn next_row(&mut self) -> Result<Option<csv::StringRecord>, ReportError> {
        let mut row = csv::StringRecord::new();
        self.line += 1;
        match self.reader.read_record(&mut row) {
            Ok(true) => Ok(Some(row)),
            Ok(false) => Ok(None),
            Err(e) => Err(self.bad(e.to_string())),
        }
    }

    /// The `n`-th wanted column of `row`, parsed.
    fn parse<T: std::str::FromStr>(
        &self,
        row: &csv::StringRecord,
        n: usize,
    ) -> Result<T, ReportError> {
        let field = row.get(self.columns[n]).unwrap_or("");
        field
            .parse()
            .map_err(|_| self.bad(format!("{} = {field:?} is not a number", self.names[n])))
    }

    /// The node index of a row with `i`, `j`, `x`, `y`, `z` among its
    /// wanted columns (by those names), checked against the grid (a CSV of
    /// another grid must not be painted on this one), and the node's depth
    /// on the grid: the row's point (part frame) mapped by `frame` into
    /// vehicle coordinates, then by `axes` onto the grid (its y, for
    /// push-and-slide).
    fn node(
        &self,
        row: &csv::StringRecord,
        spec: GridSpec,
        frame: &Frame,
        axes: GridAxes,
    ) -> Result<(usize, f64), ReportError> {
        let col = |name: &str| {
            self.names
                .iter()
                .position(|n| n == name)
                .expect("a wanted column")
        };
        let i: usize = self.parse(row, col("i"))?;
        let j: usize = self.parse(row, col("j"))?;
        let x: f64 = self.parse(row, col("x"))?;
        let y: f64 = self.parse(row, col("y"))?;
        let z: f64 = self.parse(row, col("z"))?;
        let part_point = [x, y, z];
        let [x, y, z] = axes.grid(frame.to_vehicle(part_point));
        // Through a frame the point was mapped twice (to the part for the
        // CSV, back here): a few units in the last place of its largest
        // coordinate, in either frame, not of x or z alone.
        let reach = if frame.is_none() {
            0.0
        } else {
            part_point
                .iter()
                .chain(&[x, y, z])
                .fold(spec.pitch, |m, c| m.max(c.abs()))
        };
        let scale = spec.pitch.max(reach);
        let near = |v: f64, node: f64| {
            same_coordinate(v, node, scale) || (v - node).abs() <= self.rounding
        };
        if i >= spec.nx || j >= spec.nz || !near(x, spec.x(i)) || !near(z, spec.z(j)) {
            return Err(self.bad(format!(
                "node ({i}, {j}) at x = {x}, z = {z} is not a node of the run's {} x {} grid",
                spec.nx, spec.nz
            )));
        }
        Ok((j * spec.nx + i, y))
    }
}

/// Finds the run's part file, or an assembly's analysed files (merged, in
/// order), and reads them in their own frame; the path is the (first)
/// file's.
fn find_parts(
    dir: &Path,
    given: Option<&Path>,
    summary: &Summary,
) -> Result<(PathBuf, Part), ReportError> {
    if summary.files.is_empty() {
        return find_part(
            dir,
            given,
            &summary.input_file,
            &summary.sha256,
            summary.scale,
        );
    }
    if let Some(path) = given {
        return Err(ReportError::Part {
            path: path.to_path_buf(),
            reason: format!(
                "the run is an assembly of {} files, found by their paths and SHA-256 in summary.json; --part names one file",
                summary.files.len()
            ),
        });
    }
    let mut first = None;
    let mut triangles = Vec::new();
    let (mut file_triangles, mut degenerate, mut bodies) = (0, 0, 0);
    for f in summary.files.iter().filter(|f| !f.ignored) {
        let (path, part) = find_part(dir, None, &f.path, &f.sha256, summary.scale)?;
        first.get_or_insert(path);
        triangles.extend(part.triangles);
        file_triangles += part.file_triangles;
        degenerate += part.degenerate;
        bodies += part.bodies;
    }
    let first = first.ok_or_else(|| ReportError::Part {
        path: dir.join(crate::output::SUMMARY_JSON),
        reason: "every file of the assembly is ignored".into(),
    })?;
    Ok((
        first,
        Part {
            triangles,
            file_triangles,
            degenerate,
            bodies,
        },
    ))
}

/// Finds the part file named `input_file` with SHA-256 `sha256` (at
/// `given` when given) and reads it in its own frame.
fn find_part(
    dir: &Path,
    given: Option<&Path>,
    input_file: &str,
    sha256: &str,
    scale: f64,
) -> Result<(PathBuf, Part), ReportError> {
    let named = PathBuf::from(input_file);
    let candidates: Vec<PathBuf> = match given {
        Some(p) => vec![p.to_path_buf()],
        None => {
            let mut c = vec![named.clone()];
            if named.is_relative() {
                if let Some(parent) = dir.parent() {
                    c.push(parent.join(&named));
                }
                // A report made from another directory: the part named
                // relative to where the run was made, which is most often
                // an ancestor of the run directory (the SHA-256 decides).
                if let Ok(real) = dir.canonicalize() {
                    c.extend(real.ancestors().skip(1).take(8).map(|a| a.join(&named)));
                }
            }
            c
        }
    };
    let mut mismatched = Vec::new();
    for path in &candidates {
        let Ok(bytes) = crate::limits::read_bounded(path, crate::limits::MAX_PART_FILE_BYTES)
        else {
            continue;
        };
        let sha = sha256_hex(&bytes);
        if sha != sha256 {
            mismatched.push((path.clone(), sha));
            continue;
        }
        // As `analyze` read it, scaled but never mirrored: the report
        // draws the part as it is.
        let part = read_part_bytes(path, &bytes, scale, Side::Left)
            .map_err(|e| ReportError::Part {
                path: path.clone(),
                reason: e.to_string(),
            })?
            .part;
        return Ok((path.clone(), part));
    }
    if let Some((path, sha)) = mismatched.into_iter().next() {
        return Err(ReportError::PartChanged {
            path,
            expected: sha256.to_string(),
            found: sha,
        });
    }
    Err(ReportError::PartMissing {
        input_file: input_file.to_string(),
        tried: candidates,
    })
}

fn read_text(path: &Path) -> Result<String, ReportError> {
    let io = |source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    };
    let bytes = crate::limits::read_bounded(path, crate::limits::MAX_RUN_JSON_BYTES).map_err(io)?;
    String::from_utf8(bytes)
        .map_err(|e| io(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts() -> NodeCounts {
        let spec = GridSpec {
            pitch: 2.0,
            i_origin: -3,
            j_origin: 10,
            nx: 5,
            nz: 4,
        };
        let mut c = NodeCounts::empty(spec).unwrap();
        // Node (1, 2) at x = -4, z = 24, count 3; its neighbour (2, 2) at
        // x = -2, count 5.
        c.count[2 * 5 + 1] = 3;
        c.y[2 * 5 + 1] = -1.0;
        c.count[2 * 5 + 2] = 5;
        c.y[2 * 5 + 2] = -2.0;
        c
    }

    fn summary_with(origin: [f64; 2], pitch: f64) -> Summary {
        serde_json::from_value(serde_json::json!({
            "kneeform_version": "0", "run_unix_time": 0, "input_file": "p.stl",
            "sha256": "", "triangles": 1, "degenerate_triangles": 0,
            "bbox_min": [0.0, 0.0, 0.0], "bbox_max": [1.0, 1.0, 1.0], "scale": 1.0,
            "side": "left", "triangle_side_mm": 200.0, "triangle_side_assumed": true,
            "radius_mm": 60.0, "thickness_mm": 120.0, "pitch_mm": pitch,
            "grid_origin": origin, "grid_size": [3, 4], "sampled_nodes": 1,
            "angles_deg": [0.0], "deflection_deg": 0.5, "sigma": 0.008726867790758,
            "e0_mm": 1e-6, "rate": "x-slope", "algorithm": "fast", "threads": 1,
            "per_angle": [], "composite_nodes": 0, "composite_area_mm2": 0.0,
            "timings": {"read_s": 0.0, "sample_s": 0.0, "push_slide_s": 0.0,
                        "write_s": 0.0, "total_s": 0.0}
        }))
        .unwrap()
    }

    #[test]
    fn the_readme_runs_origin_is_a_grid_even_a_last_place_off() {
        // The README's console at 1.24 mm: z0 = 1.24 * -189, written as
        // -234.35999999999999; read back by a parser that is one unit in
        // the last place off, or exactly.
        let z0: f64 = 1.24 * -189.0;
        for z in [
            z0,
            f64::from_bits(z0.to_bits() + 1),
            f64::from_bits(z0.to_bits() - 1),
        ] {
            let spec = grid_spec(&summary_with([1.24 * -210.0, z], 1.24)).expect("a grid");
            assert_eq!((spec.i_origin, spec.j_origin), (-210, -189));
        }
        // Between nodes, or not a number: not a grid.
        assert!(grid_spec(&summary_with([0.5, 0.0], 1.0)).is_none());
        assert!(grid_spec(&summary_with([1.0 + 1e-9, 0.0], 1.0)).is_none());
        assert!(grid_spec(&summary_with([0.0, 0.0], 0.0)).is_none());
    }

    #[test]
    fn a_point_takes_the_largest_count_of_the_cells_holding_it() {
        let c = counts();
        assert_eq!(c.at(-4.0, 24.0), Some((3, -1.0)));
        assert_eq!(c.at(-4.99, 24.99), Some((3, -1.0)));
        // On the shared cell edge both nodes hold it: the larger count.
        assert_eq!(c.at(-3.0, 24.0), Some((5, -2.0)));
        assert_eq!(c.at(-1.0, 23.0), Some((5, -2.0)));
        assert_eq!(c.at(-0.99, 24.0), None);
        assert_eq!(c.at(-4.0, 25.01), None);
        assert_eq!(c.at(-5.01, 24.0), None);
        // Far outside the grid.
        assert_eq!(c.at(1e6, -1e6), None);
        assert_eq!(c.nodes(), 2);
    }
}
