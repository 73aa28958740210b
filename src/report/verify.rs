//! Reading verification directories: what `kneeform verify` (`verify.json`,
//! `verify.csv`) and `kneeform converge` (`converge.json`, `converge.csv`,
//! plots) leave behind.
//!
//! The files are kept as raw JSON and text, and only the few fields the
//! report reasons about (tolerance, verdict, recommended pitch) are read by
//! name, each optional: the report shows whatever metrics a run holds, so a
//! new metric needs no change here.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::error::ReportError;
use crate::limits::{MAX_RUN_JSON_BYTES, MAX_RUN_TABLE_BYTES};

/// The figures a verification directory may hold, in the order shown.
pub(crate) const VERIFY_FIGURES: [&str; 2] = ["error_vs_pitch.png", "time_vs_pitch.png"];

/// One verification directory, read.
#[derive(Debug, Clone)]
pub struct Verification {
    /// The directory as given.
    pub dir: PathBuf,
    /// `verify.json`, when present.
    pub verify: Option<Value>,
    /// `verify.csv`, when present (text).
    pub verify_csv: Option<String>,
    /// `converge.json`, when present.
    pub converge: Option<Value>,
    /// `converge.csv`, when present (text).
    pub converge_csv: Option<String>,
    /// The figures of [`VERIFY_FIGURES`] present: file name and PNG bytes.
    pub figures: Vec<(String, Vec<u8>)>,
}

/// The citation prefix of the `k`-th verification directory's files.
pub(crate) fn verify_label(k: usize, file: &str) -> String {
    format!("verify[{k}]/{file}")
}

/// The verdict of a `verify` run against its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Verdict {
    /// The file says the run passed.
    Pass,
    /// The file says the run failed.
    Fail,
    /// The file says the run's evidence supports no claim.
    Inconclusive,
    /// The file gives no verdict.
    Unknown,
}

impl Verification {
    /// Reads `dir`; at least one of `verify.json` and `converge.json` must
    /// be there.
    pub fn read(dir: &Path) -> Result<Verification, ReportError> {
        let json = |name: &str| -> Result<Option<Value>, ReportError> {
            let path = dir.join(name);
            match checked_text(dir, name, MAX_RUN_JSON_BYTES)? {
                None => Ok(None),
                Some(text) => serde_json::from_str(&text)
                    .map(Some)
                    .map_err(|source| ReportError::Json { path, source }),
            }
        };
        let verify = json("verify.json")?;
        let converge = json("converge.json")?;
        if verify.is_none() && converge.is_none() {
            return Err(ReportError::NotAVerification {
                dir: dir.to_path_buf(),
            });
        }
        // Without a record (a directory of an older kneeform), verify.csv
        // is read no further than its verify.json's pairs could fill.
        let pairs = verify
            .as_ref()
            .and_then(|v| v.pointer("/counts/pairs"))
            .and_then(Value::as_u64);
        let csv_bound = pairs.map_or(MAX_RUN_TABLE_BYTES, |p| {
            (p.saturating_add(1))
                .saturating_mul(MAX_CSV_ROW_BYTES)
                .min(MAX_RUN_TABLE_BYTES)
        });
        let verify_csv = checked_text(dir, "verify.csv", csv_bound)?;
        if let (Some(text), Some(pairs)) = (&verify_csv, pairs) {
            let rows = text.lines().count().saturating_sub(1) as u64;
            if rows != pairs {
                return Err(ReportError::Inconsistent {
                    path: dir.join("verify.csv"),
                    reason: format!(
                        "{rows} rows where its verify.json counts {pairs} pairs: the table is not that study's"
                    ),
                });
            }
        }
        let figures = VERIFY_FIGURES
            .iter()
            .map(|name| {
                Ok(checked_bytes(dir, name, MAX_RUN_TABLE_BYTES)?.map(|b| (name.to_string(), b)))
            })
            .collect::<Result<Vec<_>, ReportError>>()?
            .into_iter()
            .flatten()
            .collect();
        Ok(Verification {
            dir: dir.to_path_buf(),
            verify,
            verify_csv,
            converge,
            converge_csv: checked_text(dir, "converge.csv", MAX_RUN_TABLE_BYTES)?,
            figures,
        })
    }

