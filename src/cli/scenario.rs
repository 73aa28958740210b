//! `kneeform scenario`: writes a synthetic part as STL.

use anyhow::Context;
use kneeform::scenario;

use super::args::ScenarioArgs;

pub fn run(args: &ScenarioArgs) -> anyhow::Result<()> {
    let field = args.name.default_field();
    let triangles = scenario::triangulate(args.name, &field);
    scenario::write_stl(&args.out, &triangles)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    eprintln!(
        "kneeform: wrote {} triangles to {}",
        triangles.len(),
        args.out.display()
    );
    Ok(())
}
