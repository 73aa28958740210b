//! The part as a parry3d `TriMesh` in the analysis frame.
//!
//! The oracle reads STL itself (binary or ASCII, through `stl_io`) and
//! applies the same `scale` and `side` as the engine, so both can be run on
//! one file with the same flags. Vertices with bit-identical coordinates
//! (after scale and mirror) are merged; triangles that repeat a vertex or
//! have zero area are dropped and counted.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

use parry3d_f64::math::Vector;
use parry3d_f64::shape::TriMesh;
use serde::{Deserialize, Serialize};

use crate::OracleError;

/// Bytes parry's BVH takes per triangle while it is built: its wide nodes
/// (128 bytes a triangle in f64) twice over while it refits them, its
/// leaves (64) and their indices.
const BVH_BUILD_BYTES_PER_TRIANGLE: usize = 352;

/// Which side of the vehicle the part is on (SPEC, "Frame and units").
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Side {
    /// The analysis frame itself: the surface faces -y. Taken as is.
    #[default]
    Left,
    /// Mirrored y -> -y into the analysis frame (with the triangle winding
    /// flipped back, so outward normals stay outward).
    Right,
}

/// The part's triangle mesh in the analysis frame (mm).
#[derive(Clone)]
pub struct Part {
    mesh: TriMesh,
    dropped: usize,
    mins: [f64; 3],
    maxs: [f64; 3],
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("triangles", &self.triangle_count())
            .field("dropped", &self.dropped)
            .field("mins", &self.mins)
            .field("maxs", &self.maxs)
            .finish()
    }
}

