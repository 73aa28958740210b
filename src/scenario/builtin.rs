//! The built-in scenarios: every file of `scenarios/`, embedded in the
//! binary so that `kneeform scenario NAME` works from any directory. A
//! built-in's name is its file's stem, and the file is its only
//! definition.

use std::path::Path;

use super::file::{ScenarioFile, parse};

/// The paper's console side in triangles (Inui, Gunji and Umezu): the
/// benchmark part is the built-in `console` refined to at least this many,
/// in `kneeform bench` and in the oracle's benchmark alike.
pub const PAPER_TRIANGLES: usize = 369_408;

/// `(stem, text)` of each named file of `scenarios/`.
macro_rules! embedded {
    ($($stem:literal),* $(,)?) => {
        [$(($stem, include_str!(concat!("../../scenarios/", $stem, ".toml")))),*]
    };
}

/// The scenario files, sorted by stem; a test checks that these are all
/// the `.toml` files of `scenarios/`.
const BUILTINS: [(&str, &str); 15] = embedded![
    "angled-features",
    "bump",
    "console",
    "depression",
    "flat-wall",
    "groove",
    "growing-wave",
    "pocket-behind-ridge",
    "ramp",
    "step",
    "switch-boss",
    "thin-rib",
    "tilted-wave",
    "wave",
    "wavy-ridge",
];

/// The built-in scenarios' names, the stems of `scenarios/*.toml`, sorted.
pub fn builtin_names() -> impl Iterator<Item = &'static str> {
    BUILTINS.iter().map(|&(stem, _)| stem)
}

/// The built-in scenario `name` (see [`builtin_names`]), parsed and
/// checked as [`super::load`] would read `scenarios/NAME.toml`; `None` for
/// any other name.
///
/// # Panics
///
/// Never for a built-in name: a test parses every one.
pub fn builtin(name: &str) -> Option<ScenarioFile> {
    let &(stem, text) = BUILTINS.iter().find(|&&(stem, _)| stem == name)?;
    let path = Path::new("scenarios").join(format!("{stem}.toml"));
    Some(parse(text, &path).unwrap_or_else(|e| panic!("built-in scenario: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtins_are_the_scenario_files() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
        let mut on_disk: Vec<(String, String)> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| super::super::file::is_scenario_file(p))
            .map(|p| {
                let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
                (stem, std::fs::read_to_string(&p).unwrap())
            })
            .collect();
        on_disk.sort();
        let embedded: Vec<(String, String)> = BUILTINS
            .iter()
            .map(|&(s, t)| (s.to_owned(), t.to_owned()))
            .collect();
        assert_eq!(embedded, on_disk);
        for name in builtin_names() {
            let from_disk = super::super::file::load(&Path::new(dir).join(format!("{name}.toml")));
            assert_eq!(builtin(name), Some(from_disk.unwrap()), "{name}");
        }
        assert_eq!(builtin("no-such-part"), None);
        assert_eq!(builtin("wave.toml"), None);
    }
}
