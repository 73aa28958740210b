//! Synthetic parts for the oracle's tests: height-field triangulations
//! `y = g(x, z)` whose surface faces -y (the analysis frame).

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

/// Triangulates the height field `y = g(i, j)` over the vertices
/// `(xs[i], zs[j])`, two triangles per cell, wound so that their normal is
/// -y (facing the knee-form).
pub fn height_field(xs: &[f64], zs: &[f64], g: impl Fn(usize, usize) -> f64) -> Vec<[[f64; 3]; 3]> {
    let p = |i: usize, j: usize| [xs[i], g(i, j), zs[j]];
    let mut out = Vec::new();
    for i in 0..xs.len() - 1 {
        for j in 0..zs.len() - 1 {
            out.push([p(i, j), p(i + 1, j), p(i, j + 1)]);
            out.push([p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    out
}
