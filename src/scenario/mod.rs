//! Synthetic height-field parts with known geometry: the scenario library
//! for tests, convergence studies and the benchmark.
//!
//! Each part is a surface `y = g(x, z)` in SPEC's analysis frame (mm): the
//! surface faces -y, the knee comes from -y, is pushed in +y and slides in
//! -x (towards the vehicle front). So a feature that **sticks out towards
//! the knee has a smaller y**.
//!
//! The scenario files are the only definition of the parts: the library in
//! `scenarios/*.toml`, one part per file, each a sum of named `Feature`
//! primitives (plane, wave, bump, boss, ridge, groove, rib, step, console)
//! over an [`Extent`] with its tessellation step and a one-line
//! description. This module offers:
//!
//! * [`load`] and [`parse`]: a file read and checked into a
//!   [`ScenarioFile`], whose [`ScenarioFile::height`] is the surface's
//!   closed form and [`ScenarioFile::triangulate`] its mesh;
//! * [`builtin`]: the same files embedded in the binary, by stem
//!   ([`builtin_names`]: `wave`, `thin-rib`, `console`, ...), for
//!   `kneeform scenario NAME`, the tests and the benchmark (the built-in
//!   `console` at [`PAPER_TRIANGLES`]);
//! * [`tessellate`]: the one height-field tessellation, two triangles per
//!   lattice cell facing -y; the files use it on a square lattice with
//!   vertex lines at their creases (so thin features are in the mesh at
//!   any step), and the tests and the oracle's tests and examples on
//!   lattices of their own.
//!
//! A scenario's mesh is written as a binary STL by
//! [`crate::output::write_stl`], which the CLI reads like any other part.

mod builtin;
mod console;
mod file;
mod lattice;
mod primitive;

#[cfg(test)]
mod library_tests;

pub use builtin::{PAPER_TRIANGLES, builtin, builtin_names};
pub use file::ScenarioError;
pub use file::{Extent, ScenarioFile, is_scenario_file, load, parse};
#[cfg(test)]
pub(crate) use lattice::axis;
pub use lattice::{MAX_TRIANGLES, tessellate};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::write_stl;

    #[test]
    fn stl_round_trips() {
        let dir = crate::output::temp_dir("scenario");
        let path = dir.join("bump.stl");
        let bump = ScenarioFile {
            extent: Extent {
                x: [-300.0, 300.0],
                z: [-20.0, 20.0],
                step: 5.0,
            },
            ..builtin("bump").unwrap()
        };
        let tris = bump.triangulate(None);
        write_stl(&path, &tris).unwrap();
        // Only the final file remains.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let mut file = std::fs::File::open(&path).unwrap();
        let back: Vec<stl_io::Triangle> = stl_io::create_stl_reader(&mut file)
            .unwrap()
            .map(Result::unwrap)
            .collect();
        assert_eq!(back.len(), tris.len());
        for (b, t) in back.iter().zip(&tris) {
            for (bv, tv) in b.vertices.iter().zip(t) {
                for k in 0..3 {
                    // STL stores f32.
                    assert!((f64::from(bv[k]) - tv[k]).abs() <= 1e-5 * tv[k].abs().max(1.0));
                }
            }
            assert!(b.normal[1] < 0.0);
        }
        std::fs::remove_dir_all(dir).unwrap();
    }
}