    /// The `outcome` field of `verify.json`; in a file written before
    /// outcomes, its `pass`.
    pub fn verdict(&self) -> Verdict {
        let json = self.verify.as_ref();
        match json.and_then(|v| v.get("outcome")).and_then(Value::as_str) {
            Some("PASS") => return Verdict::Pass,
            Some("FAIL") => return Verdict::Fail,
            Some("INCONCLUSIVE") => return Verdict::Inconclusive,
            _ => {}
        }
        match json.and_then(|v| v.get("pass")) {
            Some(Value::Bool(true)) => Verdict::Pass,
            Some(Value::Bool(false)) => Verdict::Fail,
            _ => Verdict::Unknown,
        }
    }
}

/// The keys of a strike rule, in `summary.json`, `verify.json` and
/// `converge.json` alike: today's contact tolerance and the deflection
/// rule's parameters. A key present in one file must be in the other, with
/// the same value.
pub const STRIKE_RULE_KEYS: [&str; 7] = [
    "eps_mm",
    "deflection_deg",
    "sigma",
    "e0_mm",
    "rate",
    "level",
    "window_mm",
];

/// Relative tolerance of the numbers compared between a run and a
/// verification: both were written from the same flags, so they agree to
/// the last bits; this only forgives a reader's last-place rounding.
const SAME_NUMBER: f64 = 1e-12;

impl Verification {
    /// Checks that this verification is of the run whose `summary.json` is
    /// `run`: the same part (SHA-256 of the file, scale, side), knee-form,
    /// pitch (in `verify.json`; in `converge.json`, the run's pitch among
    /// the pitches studied) and strike rule. Fields are compared where
    /// both files have them, except the part's SHA-256, which must be
    /// there: without it the verification could be of any part.
    pub fn check_against(&self, run: &Value) -> Result<(), ReportError> {
        for (file, json) in [
            ("verify.json", &self.verify),
            ("converge.json", &self.converge),
        ] {
            if let Some(json) = json {
                self.check_file(file, json, run)?;
            }
        }
        Ok(())
    }