impl Part {
    /// Builds the part from triangles already in the analysis frame (mm),
    /// each as three `[x, y, z]` vertices.
    ///
    /// Errors: [`OracleError::NonFinite`] for a NaN or infinite coordinate,
    /// [`OracleError::NoTriangles`] when nothing is left after dropping
    /// degenerate triangles.
    pub fn from_triangles(triangles: &[[[f64; 3]; 3]]) -> Result<Self, OracleError> {
        // The map from coordinates to vertex ids is dropped before parry
        // builds its BVH: both at once were the oracle's peak.
        let (vertices, indices, dropped) = {
            let mut index_of: HashMap<[u64; 3], u32> = HashMap::new();
            let mut vertices: Vec<Vector> = Vec::new();
            let mut indices: Vec<[u32; 3]> = Vec::new();
            indices
                .try_reserve_exact(triangles.len())
                .map_err(|_| OracleError::OutOfMemory {
                    bytes: triangles.len().saturating_mul(12),
                })?;
            let mut dropped = 0;
            for (t, tri) in triangles.iter().enumerate() {
                if tri.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(OracleError::NonFinite { triangle: t });
                }
                let ids = tri.map(|p| {
                    // -0.0 and 0.0 are the same point.
                    let key = p.map(|c| (c + 0.0).to_bits());
                    *index_of.entry(key).or_insert_with(|| {
                        vertices.push(Vector::from_array(p));
                        (vertices.len() - 1) as u32
                    })
                });
                let [a, b, c] = ids.map(|i| vertices[i as usize]);
                let repeats = ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2];
                if repeats || (b - a).cross(c - a).length() == 0.0 {
                    dropped += 1;
                    continue;
                }
                indices.push(ids);
            }
            (vertices, indices, dropped)
        };
        if indices.is_empty() {
            return Err(OracleError::NoTriangles { dropped });
        }
        let mut mins = [f64::INFINITY; 3];
        let mut maxs = [f64::NEG_INFINITY; 3];
        for tri in &indices {
            for &i in tri {
                let v = vertices[i as usize].to_array();
                for k in 0..3 {
                    mins[k] = mins[k].min(v[k]);
                    maxs[k] = maxs[k].max(v[k]);
                }
            }
        }
        // parry allocates its BVH without a way to fail: the memory it
        // takes is asked for (and given back) first, so that where the
        // system would not give it the oracle fails, not the process.
        let bvh = indices.len().saturating_mul(BVH_BUILD_BYTES_PER_TRIANGLE);
        Vec::<u8>::new()
            .try_reserve_exact(bvh)
            .map_err(|_| OracleError::OutOfMemory { bytes: bvh })?;
        let mesh = TriMesh::new(vertices, indices).map_err(|e| OracleError::Mesh(e.to_string()))?;
        Ok(Self {
            mesh,
            dropped,
            mins,
            maxs,
        })
    }

    /// Reads an STL file (binary or ASCII) and maps it into the analysis
    /// frame: coordinates times `scale`, then mirrored y -> -y for
    /// [`Side::Right`] with the winding flipped back.
    pub fn from_stl_path(path: &Path, scale: f64, side: Side) -> Result<Self, OracleError> {
        let file = File::open(path).map_err(|source| OracleError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_stl_reader(&mut BufReader::new(file), scale, side).map_err(|e| match e {
            OracleError::Io { source, .. } => OracleError::Io {
                path: path.display().to_string(),
                source,
            },
            other => other,
        })
    }

    /// As [`Part::from_stl_path`], from any seekable reader.
    pub fn from_stl_reader<R: Read + Seek>(
        reader: &mut R,
        scale: f64,
        side: Side,
    ) -> Result<Self, OracleError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(OracleError::InvalidScale(scale));
        }
        let io_error = |source| OracleError::Io {
            path: String::from("<reader>"),
            source,
        };
        let stl = stl_io::read_stl(reader).map_err(io_error)?;
        let mirror = match side {
            Side::Left => 1.0,
            Side::Right => -1.0,
        };
        let triangles: Vec<[[f64; 3]; 3]> = stl
            .faces
            .iter()
            .map(|face| {
                let [a, b, c] = face.vertices.map(|i| {
                    let v = stl.vertices[i].0;
                    [
                        f64::from(v[0]) * scale,
                        f64::from(v[1]) * scale * mirror,
                        f64::from(v[2]) * scale,
                    ]
                });
                // A mirror reverses orientation: swap two vertices to keep
                // the outward side outward.
                match side {
                    Side::Left => [a, b, c],
                    Side::Right => [a, c, b],
                }
            })
            .collect();
        Self::from_triangles(&triangles)
    }

    /// The parry3d mesh, in the analysis frame (mm).
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// Number of triangles kept.
    pub fn triangle_count(&self) -> usize {
        self.mesh.indices().len()
    }

    /// Number of input triangles dropped as degenerate (a repeated vertex or
    /// zero area).
    pub fn dropped_triangles(&self) -> usize {
        self.dropped
    }

    /// Bounding box of the kept triangles, `(mins, maxs)` as `[x, y, z]` mm.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.mins, self.maxs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn mesh_path(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/meshes")
            .join(name)
    }

    #[test]
    fn merges_vertices_and_drops_degenerate_triangles() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        let c = [0.0, 0.0, 1.0];
        let d = [1.0, 0.0, 1.0];
        let collinear = [2.0, 0.0, 0.0];
        let part =
            Part::from_triangles(&[[a, b, c], [b, d, c], [a, a, b], [a, b, collinear]]).unwrap();
        assert_eq!(part.triangle_count(), 2);
        assert_eq!(part.dropped_triangles(), 2);
        // The shared edge b-c is one pair of vertices, not four.
        assert_eq!(part.mesh().vertices().len(), 5);
        // Bounds are those of the kept triangles: the collinear one is gone.
        assert_eq!(part.bounds(), ([0.0, 0.0, 0.0], [1.0, 0.0, 1.0]));
    }

    #[test]
    fn refuses_no_triangles_and_non_finite_input() {
        assert!(matches!(
            Part::from_triangles(&[]),
            Err(OracleError::NoTriangles { dropped: 0 })
        ));
        let p = [0.0, 0.0, 0.0];
        assert!(matches!(
            Part::from_triangles(&[[p, p, p]]),
            Err(OracleError::NoTriangles { dropped: 1 })
        ));
        assert!(matches!(
            Part::from_triangles(&[[p, [f64::NAN, 0.0, 0.0], [0.0, 0.0, 1.0]]]),
            Err(OracleError::NonFinite { triangle: 0 })
        ));
    }

    const ASCII: &str = "solid t\n facet normal 0 1 0\n  outer loop\n   vertex 0 2 0\n   vertex 0 2 1\n   vertex 1 2 0\n  endloop\n endfacet\nendsolid t\n";

    #[test]
    fn ascii_stl_is_scaled_and_right_side_is_mirrored_with_winding_fixed() {
        let left = Part::from_stl_reader(&mut Cursor::new(ASCII), 10.0, Side::Left).unwrap();
        let right = Part::from_stl_reader(&mut Cursor::new(ASCII), 10.0, Side::Right).unwrap();
        assert_eq!(left.bounds(), ([0.0, 20.0, 0.0], [10.0, 20.0, 10.0]));
        assert_eq!(right.bounds(), ([0.0, -20.0, 0.0], [10.0, -20.0, 10.0]));
        // (b - a) x (c - a) for (0,0,0),(0,0,1),(1,0,0) is +y: the facet
        // faces +y in the file. Mirrored, it must face -y; without the
        // winding swap the mirrored vertices would still wind to +y.
        let normal = |p: &Part| {
            let v = p.mesh().vertices();
            let [a, b, c] = p.mesh().indices()[0].map(|i| v[i as usize]);
            (b - a).cross(c - a).normalize()
        };
        assert!((normal(&left) - Vector::new(0.0, 1.0, 0.0)).length() < 1e-12);
        assert!((normal(&right) - Vector::new(0.0, -1.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn real_meshes_load_and_empty_files_are_refused() {
        for (name, min_triangles) in [
            ("1002_tray_bottom.STL", 4000),
            ("octagonal_pocket.stl", 100),
            ("featuretype.STL", 100),
            ("DC-DC_case.stl", 100),
            ("busted.STL", 100),
            ("soup.stl", 10),
            ("multibody.stl", 10),
        ] {
            let part = Part::from_stl_path(&mesh_path(name), 1.0, Side::Left)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(part.triangle_count() >= min_triangles, "{name}: {part:?}");
            let (mins, maxs) = part.bounds();
            assert!((0..3).all(|k| mins[k] <= maxs[k] && mins[k].is_finite()));
        }
        for name in ["empty.stl", "empty_ascii.stl", "empty_bin.stl"] {
            let err = Part::from_stl_path(&mesh_path(name), 1.0, Side::Left).unwrap_err();
            assert!(
                matches!(
                    err,
                    OracleError::NoTriangles { .. } | OracleError::Io { .. }
                ),
                "{name}: {err}"
            );
            assert!(!err.to_string().is_empty());
        }
        let missing = Part::from_stl_path(&mesh_path("no_such.stl"), 1.0, Side::Left).unwrap_err();
        assert!(missing.to_string().contains("no_such.stl"), "{missing}");
    }
}
