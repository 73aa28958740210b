//! Benchmark of the exact oracle on the benchmark console side.
//!
//! Builds the same part as `kneeform bench`: the built-in console
//! (`scenarios/console.toml`, 1500 x 600 mm: a bulge, waves, a wavy ridge,
//! switch-like bosses, a dip behind a protrusion, a thin rib, a groove and
//! a diagonal ridge, facing -y) refined to the paper's 369,408+ triangles,
//! then pushes and slides a sample of starts at a few angles,
//! single-threaded and with 2 rayon threads, and prints shape casts per
//! second and time per start (push + full slide trace); then a row of
//! consecutive starts, each alone and chained along the row.
//!
//! Run: `cargo run --release -p kneeform-oracle --example oracle_bench`

use std::time::Instant;

use kneeform::scenario::{PAPER_TRIANGLES, builtin};
use kneeform_oracle::{Chain, OracleOptions, Part, StartStatus, StartTrace, evaluate};

fn run(part: &Part, starts: &[[f64; 2]], angles: &[f64], options: &OracleOptions, threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let clock = Instant::now();
    let traces: Vec<StartTrace> = pool
        .install(|| evaluate(part, starts, angles, options))
        .unwrap();
    let seconds = clock.elapsed().as_secs_f64();
    let casts: usize = traces.iter().map(|t| t.casts).sum();
    let contacts: usize = traces.iter().map(|t| t.contacts.len()).sum();
    let count = |f: fn(&StartStatus) -> bool| traces.iter().filter(|t| f(&t.status)).count();
    println!(
        "threads {threads}: {} starts ({} placed, {} not placed, {} failed), {casts} casts, {contacts} contacts, {seconds:.2} s",
        traces.len(),
        count(|s| *s == StartStatus::Placed),
        count(|s| *s == StartStatus::NotPlaced),
        count(|s| matches!(s, StartStatus::Failed { .. })),
    );
    println!(
        "  {:.0} casts/s, {:.1} ms per start (wall), {:.1} casts per start",
        casts as f64 / seconds,
        1e3 * seconds / traces.len() as f64,
        casts as f64 / traces.len() as f64,
    );
    // Strikes at SPEC's default threshold, and the contacts whose stated
    // rate error leaves them on either side of it.
    let sigma = 0.5f64.to_radians().tan();
    let strikes: usize = traces
        .iter()
        .filter_map(|t| t.strikes(sigma).ok())
        .map(Iterator::count)
        .sum();
    let undecided = traces
        .iter()
        .flat_map(|t| &t.contacts)
        .filter(|c| (c.rate - sigma).abs() <= c.rate_error)
        .count();
    println!(
        "  strikes at 0.5 degrees: {strikes}, contacts within their rate error of it: {undecided}"
    );
}

fn main() {
    let clock = Instant::now();
    let console = builtin("console").expect("the console is a built-in scenario");
    let triangles: Vec<[[f64; 3]; 3]> = console.triangulate(Some(PAPER_TRIANGLES));
    let part = Part::from_triangles(&triangles).expect("the console builds");
    let (mins, maxs) = part.bounds();
    println!(
        "part: {} triangles, x {:.0}..{:.0}, y {:.1}..{:.1}, z {:.0}..{:.0} mm, built in {:.2} s",
        part.triangle_count(),
        mins[0],
        maxs[0],
        mins[1],
        maxs[1],
        mins[2],
        maxs[2],
        clock.elapsed().as_secs_f64()
    );
    // The paper's pitch is 1.24 mm: bisect to a tenth of it, and end the
    // slides at the part's -x edge.
    let options = OracleOptions {
        witness_tolerance: 0.124,
        x_min: mins[0],
        ..OracleOptions::default()
    };
    println!("options: {options:?}");
    // 8 x 4 starts spread over the part, at 3 angles.
    let starts: Vec<[f64; 2]> = (0..8)
        .flat_map(|i| (0..4).map(move |j| [100.0 + 180.0 * i as f64, 75.0 + 150.0 * j as f64]))
        .collect();
    let angles = [-30.0, 0.0, 30.0];
    for threads in [1, 2] {
        run(&part, &starts, &angles, &options, threads);
    }
    // A row of 128 consecutive grid starts (1.24 mm apart, z = 300.08 mm,
    // a strip's row) at 4 angles: each start alone, then chained along
    // the row in blocks of 64 (`verify --starts strip:...`).
    let pitch = 1.24;
    let row: Vec<[f64; 2]> = (0..128)
        .map(|k| [pitch * (480 + k) as f64, pitch * 242.0])
        .collect();
    let angles = [-13.0, 0.0, 9.0, 30.0];
    let chained = OracleOptions {
        chain: Some(Chain { pitch, block: 64 }),
        ..options
    };
    println!("a row of {} starts x {} angles:", row.len(), angles.len());
    for (what, options) in [("alone", &options), ("chained", &chained)] {
        print!("  {what}: ");
        run(&part, &row, &angles, options, 2);
    }
}
