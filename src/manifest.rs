//! A `kneeform batch` manifest read into the analyses it asks for: its
//! items checked (at least one, every item with a part, no two on one
//! output directory) and each turned into its `analyze` arguments. Pure
//! but for the resolving of output paths, so that the CLI and the fuzz
//! targets read a manifest the same way.

use std::path::{Component, Path, PathBuf};

use serde::Deserialize;

/// The manifest file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    /// Flags of every item: its own `pitch`, `angles` and `side` replace
    /// these, its `args` follow these.
    #[serde(default)]
    defaults: Flags,
    /// The analyses, in order.
    #[serde(default, rename = "item")]
    items: Vec<Item>,
}

/// `analyze` flags: a few by name, any others as written.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Flags {
    pitch: Option<f64>,
    angles: Option<String>,
    side: Option<String>,
    #[serde(default)]
    args: Vec<String>,
}

/// One analysis as the manifest writes it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Item {
    /// Its part file(s): one path, or several (an assembly).
    part: PartPaths,
    /// Its output directory.
    out: PathBuf,
    #[serde(flatten)]
    flags: Flags,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum PartPaths {
    One(PathBuf),
    Many(Vec<PathBuf>),
}

impl Flags {
    /// Appends the flags of `item` over `defaults`: its `pitch`, `angles`
    /// and `side` replace the defaults', its `args` follow theirs.
    fn push_onto(defaults: &Flags, item: &Flags, argv: &mut Vec<String>) {
        // `--flag=value`: a value such as -1 is the flag's, not another
        // flag (clap printed its usage for `pitch = -1`).
        if let Some(p) = item.pitch.or(defaults.pitch) {
            argv.push(format!("--pitch={p}"));
        }
        if let Some(a) = item.angles.as_ref().or(defaults.angles.as_ref()) {
            argv.push(format!("--angles={a}"));
        }
        if let Some(s) = item.side.as_ref().or(defaults.side.as_ref()) {
            argv.push(format!("--side={s}"));
        }
        argv.extend(defaults.args.iter().chain(&item.args).cloned());
    }
}

/// One analysis of a batch, ready to run in the manifest's directory.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchItem {
    /// Its part files, as the manifest names them (relative to its
    /// directory).
    pub parts: Vec<PathBuf>,
    /// Its output directory, as the manifest names it.
    pub out: PathBuf,
    /// The `kneeform` arguments of its run: `analyze`, the parts,
    /// `--out`, then the flags (its own over the defaults).
    pub argv: Vec<String>,
}

/// The analyses the manifest `text` asks for, in order; `base` is the
/// manifest's directory, against which output directories are compared.
/// The reason, in one line, when the manifest is not one: not TOML of the
/// manifest's keys, no item, an item without a part, two items on one
/// output directory (`dd/x` and `./dd/x` are one: they would replace
/// each other's result and both run again on every resume).
pub fn plan(text: &str, base: &Path) -> Result<Vec<BatchItem>, String> {
    let manifest: Manifest = toml::from_str(text).map_err(|e| e.message().to_string())?;
    if manifest.items.is_empty() {
        return Err("no [[item]]: each is one analysis (part, out, flags)".into());
    }
    let mut outs = std::collections::BTreeMap::new();
    let mut items = Vec::with_capacity(manifest.items.len());
    for (k, item) in manifest.items.iter().enumerate() {
        if let Some(earlier) = outs.insert(resolved(&base.join(&item.out)), k + 1) {
            return Err(format!(
                "item {} writes to {}, the directory item {earlier} writes to",
                k + 1,
                item.out.display()
            ));
        }
        let parts = match &item.part {
            PartPaths::One(p) => vec![p.clone()],
            PartPaths::Many(p) => p.clone(),
        };
        if parts.is_empty() {
            return Err(format!("item {} has no part (part = [])", k + 1));
        }
        let mut argv = vec!["analyze".to_string()];
        argv.extend(parts.iter().map(|p| p.display().to_string()));
        argv.extend(["--out".into(), item.out.display().to_string()]);
        Flags::push_onto(&manifest.defaults, &item.flags, &mut argv);
        items.push(BatchItem {
            parts,
            out: item.out.clone(),
            argv,
        });
    }
    Ok(items)
}

/// `path` made absolute and normal: `.` and `..` resolved, and the part
/// of it that exists followed through links (the rest kept as written).
fn resolved(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut normal = PathBuf::new();
    for c in absolute.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                normal.pop();
            }
            c => normal.push(c),
        }
    }
    // The longest existing ancestor, canonical, with the rest after it.
    let mut rest = Vec::new();
    let mut head = normal.as_path();
    loop {
        if let Ok(real) = head.canonicalize() {
            return rest.iter().rev().fold(real, |p, c| p.join(c));
        }
        match (head.file_name(), head.parent()) {
            (Some(name), Some(parent)) => {
                rest.push(name.to_os_string());
                head = parent;
            }
            _ => return normal,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_take_their_own_flags_over_the_defaults() {
        let text = "[defaults]\npitch = 2\nargs = [\"--report\"]\n\n\
                    [[item]]\npart = \"a.stl\"\nout = \"a\"\n\n\
                    [[item]]\npart = [\"b.stl\", \"c.stl\"]\nout = \"bc\"\npitch = -1\nargs = [\"--side\", \"right\"]\n";
        let items = plan(text, Path::new("/nonexistent")).unwrap();
        assert_eq!(
            items[0].argv,
            ["analyze", "a.stl", "--out", "a", "--pitch=2", "--report"]
        );
        assert_eq!(items[1].parts, [PathBuf::from("b.stl"), "c.stl".into()]);
        assert_eq!(
            items[1].argv,
            [
                "analyze",
                "b.stl",
                "c.stl",
                "--out",
                "bc",
                "--pitch=-1",
                "--report",
                "--side",
                "right"
            ]
        );
    }

    #[test]
    fn one_output_directory_two_ways_is_refused() {
        let text = "[[item]]\npart = \"a.stl\"\nout = \"dd/x\"\n\n\
                    [[item]]\npart = \"b.stl\"\nout = \"./dd/y/../x\"\n";
        let e = plan(text, Path::new("/nonexistent")).unwrap_err();
        assert!(e.contains("item 2 writes to ./dd/y/../x"), "{e}");
    }

    #[test]
    fn empty_manifests_and_parts_are_refused() {
        assert!(
            plan("", Path::new("."))
                .unwrap_err()
                .contains("no [[item]]")
        );
        let e = plan("[[item]]\npart = []\nout = \"x\"\n", Path::new(".")).unwrap_err();
        assert!(e.contains("no part"), "{e}");
        assert!(plan("[[item]]\nout = 1\n", Path::new(".")).is_err());
    }
}
