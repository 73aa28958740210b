//! Benchmark of the exact oracle on a console-like part.
//!
//! Builds a ~400k-triangle height field itself (1500 x 600 mm, waves and
//! bumps, facing -y), then pushes and slides a sample of starts at a few
//! angles, single-threaded and with 2 rayon threads, and prints shape casts
//! per second and time per start (push + full slide trace).
//!
//! Run: `cargo run --release -p kneeform-oracle --example oracle_bench`

use std::time::Instant;

use kneeform_oracle::{OracleOptions, Part, StartStatus, StartTrace, evaluate};

/// Cells along x and z: 2 * 707 * 283 = 400,162 triangles, ~2.1 mm cells.
const NX: usize = 707;
const NZ: usize = 283;
const SIZE_X: f64 = 1500.0;
const SIZE_Z: f64 = 600.0;

/// The console side: a gentle bulge, waves along x and z, and a few round
/// bosses sticking out towards the knee (towards -y).
fn surface(x: f64, z: f64) -> f64 {
    use std::f64::consts::TAU;
    let bulge = 0.00002 * (x - 750.0).powi(2) + 0.00005 * (z - 300.0).powi(2);
    let waves = 4.0 * (TAU * x / 180.0).sin() * (TAU * z / 260.0).cos();
    let bosses = [
        (300.0, 200.0, 40.0, 12.0),
        (800.0, 420.0, 60.0, 18.0),
        (1200.0, 250.0, 35.0, 9.0),
    ]
    .iter()
    .map(|&(bx, bz, r, h): &(f64, f64, f64, f64)| {
        let d2 = ((x - bx).powi(2) + (z - bz).powi(2)) / (r * r);
        h * (-d2).exp()
    })
    .sum::<f64>();
    bulge + waves - bosses
}

fn console() -> Vec<[[f64; 3]; 3]> {
    let p = |i: usize, j: usize| {
        let (x, z) = (SIZE_X * i as f64 / NX as f64, SIZE_Z * j as f64 / NZ as f64);
        [x, surface(x, z), z]
    };
    let mut out = Vec::with_capacity(2 * NX * NZ);
    for i in 0..NX {
        for j in 0..NZ {
            out.push([p(i, j), p(i + 1, j), p(i, j + 1)]);
            out.push([p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    out
}

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
    let triangles = console();
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
}
