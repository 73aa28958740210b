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

/// One flag of an argument list and its value, as written (`--pitch=2`,
/// or `--pitch` and `2`), or a lone argument (a part path), whose name
/// is empty.
struct Group<'a> {
    name: &'a str,
    tokens: &'a [String],
}

/// `args` cut into flags with their values. `is_switch` says which flags
/// take no value; any other `--flag` takes the next argument unless that
/// is a flag itself (`--x=v` carries its own).
fn groups<'a>(args: &'a [String], is_switch: &dyn Fn(&str) -> bool) -> Vec<Group<'a>> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < args.len() {
        let a = args[k].as_str();
        let (name, len) = match a.split_once('=') {
            _ if !a.starts_with("--") => ("", 1),
            Some((name, _)) => (name, 1),
            None if is_switch(a) => (a, 1),
            None => {
                let has_value = args.get(k + 1).is_some_and(|v| !v.starts_with("--"));
                (a, 1 + usize::from(has_value))
            }
        };
        out.push(Group {
            name,
            tokens: &args[k..k + len],
        });
        k += len;
    }
    out
}

impl Flags {
    /// Appends the flags of `item` over `defaults`: a flag the item sets,
    /// by name (`pitch`, `angles`, `side`) or in its `args`, replaces the
    /// defaults' (a flag given twice failed the item); the defaults'
    /// `args` come before the item's.
    fn push_onto(
        defaults: &Flags,
        item: &Flags,
        is_switch: &dyn Fn(&str) -> bool,
        argv: &mut Vec<String>,
    ) {
        let own = groups(&item.args, is_switch);
        // Whether the item sets `name`, by name or in its `args`.
        let set_by_item = |name: &str| {
            own.iter().any(|g| g.name == name)
                || match name {
                    "--pitch" => item.pitch.is_some(),
                    "--angles" => item.angles.is_some(),
                    "--side" => item.side.is_some(),
                    _ => false,
                }
        };
        // `--flag=value`: a value such as -1 is the flag's, not another
        // flag (clap printed its usage for `pitch = -1`).
        let named = |flag: &str, mine: Option<String>, theirs: Option<String>| {
            mine.or(theirs.filter(|_| !set_by_item(flag)))
                .map(|v| format!("{flag}={v}"))
        };
        argv.extend(named(
            "--pitch",
            item.pitch.map(|p| p.to_string()),
            defaults.pitch.map(|p| p.to_string()),
        ));
        argv.extend(named(
            "--angles",
            item.angles.clone(),
            defaults.angles.clone(),
        ));
        argv.extend(named("--side", item.side.clone(), defaults.side.clone()));
        for g in groups(&defaults.args, is_switch) {
            if g.name.is_empty() || !set_by_item(g.name) {
                argv.extend(g.tokens.iter().cloned());
            }
        }
        argv.extend(item.args.iter().cloned());
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
///
/// `is_switch` says which `analyze` flags take no value (`--report`), so
/// that a flag the item sets replaces the defaults' with its value.
pub fn plan(
    text: &str,
    base: &Path,
    is_switch: &dyn Fn(&str) -> bool,
) -> Result<Vec<BatchItem>, String> {
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
        Flags::push_onto(&manifest.defaults, &item.flags, is_switch, &mut argv);
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

    fn switch(flag: &str) -> bool {
        matches!(flag, "--report" | "--force" | "--points-csv")
    }

    #[test]
    fn items_take_their_own_flags_over_the_defaults() {
        let text = "[defaults]\npitch = 2\nargs = [\"--report\"]\n\n\
                    [[item]]\npart = \"a.stl\"\nout = \"a\"\n\n\
                    [[item]]\npart = [\"b.stl\", \"c.stl\"]\nout = \"bc\"\npitch = -1\nargs = [\"--side\", \"right\"]\n";
        let items = plan(text, Path::new("/nonexistent"), &switch).unwrap();
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

    /// Issue 24, item 12: `[defaults] args` were appended to an item's
    /// own, so a flag in both failed the item. The item's value wins,
    /// whichever way either gives it.
    #[test]
    fn an_item_s_own_flag_replaces_the_defaults() {
        let text = "[defaults]\npitch = 2\nargs = [\"--deflection\", \"0.5\", \"--report\", \"--window=4\", \"--angles\", \"0\", \"extra.stl\"]\n\n\
                    [[item]]\npart = \"a.stl\"\nout = \"a\"\nangles = \"-30:30:10\"\nargs = [\"--deflection\", \"3\", \"--window\", \"2\", \"--pitch=1\"]\n\n\
                    [[item]]\npart = \"b.stl\"\nout = \"b\"\nargs = [\"--report\"]\n";
        let items = plan(text, Path::new("/nonexistent"), &switch).unwrap();
        assert_eq!(
            items[0].argv,
            [
                "analyze",
                "a.stl",
                "--out",
                "a",
                "--angles=-30:30:10",
                "--report",
                "extra.stl",
                "--deflection",
                "3",
                "--window",
                "2",
                "--pitch=1"
            ]
        );
        assert_eq!(
            items[1].argv,
            [
                "analyze",
                "b.stl",
                "--out",
                "b",
                "--pitch=2",
                "--deflection",
                "0.5",
                "--window=4",
                "--angles",
                "0",
                "extra.stl",
                "--report"
            ]
        );
    }

    #[test]
    fn one_output_directory_two_ways_is_refused() {
        let text = "[[item]]\npart = \"a.stl\"\nout = \"dd/x\"\n\n\
                    [[item]]\npart = \"b.stl\"\nout = \"./dd/y/../x\"\n";
        let e = plan(text, Path::new("/nonexistent"), &switch).unwrap_err();
        assert!(e.contains("item 2 writes to ./dd/y/../x"), "{e}");
    }

    #[test]
    fn empty_manifests_and_parts_are_refused() {
        assert!(
            plan("", Path::new("."), &switch)
                .unwrap_err()
                .contains("no [[item]]")
        );
        let e = plan(
            "[[item]]\npart = []\nout = \"x\"\n",
            Path::new("."),
            &switch,
        )
        .unwrap_err();
        assert!(e.contains("no part"), "{e}");
        assert!(plan("[[item]]\nout = 1\n", Path::new("."), &switch).is_err());
    }
}
