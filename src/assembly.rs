//! Assemblies: several part files analysed as one part (`analyze trim.stl
//! bezel.stl switch.stl`), each colliding node attributed to the file whose
//! surface set its height.
//!
//! The files' triangles are merged in the files' order into one
//! [`Part`], so the height grid is exactly the grid of one file holding
//! them all; the rasterizer ([`crate::grid::HeightGrid::sample_attributed`])
//! carries each triangle's file index to the node it sets. Where two files
//! set the same height at a node (a tie to the last bit), the node is the
//! **lowest-indexed** file's: the rasterizer keeps the first of equal
//! depths, and the lower index comes first.
//!
//! Files the regulation disregards (materials softer than 50 Shore A:
//! `--ignore FILE`) are read and identified (path, SHA-256, triangles) but
//! kept out of the height grid: the knee-form passes through them.

use std::path::{Path, PathBuf};

use crate::frame::Placement;

use crate::input::{Assembly, AssemblyError, AssemblyFile, MeshError, PartFile, read_part_placed};
use crate::mesh::Part;

/// What to read: the files of a part, the ones to disregard, and how
/// their coordinates map into the analysis frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PartSource {
    /// The part's files, in order (one for a single part).
    pub files: Vec<PathBuf>,
    /// Files disregarded by the regulation: identified, not analysed. A
    /// file both here and in `files` is disregarded.
    pub ignored: Vec<PathBuf>,
    /// Factor from the files' units to mm.
    pub scale: f64,
    /// The frame and side of every file.
    pub placement: Placement,
}

impl PartSource {
    /// One file, no frame.
    pub fn file(path: &Path, scale: f64, placement: Placement) -> PartSource {
        PartSource {
            files: vec![path.to_path_buf()],
            ignored: Vec::new(),
            scale,
            placement,
        }
    }

    /// Whether this is one file with nothing disregarded: read exactly as
    /// `read_part_placed` reads it, with no [`Assembly`].
    pub fn is_single(&self) -> bool {
        self.files.len() == 1 && self.ignored.is_empty()
    }

    /// Reads the part: one file as `read_part_placed`; several (or any
    /// `--ignore`) merged in order, with an [`Assembly`] saying which file
    /// each triangle came from.
    pub fn read(&self) -> Result<PartFile, MeshError> {
        if self.is_single() {
            return read_part_placed(&self.files[0], self.scale, &self.placement);
        }
        let order = self.order()?;
        let mut merged: Option<PartFile> = None;
        let mut files = Vec::with_capacity(order.len());
        let mut file_of = Vec::new();
        let mut triangles = Vec::new();
        let (mut file_triangles, mut degenerate, mut bodies) = (0, 0, 0);
        for (index, (path, ignored)) in order.into_iter().enumerate() {
            let read = read_part_placed(&path, self.scale, &self.placement)?;
            files.push(AssemblyFile {
                path: path.clone(),
                sha256: read.sha256.clone(),
                triangles: read.part.file_triangles,
                degenerate: read.part.degenerate,
                bodies: read.part.bodies,
                ignored,
            });
            if ignored {
                continue;
            }
            file_triangles += read.part.file_triangles;
            degenerate += read.part.degenerate;
            bodies += read.part.bodies;
            file_of.extend(std::iter::repeat_n(index as u32, read.part.triangles.len()));
            triangles.extend_from_slice(&read.part.triangles);
            merged.get_or_insert(read);
        }
        let mut merged = merged.ok_or(AssemblyError::NothingToAnalyse)?;
        merged.part = Part {
            triangles,
            file_triangles,
            degenerate,
            bodies,
        };
        merged.sha256 = String::new();
        merged.assembly = Some(Assembly { files, file_of });
        Ok(merged)
    }

    /// The files in order with whether each is disregarded: `files` as
    /// given (those also in `ignored` disregarded), then the rest of
    /// `ignored`. Files are compared by their canonical path where it can
    /// be had.
    fn order(&self) -> Result<Vec<(PathBuf, bool)>, AssemblyError> {
        let key = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
        let ignored_keys: Vec<PathBuf> = self.ignored.iter().map(|p| key(p)).collect();
        let mut seen: Vec<PathBuf> = Vec::new();
        let mut order = Vec::new();
        for path in &self.files {
            let k = key(path);
            if seen.contains(&k) {
                return Err(AssemblyError::Repeated { path: path.clone() });
            }
            order.push((path.clone(), ignored_keys.contains(&k)));
            seen.push(k);
        }
        for (path, k) in self.ignored.iter().zip(ignored_keys) {
            if !seen.contains(&k) {
                order.push((path.clone(), true));
                seen.push(k);
            }
        }
        if order.iter().all(|(_, ignored)| *ignored) {
            return Err(AssemblyError::NothingToAnalyse);
        }
        if order.len() > u32::MAX as usize {
            return Err(AssemblyError::TooMany(order.len()));
        }
        Ok(order)
    }
}

/// Per file of `assembly`, the composite's nodes whose height that file
/// set: `node_file` is the grid's attribution, `composite` the count per
/// node.
pub(crate) fn colliding_nodes_per_file(
    assembly: &Assembly,
    node_file: &[u32],
    composite: &[u16],
) -> Vec<usize> {
    let mut per_file = vec![0; assembly.files.len()];
    for (&f, _) in node_file.iter().zip(composite).filter(|&(_, &c)| c > 0) {
        per_file[f as usize] += 1;
    }
    per_file
}
