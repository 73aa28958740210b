//! `kneeform scenario`: writes a synthetic part as STL, from a scenario
//! file (`.toml`) or the name of one of `scenarios/`, built into the
//! binary.

use std::path::Path;

use anyhow::{Context, anyhow, bail};
use kneeform::scenario::{self, MAX_TRIANGLES, ScenarioFile};

use super::args::ScenarioArgs;

/// The scenario `part` names: a file when it ends in `.toml`, else a
/// built-in (a file stem of `scenarios/`).
fn resolve(part: &str) -> anyhow::Result<ScenarioFile> {
    let path = Path::new(part);
    if scenario::is_scenario_file(path) {
        return Ok(scenario::load(path)?);
    }
    scenario::builtin(part).ok_or_else(|| {
        let names: Vec<&str> = scenario::builtin_names().collect();
        anyhow!(
            "unknown scenario `{part}`: give a scenario file ending in .toml \
             or one of {}",
            names.join(", ")
        )
    })
}

pub fn run(args: &ScenarioArgs) -> anyhow::Result<()> {
    if let Some(n) = args.triangles
        && !(1..=MAX_TRIANGLES).contains(&n)
    {
        bail!("--triangles must be between 1 and {MAX_TRIANGLES}, got {n}");
    }
    let file = resolve(&args.part)?;
    let step = file.step_for(args.triangles);
    let triangles = file.triangulate(args.triangles);
    // What `analyze` would refuse is not written: no triangles (an extent
    // too small for one), non-finite or out-of-range heights.
    kneeform::input::check_triangles(&args.part, &triangles, 1.0)
        .context("the scenario makes no usable part")?;
    kneeform::output::write_stl(&args.out, &triangles)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    super::print_result(&format!(
        "kneeform: wrote {} triangles (step {step:.4} mm) to {}",
        triangles.len(),
        args.out.display()
    ));
    Ok(())
}
