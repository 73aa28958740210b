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

use super::ReportError;

/// The figures a verification directory may hold, in the order shown.
pub const VERIFY_FIGURES: [&str; 2] = ["error_vs_pitch.png", "time_vs_pitch.png"];

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

/// The verdict of a `verify` run against its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The file says the run passed.
    Pass,
    /// The file says the run failed.
    Fail,
    /// The file gives no verdict.
    Unknown,
}

impl Verification {
    /// Reads `dir`; at least one of `verify.json` and `converge.json` must
    /// be there.
    pub fn read(dir: &Path) -> Result<Verification, ReportError> {
        let json = |name: &str| -> Result<Option<Value>, ReportError> {
            let path = dir.join(name);
            match optional_text(&path)? {
                None => Ok(None),
                Some(text) => serde_json::from_str(&text)
                    .map(Some)
                    .map_err(|source| ReportError::Json { path, source }),
            }
        };
        let v = Verification {
            dir: dir.to_path_buf(),
            verify: json("verify.json")?,
            verify_csv: optional_text(&dir.join("verify.csv"))?,
            converge: json("converge.json")?,
            converge_csv: optional_text(&dir.join("converge.csv"))?,
            figures: VERIFY_FIGURES
                .iter()
                .filter_map(|name| {
                    std::fs::read(dir.join(name))
                        .ok()
                        .map(|bytes| (name.to_string(), bytes))
                })
                .collect(),
        };
        if v.verify.is_none() && v.converge.is_none() {
            return Err(ReportError::NotAVerification {
                dir: dir.to_path_buf(),
            });
        }
        Ok(v)
    }

    /// The `pass` field of `verify.json`.
    pub fn verdict(&self) -> Verdict {
        match self.verify.as_ref().and_then(|v| v.get("pass")) {
            Some(Value::Bool(true)) => Verdict::Pass,
            Some(Value::Bool(false)) => Verdict::Fail,
            _ => Verdict::Unknown,
        }
    }
}

fn optional_text(path: &Path) -> Result<Option<String>, ReportError> {
    match std::fs::read_to_string(path) {
        Ok(text) => Ok(Some(text)),
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
pub fn scalars<'a>(
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
pub fn escape_pointer(key: &str) -> String {
    key.replace('~', "~0").replace('/', "~1")
}

#[cfg(test)]
mod tests {
    use super::*;

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
