//! `kneeform scenario`: writes a synthetic part as STL, from a scenario
//! file (`scenarios/*.toml`) or a built-in name.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::ValueEnum;
use kneeform::scenario::{self, MAX_TRIANGLES, Scenario};

use super::args::ScenarioArgs;

/// Where the part comes from, resolved from the raw argument before any
/// work.
enum Source {
    File(PathBuf),
    Builtin(Scenario),
}

impl Source {
    fn parse(part: &str) -> anyhow::Result<Source> {
        let path = PathBuf::from(part);
        if scenario::is_scenario_file(&path) {
            return Ok(Source::File(path));
        }
        if let Ok(s) = Scenario::from_str(part, false) {
            return Ok(Source::Builtin(s));
        }
        let names: Vec<String> = Scenario::value_variants()
            .iter()
            .filter_map(|s| s.to_possible_value())
            .map(|v| v.get_name().to_owned())
            .collect();
        bail!(
            "unknown scenario `{part}`: give a scenario file ending in .toml \
             (see scenarios/) or one of {}",
            names.join(", ")
        )
    }
}

pub fn run(args: &ScenarioArgs) -> anyhow::Result<()> {
    let source = Source::parse(&args.part)?;
    if let Some(n) = args.triangles
        && !(1..=MAX_TRIANGLES).contains(&n)
    {
        bail!("--triangles must be between 1 and {MAX_TRIANGLES}, got {n}");
    }
    let (triangles, step) = match &source {
        Source::File(path) => {
            let file = scenario::load(path)?;
            let step = file.step_for(args.triangles);
            (file.triangulate(args.triangles), step)
        }
        Source::Builtin(s) => {
            let field = s.field_for(args.triangles);
            (scenario::triangulate(*s, &field), field.step)
        }
    };
    scenario::write_stl(&args.out, &triangles)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    eprintln!(
        "kneeform: wrote {} triangles (step {step:.4} mm) to {}",
        triangles.len(),
        args.out.display()
    );
    Ok(())
}