    fn check_file(&self, file: &str, json: &Value, run: &Value) -> Result<(), ReportError> {
        let refuse = |reason: String| ReportError::Mismatch {
            dir: self.dir.clone(),
            file: file.to_string(),
            reason,
        };
        // verify and converge read one file: an assembly's run is of
        // several, whatever its first file.
        if let Some(Value::Array(files)) = run.get("files") {
            return Err(refuse(format!(
                "the run is an assembly of {} files, and a verification checks one part file",
                files.len()
            )));
        }
        match (json.get("input_sha256"), run.get("sha256")) {
            (Some(Value::String(a)), Some(Value::String(b))) if a == b => {}
            (Some(Value::String(a)), Some(Value::String(b))) => {
                return Err(refuse(format!(
                    "it verified another part (SHA-256 {}..., the run's {}...)",
                    short(a),
                    short(b)
                )));
            }
            _ => {
                return Err(refuse(
                    "it does not record the part's SHA-256 (input_sha256; written by an earlier kneeform), so it may be of another part: run it again".into(),
                ));
            }
        }
        // A frame moves the part in the analysis frame: another setup.
        // Absent is no frame, on either side.
        let frame = |v: &Value| {
            v.get("frame")
                .and_then(|f| f.get("part_to_vehicle"))
                .cloned()
        };
        match (frame(json), frame(run)) {
            (None, None) => {}
            (Some(a), Some(b)) if same(&a, &b) => {}
            (a, b) => {
                let say = |f: Option<Value>| f.map_or("none".to_string(), |f| f.to_string());
                return Err(refuse(format!(
                    "its frame (part to vehicle) is {}, the run's {}",
                    say(a),
                    say(b)
                )));
            }
        }
        for key in ["scale", "side"] {
            if let (Some(a), Some(b)) = (json.get(key), run.get(key))
                && !same(a, b)
            {
                return Err(refuse(format!("its {key} is {a}, the run's {b}")));
            }
        }
        if let Some(knee) = json.get("knee_form_mm") {
            let run_knee = Value::from(
                ["triangle_side_mm", "radius_mm", "thickness_mm"]
                    .iter()
                    .map(|k| run.get(*k).cloned().unwrap_or(Value::Null))
                    .collect::<Vec<_>>(),
            );
            if !same(knee, &run_knee) {
                return Err(refuse(format!(
                    "its knee-form L, R, W is {knee} mm, the run's {run_knee} mm"
                )));
            }
        }
        let run_pitch = run.get("pitch_mm").and_then(Value::as_f64);
        if let (Some(p), Some(run_p)) = (json.get("pitch_mm").and_then(Value::as_f64), run_pitch)
            && !close(p, run_p)
        {
            return Err(refuse(format!("its pitch is {p} mm, the run's {run_p} mm")));
        }
        if let (Some(Value::Array(ladder)), Some(run_p)) = (json.get("pitches_mm"), run_pitch)
            && !ladder
                .iter()
                .filter_map(Value::as_f64)
                .any(|p| close(p, run_p))
        {
            let ladder: Vec<String> = ladder.iter().map(Value::to_string).collect();
            return Err(refuse(format!(
                "its pitch ladder {} mm does not include the run's {run_p} mm",
                ladder.join(", ")
            )));
        }
        let rule = |v: &Value| -> Vec<&str> {
            STRIKE_RULE_KEYS
                .iter()
                .copied()
                .filter(|k| v.get(*k).is_some())
                .collect()
        };
        let (mine, theirs) = (rule(json), rule(run));
        if mine != theirs {
            return Err(refuse(format!(
                "its strike rule has {}, the run's {}",
                list(&mine),
                list(&theirs)
            )));
        }
        for key in mine {
            let (a, b) = (&json[key], &run[key]);
            if !same(a, b) {
                return Err(refuse(format!(
                    "its strike rule differs: {key} is {a}, the run's {b}"
                )));
            }
        }
        Ok(())
    }
}

/// Equal JSON values, numbers within [`SAME_NUMBER`] (relative).
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => close(x, y),
            _ => false,
        },
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b))
        }
        _ => a == b,
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= SAME_NUMBER * a.abs().max(b.abs())
}

fn short(sha: &str) -> &str {
    sha.get(..12).unwrap_or(sha)
}

fn list(keys: &[&str]) -> String {
    if keys.is_empty() {
        "none of its fields".into()
    } else {
        keys.join(", ")
    }
}

/// The longest `verify.csv` row read per pair (bytes) where no record
/// states the table's size: its rows are some 300 bytes.
const MAX_CSV_ROW_BYTES: u64 = 4096;

/// The file `name` of the study directory `dir` as text, `None` when it
/// is not there; see [`checked_bytes`].
fn checked_text(dir: &Path, name: &str, max_bytes: u64) -> Result<Option<String>, ReportError> {
    let path = dir.join(name);
    checked_bytes(dir, name, max_bytes)?
        .map(|bytes| {
            String::from_utf8(bytes).map_err(|e| ReportError::Io {
                path: path.clone(),
                source: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
            })
        })
        .transpose()
}

