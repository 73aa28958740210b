//! Synthetic parts for the oracle's tests: the lattices that the engine's
//! height-field tessellation, [`kneeform::scenario::tessellate`], turns
//! into parts `y = g(i, j)` whose surface faces -y (the analysis frame).
//! Test fixtures only: the oracle's own geometry shares nothing with the
//! engine.

#![allow(dead_code)]

/// `n >= 2` evenly spaced values from `a` to `b` inclusive.
pub fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

/// Concatenates coordinate runs, dropping a value equal to the previous
/// one (where two runs meet). To make a vertical riser, insert a repeated
/// x (or z) afterwards: `g` is called with the index, so it can give the
/// two copies different heights.
pub fn knots(runs: &[Vec<f64>]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for run in runs {
        for &v in run {
            if out.last() != Some(&v) {
                out.push(v);
            }
        }
    }
    out
}

/// The part in the STL file at `path`, scaled to about `size` mm on its
/// longest side (as a user's part), on `side`.
pub fn stl_at_size(
    path: &std::path::Path,
    size: f64,
    side: kneeform_oracle::Side,
) -> Result<kneeform_oracle::Part, kneeform_oracle::OracleError> {
    use kneeform_oracle::{Part, Side};
    let raw = Part::from_stl_path(path, 1.0, Side::Left)?;
    let (mins, maxs) = raw.bounds();
    let extent = (0..3).map(|k| maxs[k] - mins[k]).fold(0.0, f64::max);
    Part::from_stl_path(path, size / extent, side)
}

/// Starts at the centres of an `nx` x `nz` array of cells over the
/// part's xz-extent, row by row in x.
pub fn starts_over(part: &kneeform_oracle::Part, nx: usize, nz: usize) -> Vec<[f64; 2]> {
    let (mins, maxs) = part.bounds();
    (0..nx)
        .flat_map(|i| {
            (0..nz).map(move |j| {
                [
                    mins[0] + (maxs[0] - mins[0]) * (i as f64 + 0.5) / nx as f64,
                    mins[2] + (maxs[2] - mins[2]) * (j as f64 + 0.5) / nz as f64,
                ]
            })
        })
        .collect()
}
