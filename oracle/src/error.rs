//! Errors of the oracle's inputs: the part and the options.

/// Why the oracle refused its inputs. Per-start failures of the geometry
/// queries are not errors: they are [`crate::StartStatus::Failed`].
#[derive(Debug, thiserror::Error)]
pub enum OracleError {
    /// The STL file could not be opened or parsed.
    #[error("cannot read STL {path}: {source}")]
    Io {
        /// The file, or `<reader>` when read from a stream.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The mesh has no triangle left after dropping degenerate ones.
    #[error("the part has no triangles ({dropped} degenerate ones dropped)")]
    NoTriangles {
        /// How many degenerate triangles were dropped.
        dropped: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("triangle {triangle} has a non-finite coordinate")]
    NonFinite {
        /// Index of the triangle in the input.
        triangle: usize,
    },
    /// The scale factor is not a finite positive number.
    #[error("scale must be finite and > 0, got {0}")]
    InvalidScale(f64),
    /// The system would not give the memory the part's mesh and its BVH
    /// take: asked for before parry builds them, since an allocation
    /// failing inside parry aborts the process.
    #[error("cannot allocate the {:.2} GiB the exact oracle's copy of the part takes", *bytes as f64 / f64::from(1u32 << 30))]
    OutOfMemory {
        /// The bytes asked for.
        bytes: usize,
    },
    /// parry3d refused the mesh.
    #[error("parry3d refused the mesh: {0}")]
    Mesh(String),
    /// An option is out of its range.
    #[error("invalid oracle option: {0}")]
    InvalidOptions(String),
}
