//! The library's imports, as ARCHITECTURE.md states them (issue 23): no
//! module imports a circle of modules, and every import between the
//! top-level modules points to the same floor or down.
//!
//! What counts as an import, read from the text of `src/` (a file is a
//! module: `mod.rs`, `lib.rs` and `main.rs` name their directory's): every
//! `use crate::…`, `use super::…` and `use self::…` that is not `pub`
//! (a re-export is the parent's own surface, not a dependency of it), and
//! every `crate::…::` and `super::…::` path in the code, each resolved to
//! the longest module it names. Comments and inline test modules
//! (`#[cfg(test)] mod tests { … }`, to the end of the file) are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The floors of ARCHITECTURE.md's code map, lowest first: a top-level
/// module imports from its own floor or below. (The crate root sits above
/// them all.)
const FLOORS: [&[&str]; 11] = [
    &["limits", "strike", "zbuffer", "frame", "mesh", "partition"],
    &["grid"],
    &["kneeform"],
    &["surface"],
    &["engine", "direct", "memory", "blind"],
    &["scenario", "input", "assembly", "sanity", "setup", "zones"],
    &["summary", "analysis"],
    &["harness"],
    &["output"],
    &["shard", "report"],
    &["manifest"],
];

/// Every `.rs` file under `dir`, by its path relative to `dir` (with `/`).
fn sources(dir: &Path) -> BTreeMap<String, String> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).unwrap().to_string_lossy();
                let text = std::fs::read_to_string(&path).unwrap();
                out.insert(rel.replace('\\', "/"), text);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The module path of the file `rel` (`harness/mod.rs`: `harness`).
fn module_of(rel: &str) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .trim_end_matches(".rs")
        .split('/')
        .map(String::from)
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// `text` without comments and without an inline test module and what
/// follows it.
fn code_of(text: &str) -> String {
    let mut code = String::new();
    let mut test_attribute = false;
    for line in text.lines() {
        let t = line.trim();
        if test_attribute && t.starts_with("mod ") && t.ends_with('{') {
            break;
        }
        test_attribute = t == "#[cfg(test)]";
        if !t.starts_with("//") {
            code.push_str(line);
            code.push('\n');
        }
    }
    code
}

/// The paths a `use` tree names: `a::{b, c::{d, e}}` gives `a::b`,
/// `a::c::d`, `a::c::e`.
fn use_paths(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else {
        return vec![tree];
    };
    let (prefix, rest) = (&tree[..open], &tree[open + 1..tree.len() - 1]);
    let (mut items, mut depth, mut start) = (Vec::new(), 0, 0);
    for (k, c) in rest.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&rest[start..k]);
                start = k + 1;
            }
            _ => {}
        }
    }
    items.push(&rest[start..]);
    items
        .into_iter()
        .filter(|i| !i.is_empty())
        .flat_map(|i| use_paths(&format!("{prefix}{i}")))
        .collect()
}

/// The module path a path written in module `me` names (`crate::`,
/// `super::`, `self::`; `None` for another crate's).
fn absolute(me: &[String], path: &str) -> Option<Vec<String>> {
    let segments: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let (mut base, rest) = match *segments.first()? {
        "crate" => (Vec::new(), &segments[1..]),
        "self" => (me.to_vec(), &segments[1..]),
        "super" => {
            let up = segments.iter().take_while(|s| **s == "super").count();
            (me[..me.len().checked_sub(up)?].to_vec(), &segments[up..])
        }
        _ => return None,
    };
    base.extend(rest.iter().map(|s| s.to_string()));
    Some(base)
}

/// Per file, the files it imports from (itself left out).
fn imports(files: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
    let modules: BTreeMap<Vec<String>, &String> =
        files.keys().map(|rel| (module_of(rel), rel)).collect();
    // The longest module a path names.
    let file_of = |path: &[String]| {
        (0..=path.len())
            .rev()
            .find_map(|n| modules.get(&path[..n]).copied())
    };
    let mut graph = BTreeMap::new();
    for (rel, text) in files {
        let me = module_of(rel);
        // A module's children, which its paths may name without `self::`.
        let children: Vec<&String> = modules
            .keys()
            .filter(|m| m.len() == me.len() + 1 && m.starts_with(&me))
            .map(|m| &m[me.len()])
            .collect();
        let relative = |path: &str| match children
            .iter()
            .find(|c| path.starts_with(&format!("{c}::")))
        {
            Some(_) => format!("self::{path}"),
            None => path.to_string(),
        };
        let code = code_of(text);
        let mut paths = Vec::new();
        for statement in code.split(';') {
            // A `use` item: a line of the statement that starts with `use`,
            // after its visibility.
            let item = statement.lines().map(str::trim).find(|l| {
                let rest = l
                    .strip_prefix("pub")
                    .map_or(*l, |r| match r.strip_prefix('(') {
                        Some(r) => r.split_once(')').map_or(r, |(_, after)| after),
                        None => r,
                    });
                rest.trim_start().starts_with("use ")
            });
            if let Some(line) = item {
                if !line.starts_with("pub") {
                    let tree = &statement
                        [statement.find(line).unwrap() + line.find("use ").unwrap() + 4..];
                    paths.extend(use_paths(tree).iter().map(|p| relative(p)));
                }
                continue;
            }
            let s = statement;
            // Paths in the code itself: `crate::a::b::c(` names `a::b`;
            // `child::f(` a child module.
            let starts = ["crate::".to_string(), "super::".to_string()];
            let child_starts = children.iter().map(|c| format!("{c}::"));
            for start in starts.into_iter().chain(child_starts) {
                for (k, _) in s.match_indices(&start) {
                    let before = s[..k].chars().last();
                    if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                        continue;
                    }
                    let path: String = s[k..]
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                        .collect();
                    paths.push(relative(&path));
                }
            }
        }
        let targets: BTreeSet<String> = paths
            .iter()
            .filter_map(|p| absolute(&me, p))
            .filter_map(|p| file_of(&p))
            .filter(|f| *f != rel)
            .cloned()
            .collect();
        graph.insert(rel.clone(), targets);
    }
    graph
}

