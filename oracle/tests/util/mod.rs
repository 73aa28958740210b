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
