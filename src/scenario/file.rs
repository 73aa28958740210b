//! Scenario files: a part written as data (TOML), a height field summed
//! from named primitives ([`Feature`]) over an extent, with the lattice
//! step it is tessellated at and a one-line description of what it tests.
//!
//! ```toml
//! description = "y = 5 sin(2 pi x / 100): crests 5 mm towards the knee"
//!
//! [extent]
//! x = [-300, 300]   # mm
//! z = [-150, 150]   # mm
//! step = 2          # mm, the lattice step
//!
//! [[feature]]
//! kind = "wave"
//! amplitude = 5
//! wavelength = 100
//! ```
//!
//! Unknown kinds and fields are errors, as are parameters that make no
//! surface; every error names the file.

use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::lattice::{MAX_TRIANGLES, axis, refined_step, tessellate, triangle_count};
use super::primitive::Feature;
use crate::mesh::Triangle;

/// A scenario file, loaded and checked: the surface `y(x, z)` (mm,
/// analysis frame) is the sum of its features over its extent.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// What the part tests, in one line.
    pub description: String,
    /// Where the part lies and how finely it is tessellated.
    pub extent: Extent,
    /// The primitives summed into the height field, `[[feature]]` in the
    /// file; none is the flat wall `y = 0`.
    #[serde(default, rename = "feature")]
    pub features: Vec<Feature>,
}

/// The part's extent in x and z and its tessellation step (mm).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Extent {
    /// `[low, high]` in x (mm).
    pub x: [f64; 2],
    /// `[low, high]` in z (mm).
    pub z: [f64; 2],
    /// The lattice step (mm): vertices at its multiples, plus the range
    /// ends and the features' creases.
    pub step: f64,
}

/// Why a scenario file could not be used. Each names the file.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario {}: {cause}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why. Not a `source`: the message already says it, and the CLI
        /// prints the whole chain.
        cause: std::io::Error,
    },
    /// The file is not valid TOML, or not the scenario schema (an unknown
    /// kind or field, a missing parameter, a wrong type).
    #[error("{}:{line}:{column}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// Line of the error (1-based; 0 when the parser gave no place).
        line: usize,
        /// Column of the error (1-based; 0 when the parser gave no place).
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// The file parses but describes no surface (an empty extent, a
    /// non-positive step, a bad parameter).
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the feature and parameter.
        message: String,
    },
}

/// Reads and checks the scenario file at `path`.
pub fn load(path: &Path) -> Result<ScenarioFile, ScenarioError> {
    let text = crate::limits::read_text_bounded(path).map_err(|cause| ScenarioError::Read {
        path: path.to_owned(),
        cause,
    })?;
    parse(&text, path)
}

/// Parses and checks scenario `text`; `path` only names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<ScenarioFile, ScenarioError> {
    let file: ScenarioFile = toml::from_str(text).map_err(|e| {
        let (line, column) = e.span().map_or((0, 0), |span| line_column(text, span));
        ScenarioError::Parse {
            path: path.to_owned(),
            line,
            column,
            message: e.message().trim().replace('\n', " "),
        }
    })?;
    file.check().map_err(|message| ScenarioError::Invalid {
        path: path.to_owned(),
        message,
    })?;
    Ok(file)
}

/// Loads the scenario file at `path` and tessellates it
/// ([`ScenarioFile::triangulate`]).
#[cfg(test)]
fn triangles_from_file(
    path: &Path,
    min_triangles: Option<usize>,
) -> Result<Vec<Triangle>, ScenarioError> {
    let file = load(path)?;
    if let Some(n) = min_triangles.filter(|&n| n > MAX_TRIANGLES) {
        return Err(ScenarioError::Invalid {
            path: path.to_owned(),
            message: format!("{n} triangles requested, at most {MAX_TRIANGLES} are made"),
        });
    }
    Ok(file.triangulate(min_triangles))
}

