//! `summary.json`: every parameter, input identity, count and timing of a
//! run, so that a result can be audited and reproduced from it alone.

use serde::{Deserialize, Serialize};

/// The colliding area at one angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleSummary {
    /// Knee-form angle (degrees).
    pub angle_deg: f64,
    /// Starts where the knee-form touched the part.
    pub placed_starts: usize,
    /// Grid nodes in the colliding mask.
    pub colliding_nodes: usize,
    /// Their area, `colliding_nodes * pitch^2` (mm^2).
    pub colliding_area_mm2: f64,
}

/// One file of an assembly ([`crate::assembly`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileSummary {
    /// The file as given.
    pub path: String,
    /// SHA-256 of its bytes (hex).
    pub sha256: String,
    /// Triangles in the file.
    pub triangles: usize,
    /// Of those, skipped for zero area.
    pub degenerate_triangles: usize,
    /// Disregarded by the regulation (`--ignore`: softer than 50 Shore
    /// A): not in the height grid, so it never collides.
    pub ignored: bool,
    /// Composite nodes whose height this file's surface set (the lowest
    /// file index where two files set the same height): the `file` column
    /// of the CSV files.
    pub colliding_nodes: usize,
    /// Their area, `colliding_nodes * pitch^2` (mm^2).
    pub colliding_area_mm2: f64,
}

/// Wall-clock time per stage (seconds).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Reading and hashing the STL.
    pub read_s: f64,
    /// Sampling the height grid.
    pub sample_s: f64,
    /// Push and slide over every angle.
    pub push_slide_s: f64,
    /// Finding the blind spots.
    #[serde(default)]
    pub blind_s: f64,
    /// Writing the output files.
    pub write_s: f64,
    /// Everything.
    pub total_s: f64,
}

/// The whole run. Keys are snake_case; lengths mm, angles degrees, the
/// bounding box in the part's own frame (after `scale`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Version of kneeform that produced the run.
    pub kneeform_version: String,
    /// When the run finished (seconds since the Unix epoch, UTC).
    pub run_unix_time: u64,
    /// The part file as given.
    pub input_file: String,
    /// SHA-256 of the part file's bytes (hex); empty for an assembly,
    /// whose files are in `files`.
    pub sha256: String,
    /// An assembly's files (`analyze a.stl b.stl`, or any `--ignore`), in
    /// order: each one's path, SHA-256 and colliding area. Absent for one
    /// file.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<FileSummary>,
    /// Triangles in the file.
    pub triangles: usize,
    /// Triangles skipped for zero area.
    pub degenerate_triangles: usize,
    /// Part bounding box, smallest x, y, z (mm, part frame).
    pub bbox_min: [f64; 3],
    /// Part bounding box, largest x, y, z (mm, part frame).
    pub bbox_max: [f64; 3],
    /// Factor from the file's units to mm.
    pub scale: f64,
    /// `left` or `right`.
    pub side: crate::Side,
    /// `--frame`: the map from the part's coordinates into vehicle
    /// coordinates, applied before the side's mirror. Absent without one
    /// (the part is in vehicle coordinates).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<crate::frame::FrameRecord>,
    /// Knee-form triangle side L (mm).
    pub triangle_side_mm: f64,
    /// True when L is the assumed default of 200 mm.
    pub triangle_side_assumed: bool,
    /// Knee-form radius R (mm).
    pub radius_mm: f64,
    /// Knee-form thickness W (mm).
    pub thickness_mm: f64,
    /// Grid pitch (mm).
    pub pitch_mm: f64,
    /// x, z of grid node (0, 0) (mm).
    pub grid_origin: [f64; 2],
    /// Nodes along x, z.
    pub grid_size: [usize; 2],
    /// Nodes with a finite height.
    pub sampled_nodes: usize,
    /// Angles analysed (degrees).
    pub angles_deg: Vec<f64>,
    /// Deflection threshold delta (degrees): a contact is a strike when
    /// the surface turns the knee-form aside by more than this.
    pub deflection_deg: f64,
    /// The same threshold as a rate, `sigma = tan(delta)`.
    pub sigma: f64,
    /// Rounding tolerance e0 (mm): a point is a contact when it sticks out
    /// past the face level by more than this.
    pub e0_mm: f64,
    /// How a contact's deflection rate is estimated: `x-slope` (the
    /// default, SPEC's baseline: the rise from the node one pitch behind
    /// it) or `capped` (that rise capped by the node's drop below the face
    /// level over one pitch).
    pub rate: String,
    /// `fast` or `paper`.
    pub algorithm: crate::Algorithm,
    /// Worker threads.
    pub threads: usize,
    /// Per angle, in the order of `angles_deg`.
    pub per_angle: Vec<AngleSummary>,
    /// Nodes colliding at some angle.
    pub composite_nodes: usize,
    /// Their area (mm^2).
    pub composite_area_mm2: f64,
    /// The depth threshold of a blind spot (mm). Absent in runs of
    /// earlier versions.
    #[serde(default)]
    pub blind_depth_mm: f64,
    /// Grid cells where the part sticks out between the nodes by more
    /// than `blind_depth_mm`: `blind_spots.csv`.
    #[serde(default)]
    pub blind_spots: usize,
    /// Those the knee-form's face meets at some angle at a level they
    /// stick out past: contacts the grid cannot see (said in `warnings`).
    #[serde(default)]
    pub blind_spots_met: usize,
    /// With `--pitch auto`: the pitch study, its tolerance and why it
    /// chose `pitch_mm`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_study: Option<crate::harness::PitchChoice>,
    /// Time per stage.
    pub timings: Timings,
    /// The sanity checks' warnings (one line each), as printed on stderr:
    /// a part in the wrong units or facing the wrong way, angles beyond the
    /// regulation's, nothing struck. Absent in runs of earlier versions.
    #[serde(default)]
    pub warnings: Vec<String>,
}
