//! `kneeform diff RUN_A RUN_B --out DIR`: two revisions of a part compared
//! on A's grid ([`kneeform::report::diff_runs`]), written whole or not at
//! all, with the zones that changed on stderr.

use anyhow::Context;
use kneeform::report::{NodeState, ZoneChange, diff_runs, write_diff};

use super::args::DiffArgs;

/// Zone groups listed on stderr (all of them in diff_zones.csv).
const SHOWN: usize = 8;

pub fn run(args: &DiffArgs) -> anyhow::Result<()> {
    let inputs = [args.run_a.as_path(), args.run_b.as_path()];
    let out = super::stage_output(&args.out, args.force, &inputs)?;
    let diff = diff_runs(&args.run_a, &args.run_b).context("cannot compare the runs")?;
    write_diff(out.path(".").as_path(), &diff)?;
    out.commit()
        .with_context(|| format!("cannot move results into {}", args.out.display()))?;
    let cell = diff.cell_mm2();
    super::print_result(&format!("kneeform: {}", diff.mapping));
    super::print_result(&format!(
        "kneeform: struck only in A {:.0} mm^2, only in B {:.0} mm^2, in both {:.0} mm^2; results in {}",
        diff.count(NodeState::OnlyA) as f64 * cell,
        diff.count(NodeState::OnlyB) as f64 * cell,
        diff.count(NodeState::Both) as f64 * cell,
        args.out.display()
    ));
    let changed: Vec<_> = diff
        .zones
        .iter()
        .filter(|z| z.change != ZoneChange::Unchanged)
        .collect();
    if changed.is_empty() {
        super::print_result("kneeform: no struck zone changed");
    }
    for z in changed.iter().take(SHOWN) {
        let word = match z.change {
            ZoneChange::Appeared => "appeared",
            ZoneChange::Vanished => "vanished",
            ZoneChange::Grew => "grew",
            ZoneChange::Shrank => "shrank",
            ZoneChange::Unchanged => "unchanged",
        };
        super::print_result(&format!(
            "kneeform:   {word}: {:+.0} mm^2 ({:.0} -> {:.0}) around x = {:.1}, z = {:.1} mm (A's zones {:?}, B's {:?})",
            z.change_mm2,
            z.area_a_mm2,
            z.area_b_mm2,
            z.centroid_xz[0],
            z.centroid_xz[1],
            z.a_zones,
            z.b_zones
        ));
    }
    if changed.len() > SHOWN {
        super::print_result(&format!(
            "kneeform:   ... and {} more (diff_zones.csv)",
            changed.len() - SHOWN
        ));
    }
    Ok(())
}