/// Whether `path` names a scenario file rather than a mesh: its extension
/// is `.toml` (any case).
pub fn is_scenario_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// 1-based line and column of the start of `span` in `text`.
fn line_column(text: &str, span: Range<usize>) -> (usize, usize) {
    let before = &text[..span.start.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

impl ScenarioFile {
    /// The surface's y (mm, analysis frame) at `(x, z)` (mm): the sum of
    /// the features' contributions, 0 without features.
    pub fn height(&self, x: f64, z: f64) -> f64 {
        self.features.iter().map(|f| f.height(x, z)).sum()
    }

    /// The lattice step (mm) [`ScenarioFile::triangulate`] uses: the file's
    /// step, or with `Some(n)` the step refined uniformly until there are
    /// at least `n` triangles: the largest such step, so the count exceeds
    /// `n` by less than one lattice line of cells when the file's step gives
    /// fewer.
    pub fn step_for(&self, min_triangles: Option<usize>) -> f64 {
        let [xs, zs] = self.creases();
        match min_triangles {
            None => self.extent.step,
            Some(n) => refined_step(self.ranges(), self.extent.step, [&xs, &zs], n),
        }
    }

    /// The triangle count [`ScenarioFile::triangulate`] gives.
    pub fn triangle_count(&self, min_triangles: Option<usize>) -> usize {
        let [xs, zs] = self.creases();
        triangle_count(self.ranges(), self.step_for(min_triangles), [&xs, &zs])
    }

    /// Tessellates the part: a lattice at multiples of the step
    /// ([`ScenarioFile::step_for`]) over the extent, plus vertex lines at
    /// every feature's creases (so thin ribs, flat tops and peaks are in
    /// the mesh at any step), two triangles per cell with normals facing
    /// -y (the knee). Vertex y is exactly [`ScenarioFile::height`].
    ///
    /// # Panics
    ///
    /// If `min_triangles` exceeds [`MAX_TRIANGLES`] (loading checks the
    /// file's own step against it).
    pub fn triangulate(&self, min_triangles: Option<usize>) -> Vec<Triangle> {
        assert!(
            min_triangles.is_none_or(|n| n <= MAX_TRIANGLES),
            "at most {MAX_TRIANGLES} triangles, {min_triangles:?} requested"
        );
        let step = self.step_for(min_triangles);
        let [cx, cz] = self.creases();
        let [rx, rz] = self.ranges();
        let xs = axis(rx, step, &cx);
        let zs = axis(rz, step, &cz);
        tessellate(&xs, &zs, |i, k| self.height(xs[i], zs[k]))
    }

    fn ranges(&self) -> [(f64, f64); 2] {
        [
            (self.extent.x[0], self.extent.x[1]),
            (self.extent.z[0], self.extent.z[1]),
        ]
    }

    /// Every feature's crease lines, `[xs, zs]`.
    fn creases(&self) -> [Vec<f64>; 2] {
        let mut out = [Vec::new(), Vec::new()];
        for f in &self.features {
            let [xs, zs] = f.creases((self.extent.x[0], self.extent.x[1]));
            out[0].extend(xs);
            out[1].extend(zs);
        }
        out
    }

    /// The first thing that makes this file no surface, as a sentence.
    fn check(&self) -> Result<(), String> {
        if self.description.trim().is_empty() || self.description.contains('\n') {
            return Err("`description` must be one non-empty line".into());
        }
        let Extent { x, z, step } = self.extent;
        for (name, [lo, hi]) in [("x", x), ("z", z)] {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(format!(
                    "extent `{name}` must be [low, high] with low < high, got [{lo}, {hi}]"
                ));
            }
        }
        if !(step.is_finite() && step > 0.0) {
            return Err(format!("extent `step` must be positive, got {step}"));
        }
        for (k, f) in self.features.iter().enumerate() {
            f.check()
                .map_err(|e| format!("feature {} (`{}`): {e}", k + 1, f.kind()))?;
        }
        // Counted on the axes' lengths, before any lattice is built.
        let cells = ((x[1] - x[0]) / step + 2.0) * ((z[1] - z[0]) / step + 2.0);
        if 2.0 * cells > MAX_TRIANGLES as f64 || self.triangle_count(None) > MAX_TRIANGLES {
            return Err(format!(
                "extent `step` {step} mm makes more than {MAX_TRIANGLES} triangles"
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(text: &str) -> Result<ScenarioFile, ScenarioError> {
        parse(text, Path::new("scenarios/test-part.toml"))
    }

    const HEAD: &str = "description = \"a test part\"\n\
                        [extent]\nx = [0, 100]\nz = [0, 50]\nstep = 5\n";

    #[test]
    fn integers_and_defaults_parse() {
        let f = parse_str(&format!(
            "{HEAD}[[feature]]\nkind = \"plane\"\nslope_x = 1\n"
        ))
        .unwrap();
        assert_eq!(f.extent.x, [0.0, 100.0]);
        assert_eq!(f.height(7.0, 3.0), 7.0);
        assert_eq!(f.triangulate(None).len(), 2 * 20 * 10);
    }

    #[test]
    fn unknown_kinds_are_rejected_naming_the_file_and_line() {
        let err = parse_str(&format!("{HEAD}[[feature]]\nkind = \"blob\"\n")).unwrap_err();
        let msg = err.to_string();
        // Line 7 is `kind = "blob"`: the five lines of HEAD, then `[[feature]]`.
        assert!(msg.starts_with("scenarios/test-part.toml:7:"), "{msg}");
        assert!(msg.contains("unknown variant `blob`"), "{msg}");
        assert!(!msg.contains('\n'), "{msg}");
    }

    #[test]
    fn unknown_fields_are_rejected_naming_the_file() {
        let feature = "[[feature]]\nkind = \"bump\"\ncenter = [0, 0]\nradius = 4\nheight = 1\n";
        assert!(parse_str(&format!("{HEAD}{feature}")).is_ok());
        for (text, field) in [
            (format!("{HEAD}{feature}radiuss = 5\n"), "radiuss"),
            (format!("{HEAD}colour = 1\n"), "colour"),
            (HEAD.replace("step = 5", "step = 5\npitch = 1"), "pitch"),
        ] {
            let msg = parse_str(&text).unwrap_err().to_string();
            assert!(msg.starts_with("scenarios/test-part.toml:"), "{msg}");
            assert!(msg.contains(&format!("unknown field `{field}`")), "{msg}");
        }
    }

    #[test]
    fn missing_parameters_and_bad_values_are_rejected() {
        let msg = parse_str(&format!(
            "{HEAD}[[feature]]\nkind = \"bump\"\nradius = 4\nheight = 1\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(msg.contains("missing field `center`"), "{msg}");
        let msg = parse_str(&HEAD.replace("step = 5", "step = 0"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "scenarios/test-part.toml: extent `step` must be positive, got 0"
        );
        let msg = parse_str(&HEAD.replace("x = [0, 100]", "x = [100, 0]"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("extent `x` must be [low, high]"), "{msg}");
        let msg = parse_str(&HEAD.replace("step = 5", "step = 0.001"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("more than 20000000 triangles"), "{msg}");
        let msg = parse_str(&format!(
            "{HEAD}[[feature]]\nkind = \"plane\"\n[[feature]]\nkind = \"groove\"\n\
             from = [0, 0]\nto = [0, 10]\nhalf_width = 1\nshoulder = -1\ndepth = 1\n"
        ))
        .unwrap_err()
        .to_string();
        assert_eq!(
            msg,
            "scenarios/test-part.toml: feature 2 (`groove`): `shoulder` must be positive, got -1"
        );
    }

    #[test]
    fn unreadable_files_are_named() {
        let err = load(Path::new("/nonexistent/part.toml")).unwrap_err();
        let msg = format!("{:#}", anyhow::Error::from(err));
        assert!(
            msg.starts_with("cannot read scenario /nonexistent/part.toml: "),
            "{msg}"
        );
        // Said once, though the CLI prints the whole chain.
        assert_eq!(msg.matches("os error").count(), 1, "{msg}");
    }

    #[test]
    fn toml_files_are_scenarios() {
        assert!(is_scenario_file(Path::new("scenarios/wave.toml")));
        assert!(is_scenario_file(Path::new("A.TOML")));
        assert!(!is_scenario_file(Path::new("part.stl")));
        assert!(!is_scenario_file(Path::new("toml")));
    }

    #[test]
    fn too_many_triangles_are_refused_before_any_work() {
        let dir = crate::output::temp_dir("scenario-file");
        let path = dir.join("p.toml");
        std::fs::write(&path, HEAD).unwrap();
        assert_eq!(triangles_from_file(&path, None).unwrap().len(), 400);
        let msg = triangles_from_file(&path, Some(MAX_TRIANGLES + 1))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("at most 20000000"), "{msg}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