/// The file `name` of the study directory `dir`, `None` when it is not
/// there. Where `dir` holds kneeform's record of the files it wrote
/// (`kneeform-run.json`), the file must be listed there, and is read only
/// when it has the recorded size and then only when its SHA-256 is the
/// recorded one: the report shows nothing of a file changed since the
/// study wrote it. Without a record (an older kneeform's directory), at
/// most `max_bytes` are read.
fn checked_bytes(dir: &Path, name: &str, max_bytes: u64) -> Result<Option<Vec<u8>>, ReportError> {
    use crate::output::RUN_RECORD;
    let path = dir.join(name);
    if !dir.join(RUN_RECORD).is_file() {
        return optional_bytes(&path, max_bytes);
    }
    let refuse = |reason: String| ReportError::Inconsistent {
        path: path.clone(),
        reason,
    };
    let Some(expected) = crate::output::recorded(dir, name) else {
        return match std::fs::symlink_metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            _ => Err(refuse(format!(
                "not in {RUN_RECORD}: the study did not write it"
            ))),
        };
    };
    let io = |source| ReportError::Io {
        path: path.clone(),
        source,
    };
    let len = std::fs::metadata(&path).map_err(io)?.len();
    if len != expected.bytes {
        return Err(refuse(format!(
            "{len} bytes where the study wrote {} ({RUN_RECORD}): changed since",
            expected.bytes
        )));
    }
    let bytes = crate::limits::read_bounded(&path, expected.bytes).map_err(io)?;
    let sha256 = crate::input::sha256_hex(&bytes);
    if sha256 != expected.sha256 {
        return Err(refuse(format!(
            "its SHA-256 is not the one the study recorded in {RUN_RECORD}: changed since the study wrote it"
        )));
    }
    Ok(Some(bytes))
}

fn optional_bytes(path: &Path, max_bytes: u64) -> Result<Option<Vec<u8>>, ReportError> {
    match crate::limits::read_bounded(path, max_bytes) {
        Ok(bytes) => Ok(Some(bytes)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(source) => Err(ReportError::Io {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// Every scalar (number, string, bool) under `value`, depth first in the
/// map's key order, as `(label, JSON pointer, value)`; the label joins the
/// keys with `.`. Arrays of numbers are kept whole, as one entry.
pub(crate) fn scalars<'a>(
    value: &'a Value,
    pointer: &str,
    label: &str,
) -> Vec<(String, String, &'a Value)> {
    let mut out = Vec::new();
    walk(value, pointer.to_string(), label.to_string(), &mut out);
    out
}

fn walk<'a>(
    value: &'a Value,
    pointer: String,
    label: String,
    out: &mut Vec<(String, String, &'a Value)>,
) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let sub = if label.is_empty() {
                    k.clone()
                } else {
                    format!("{label}.{k}")
                };
                walk(v, format!("{pointer}/{}", escape_pointer(k)), sub, out);
            }
        }
        Value::Array(items) if !items.iter().all(Value::is_number) => {
            for (k, v) in items.iter().enumerate() {
                walk(v, format!("{pointer}/{k}"), format!("{label}[{k}]"), out);
            }
        }
        Value::Null => {}
        _ => out.push((label, pointer, value)),
    }
}