/// The circles of `graph`: its strongly connected components of more
/// than one file (Tarjan's algorithm), each sorted.
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct Walk<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, (usize, usize)>,
        stack: Vec<&'a str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(w: &mut Walk<'a>, v: &'a str) {
        w.index.insert(v, (w.next, w.next));
        w.next += 1;
        w.stack.push(v);
        for u in w.graph.get(v).into_iter().flatten() {
            let u = u.as_str();
            if !w.index.contains_key(u) {
                visit(w, u);
                let low = w.index[u].1.min(w.index[v].1);
                w.index.get_mut(v).unwrap().1 = low;
            } else if w.stack.contains(&u) {
                let low = w.index[u].0.min(w.index[v].1);
                w.index.get_mut(v).unwrap().1 = low;
            }
        }
        if w.index[v].0 == w.index[v].1 {
            let at = w.stack.iter().rposition(|&s| s == v).unwrap();
            let mut component: Vec<String> = w.stack.drain(at..).map(String::from).collect();
            if component.len() > 1 {
                component.sort();
                w.out.push(component);
            }
        }
    }
    let mut walk = Walk {
        graph,
        index: BTreeMap::new(),
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !walk.index.contains_key(v.as_str()) {
            visit(&mut walk, v);
        }
    }
    walk.out
}

/// The imports of `graph` that run up a floor: (from, to).
fn climbs(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<(String, String)> {
    let floor = |rel: &str| {
        let top = module_of(rel).first().cloned().unwrap_or_default();
        FLOORS.iter().position(|f| f.contains(&top.as_str()))
    };
    let mut out = Vec::new();
    for (from, targets) in graph {
        for to in targets {
            if let (Some(a), Some(b)) = (floor(from), floor(to))
                && b > a
            {
                out.push((from.clone(), to.clone()));
            }
        }
    }
    out
}

/// The library's import graph: `src/` but the binary's files (`main.rs`
/// and `cli/`, whose `crate` is the binary).
fn library() -> BTreeMap<String, BTreeSet<String>> {
    let mut files = sources(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    files.retain(|rel, _| rel != "main.rs" && !rel.starts_with("cli/"));
    imports(&files)
}

#[test]
fn no_module_of_the_library_imports_a_circle() {
    let graph = library();
    assert!(graph.len() > 60, "read {} files", graph.len());
    assert_eq!(circles(&graph), Vec::<Vec<String>>::new());
}

#[test]
fn every_import_between_top_level_modules_points_to_its_floor_or_down() {
    let graph = library();
    let named: BTreeSet<String> = graph
        .keys()
        .filter_map(|rel| module_of(rel).first().cloned())
        .collect();
    for top in &named {
        assert!(
            FLOORS.iter().any(|f| f.contains(&top.as_str())),
            "{top} is on no floor: add it to FLOORS and ARCHITECTURE.md"
        );
    }
    assert_eq!(climbs(&graph), Vec::<(String, String)>::new());
}

#[test]
fn the_checks_find_a_circle_and_a_climb_and_count_no_reexport_comment_or_test() {
    let files: BTreeMap<String, String> = [
        ("lib.rs", "mod grid;\nmod limits;\n"),
        // grid -> limits::a and limits -> grid: a circle, and a climb.
        ("grid.rs", "use crate::limits::{a, b::{c}};\n"),
        (
            "limits.rs",
            "fn f() { crate::grid::g(); }\n// use crate::output::x;\n",
        ),
        // A re-export, a comment and a test module are no import; a
        // child's path in the code is.
        (
            "output/mod.rs",
            "mod csv;\nmod png;\npub use self::csv::w;\nfn f() { png::p(); }\n#[cfg(test)]\nmod tests {\n    use crate::limits::t;\n}\n",
        ),
        ("output/png.rs", "use std::fmt::Display;\n"),
        ("output/csv.rs", "use super::super::grid::h;\n"),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect();
    let graph = imports(&files);
    let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
    assert_eq!(graph["grid.rs"], set(&["limits.rs"]));
    assert_eq!(graph["limits.rs"], set(&["grid.rs"]));
    assert_eq!(graph["output/mod.rs"], set(&["output/png.rs"]));
    assert_eq!(graph["output/png.rs"], set(&[]));
    assert_eq!(graph["output/csv.rs"], set(&["grid.rs"]));
    assert_eq!(
        circles(&graph),
        vec![vec!["grid.rs".to_string(), "limits.rs".to_string()]]
    );
    assert_eq!(
        climbs(&graph),
        vec![("limits.rs".to_string(), "grid.rs".to_string())]
    );
}