/// A key as a JSON pointer token (RFC 6901: `~` as `~0`, `/` as `~1`).
pub(crate) fn escape_pointer(key: &str) -> String {
    key.replace('~', "~0").replace('/', "~1")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_json() -> Value {
        serde_json::json!({
            "sha256": "ab".repeat(32), "scale": 1.0, "side": "left",
            "triangle_side_mm": 200.0, "radius_mm": 60.0, "thickness_mm": 120.0,
            "pitch_mm": 1.24, "eps_mm": 0.001
        })
    }

    fn verification(verify: Option<Value>, converge: Option<Value>) -> Verification {
        Verification {
            dir: PathBuf::from("v"),
            verify,
            verify_csv: None,
            converge,
            converge_csv: None,
            figures: Vec::new(),
        }
    }

    fn matching_verify() -> Value {
        serde_json::json!({
            "input_sha256": "ab".repeat(32), "scale": 1.0, "side": "left",
            "knee_form_mm": [200.0, 60.0, 120.0], "pitch_mm": 1.24, "eps_mm": 0.001
        })
    }

    #[test]
    fn a_verification_of_the_same_run_setup_is_accepted() {
        let run = run_json();
        verification(Some(matching_verify()), None)
            .check_against(&run)
            .unwrap();
        let converge = serde_json::json!({
            "input_sha256": "ab".repeat(32), "knee_form_mm": [200.0, 60.0, 120.0],
            "pitches_mm": [4.96, 2.48, 1.24], "eps_mm": 0.001
        });
        verification(None, Some(converge))
            .check_against(&run)
            .unwrap();
    }

    #[test]
    fn every_kind_of_mismatch_is_refused_with_its_reason() {
        let run = run_json();
        let refused = |change: &dyn Fn(&mut Value)| -> String {
            let mut v = matching_verify();
            change(&mut v);
            let err = verification(Some(v), None).check_against(&run).unwrap_err();
            let text = err.to_string();
            assert!(!text.contains('\n'), "{text}");
            text
        };
        assert!(refused(&|v| v["input_sha256"] = "cd".repeat(32).into()).contains("another part"));
        assert!(
            refused(&|v| {
                v.as_object_mut().unwrap().remove("input_sha256");
            })
            .contains("SHA-256")
        );
        assert!(refused(&|v| v["scale"] = 1000.0.into()).contains("scale"));
        assert!(refused(&|v| v["side"] = "right".into()).contains("side"));
        let turned = serde_json::json!({"given": "x,-z,y", "part_to_vehicle":
            [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0]]});
        assert!(refused(&|v| v["frame"] = turned.clone()).contains("frame"));
        // The same frame on both sides is the same setup.
        let mut framed_run = run.clone();
        framed_run["frame"] = turned.clone();
        let mut framed = matching_verify();
        framed["frame"] = turned;
        verification(Some(framed.clone()), None)
            .check_against(&framed_run)
            .unwrap();
        // A run without the frame is another setup.
        assert!(
            verification(Some(framed), None)
                .check_against(&run)
                .is_err()
        );
        // An assembly's run matches no verification of one file.
        let mut assembly = run.clone();
        assembly["files"] = serde_json::json!([{}, {}]);
        let err = verification(Some(matching_verify()), None)
            .check_against(&assembly)
            .unwrap_err();
        assert!(err.to_string().contains("assembly of 2 files"), "{err}");
        assert!(refused(&|v| v["knee_form_mm"][0] = 190.0.into()).contains("knee-form"));
        assert!(refused(&|v| v["pitch_mm"] = 2.0.into()).contains("pitch"));
        assert!(refused(&|v| v["eps_mm"] = 0.01.into()).contains("eps_mm"));
        // A different rule altogether (the deflection rule's keys).
        let text = refused(&|v| {
            v.as_object_mut().unwrap().remove("eps_mm");
            v["deflection_deg"] = 0.5.into();
        });
        assert!(
            text.contains("deflection_deg") && text.contains("eps_mm"),
            "{text}"
        );
        // A ladder without the run's pitch.
        let converge = serde_json::json!({
            "input_sha256": "ab".repeat(32), "pitches_mm": [8.0, 4.0, 2.0, 1.0], "eps_mm": 0.001
        });
        let err = verification(None, Some(converge))
            .check_against(&run)
            .unwrap_err();
        assert!(err.to_string().contains("pitch ladder"), "{err}");
    }

    #[test]
    fn scalars_walk_objects_and_keep_number_arrays_whole() {
        let v: Value = serde_json::from_str(
            r#"{"b": 1, "a/x": {"c": true, "d": [1, 2]}, "e": [{"f": "g"}], "n": null}"#,
        )
        .unwrap();
        let mut got: Vec<(String, String)> = scalars(&v, "", "")
            .into_iter()
            .map(|(l, p, _)| (l, p))
            .collect();
        got.sort();
        let want = [
            ("a/x.c", "/a~1x/c"),
            ("a/x.d", "/a~1x/d"),
            ("b", "/b"),
            ("e[0].f", "/e/0/f"),
        ];
        assert_eq!(got, want.map(|(l, p)| (l.to_string(), p.to_string())));
        for (_, p, value) in scalars(&v, "", "") {
            assert_eq!(v.pointer(&p), Some(value));
        }
    }
}
