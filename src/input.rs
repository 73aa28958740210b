//! Reading a part: an STL file (binary or ASCII, through `stl_io`, CRLF
//! included) or a scenario file, sized up before it is read, scaled to mm
//! and placed in SPEC's analysis frame (its `--frame`, then its side: y
//! mirrored for the right-hand side, so that every later step works in
//! the canonical frame, knee pushed in +y, sliding in -x; results are
//! mirrored back with [`Side::to_part`]). A part read from several files
//! is [`crate::assembly`]'s; [`Assembly`] records which file each triangle
//! came from.

use std::path::{Path, PathBuf};

use sha2::Digest;

use crate::frame::{Frame, Placement, Side};
use crate::mesh::{Part, Triangle, is_degenerate};

/// Why a part could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened or read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not STL, or is truncated.
    #[error("{path} is not a readable STL file: {reason}")]
    Format {
        /// The file.
        path: String,
        /// What the STL reader said.
        reason: String,
    },
    /// The file holds no triangles.
    #[error("{path} holds no triangles")]
    Empty {
        /// The file.
        path: String,
    },
    /// A vertex is NaN or infinite.
    #[error("{path}: triangle {index} has a non-finite coordinate")]
    NonFinite {
        /// The file.
        path: String,
        /// The triangle's index in the file.
        index: usize,
    },
    /// A vertex lies beyond `MAX_COORD_MM` once scaled.
    #[error("{path}: triangle {index} lies {} mm from the origin, beyond the {} mm a part may span (wrong --scale?)", crate::limits::short(*distance), crate::limits::short(crate::limits::MAX_COORD_MM))]
    TooFar {
        /// The file.
        path: String,
        /// The triangle's index in the file.
        index: usize,
        /// Its largest coordinate (mm, absolute).
        distance: f64,
    },
    /// A vertex lies beyond `MAX_COORD_MM` once placed by
    /// the part's frame (`--frame`).
    #[error("{path}: triangle {index} lies {} mm from the origin once placed by --frame, beyond the {} mm a part may span (a translation in the wrong unit?)", crate::limits::short(*distance), crate::limits::short(crate::limits::MAX_COORD_MM))]
    PlacedTooFar {
        /// The file.
        path: String,
        /// The triangle's index in the file.
        index: usize,
        /// Its largest coordinate once placed (mm, absolute; `inf` for a
        /// non-finite one).
        distance: f64,
    },
    /// The file holds more triangles than `MAX_PART_TRIANGLES`.
    #[error(
        "{path} holds {count} triangles, more than the {} a part may have",
        crate::limits::MAX_PART_TRIANGLES
    )]
    TooManyTriangles {
        /// The file.
        path: String,
        /// How many it holds (or declares).
        count: u64,
    },
    /// A scenario file could not be read or tessellated.
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
    /// The files of an assembly cannot be read as one part.
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    /// Every triangle is degenerate.
    #[error("{path}: all {count} triangles are degenerate (zero area)")]
    AllDegenerate {
        /// The file.
        path: String,
        /// How many triangles it has.
        count: usize,
    },
}

/// A part read from its file, with the file's identity: what a run, its
/// verification and its report are matched by.
#[derive(Debug, Clone)]
pub struct PartFile {
    /// The file as given.
    pub path: PathBuf,
    /// SHA-256 of the file's bytes (lowercase hex).
    pub sha256: String,
    /// Factor from the file's units to mm.
    pub scale: f64,
    /// The side the part was read for (mirrored into the analysis frame
    /// for [`Side::Right`]).
    pub side: Side,
    /// The map from the file's coordinates into vehicle coordinates
    /// (`--frame`; none for a part already in them), applied before the
    /// side's mirror: [`crate::frame`].
    pub frame: Frame,
    /// For a part read from several files ([`crate::assembly`]): every
    /// file, and which file each triangle of `part` came from; `None` for
    /// one file.
    pub assembly: Option<Assembly>,
    /// The part, in mm and the analysis frame.
    pub part: Part,
}

impl PartFile {
    /// A part built in memory (a test, a CAD plug-in's own mesh) rather
    /// than read: no file, so its `sha256` is empty and a report cannot
    /// be matched to it. Scale 1, left side: `part` is already in mm and
    /// the analysis frame.
    pub fn in_memory(name: &str, part: Part) -> PartFile {
        PartFile {
            path: PathBuf::from(name),
            sha256: String::new(),
            scale: 1.0,
            side: Side::Left,
            frame: Frame::none(),
            assembly: None,
            part,
        }
    }

    /// How the file's coordinates map into SPEC's analysis frame: its
    /// frame, then its side (an analysis's own, with its approach, is
    /// [`crate::Analysis::placement`]).
    pub fn placement(&self) -> Placement {
        Placement {
            side: self.side,
            frame: self.frame.clone(),
            approach: crate::frame::Approach::Slide,
        }
    }
}

/// Checks a file-units-to-mm factor: finite, within
/// `MAX_SCALE` of 1 either way.
pub fn check_scale(scale: f64) -> Result<(), crate::SetupError> {
    let max = crate::limits::MAX_SCALE;
    if scale.is_finite() && (1.0 / max..=max).contains(&scale) {
        Ok(())
    } else {
        Err(crate::SetupError::OutOfRange {
            field: "scale",
            value: scale,
            min: 1.0 / max,
            max,
        })
    }
}

/// Reads a part from an STL file (binary or ASCII) or a scenario file
/// (`.toml`, tessellated at its own step), scales it by `scale` (to mm)
/// and maps `side` into the analysis frame; the file's SHA-256 is taken
/// from the same bytes. The file is sized up before it is read
/// (`read_part_bytes_bounded`).
pub fn read_part(path: &Path, scale: f64, side: Side) -> Result<PartFile, MeshError> {
    let bytes = read_part_bytes_bounded(path)?;
    read_part_bytes(path, &bytes, scale, side)
}

/// The bytes of the part file at `path`, read only once they are known to
/// be a part of bounded size: a regular file by its size
/// ([`crate::limits::MAX_PART_FILE_BYTES`]; a scenario file
/// [`crate::limits::MAX_RUN_JSON_BYTES`]) and, for STL, by its first bytes
/// (a binary header whose triangle count gives the file's size, or ASCII's
/// `solid`), so that a large file of something else is refused without
/// being read. A stream (a pipe, a device) is read up to the size its
/// binary header gives, or the bound.
pub(crate) fn read_part_bytes_bounded(path: &Path) -> Result<Vec<u8>, MeshError> {
    use std::io::Read;
    let name = path.display().to_string();
    let io = |source| MeshError::Io {
        path: name.clone(),
        source,
    };
    if crate::scenario::is_scenario_file(path) {
        return crate::limits::read_bounded(path, crate::limits::MAX_RUN_JSON_BYTES).map_err(io);
    }
    crate::limits::not_a_device(path).map_err(io)?;
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if meta.is_dir() {
        return Err(io(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "is a directory",
        )));
    }
    let size = meta.is_file().then_some(meta.len());
    let head = read_head(&file).map_err(io)?;
    let kind = stl_kind(&head, size).map_err(|reason| MeshError::Format {
        path: name.clone(),
        reason,
    })?;
    let limit = match kind {
        StlKind::Binary { triangles } => {
            if triangles > crate::limits::MAX_PART_TRIANGLES as u64 {
                return Err(MeshError::TooManyTriangles {
                    path: name,
                    count: triangles,
                });
            }
            binary_stl_len(triangles)
        }
        StlKind::Ascii => crate::limits::MAX_PART_FILE_BYTES,
    };
    // A stream's size is unknown until read: at most MAX_STREAM_BYTES.
    let limit = if size.is_none() {
        if limit > crate::limits::MAX_STREAM_BYTES && matches!(kind, StlKind::Binary { .. }) {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "not a regular file, and its binary header announces {limit} bytes, more than the {} read from a stream: save the part to a file",
                    crate::limits::MAX_STREAM_BYTES
                ),
            )));
        }
        limit.min(crate::limits::MAX_STREAM_BYTES)
    } else {
        limit
    };
    if let Some(size) = size
        && size > limit
    {
        return Err(io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{size} bytes, more than the {limit} bytes read at most"),
        )));
    }
    let mut bytes = head;
    bytes
        .try_reserve_exact(size.unwrap_or(0).saturating_sub(bytes.len() as u64) as usize)
        .map_err(|_| {
            io(std::io::Error::new(
                std::io::ErrorKind::OutOfMemory,
                "cannot allocate memory for the file",
            ))
        })?;
    (&file)
        .take(limit + 1 - bytes.len() as u64)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(MeshError::Format {
            path: name,
            reason: format!("longer than the {limit} bytes its binary header announces"),
        });
    }
    Ok(bytes)
}

/// A part file's size, known before reading it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PartSize {
    /// Its bytes (a stream: the most read from one,
    /// [`crate::limits::MAX_STREAM_BYTES`]).
    pub file_bytes: u64,
    /// Its triangles, or the most it can hold.
    pub triangles: u64,
    /// Whether `file_bytes` is the file's (a regular file), not a bound.
    pub known: bool,
}

/// The size of the part file at `path`, for the memory reading it takes
/// ([`crate::memory::MemoryEstimate::reading`]), known before reading it:
/// from its size and, for STL, its header's triangle count (binary) or the
/// most triangles its size can hold (ASCII, [`MIN_ASCII_FACET_BYTES`]
/// each); a scenario file is parsed for its count.
pub(crate) fn part_size(path: &Path) -> Result<PartSize, MeshError> {
    let name = path.display().to_string();
    let io = |source| MeshError::Io {
        path: name.clone(),
        source,
    };
    if crate::scenario::is_scenario_file(path) {
        let bytes = read_part_bytes_bounded(path)?;
        let text = String::from_utf8_lossy(&bytes);
        let file = crate::scenario::parse(&text, path)?;
        return Ok(PartSize {
            file_bytes: bytes.len() as u64,
            triangles: file.triangle_count(None) as u64,
            known: true,
        });
    }
    crate::limits::not_a_device(path).map_err(io)?;
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        // A stream is not read twice: counted at the most read from one.
        let file_bytes = crate::limits::MAX_STREAM_BYTES;
        return Ok(PartSize {
            file_bytes,
            triangles: file_bytes / STL_RECORD,
            known: false,
        });
    }
    let size = meta.len();
    let head = read_head(&file).map_err(io)?;
    let triangles = match stl_kind(&head, Some(size)) {
        Ok(StlKind::Binary { triangles }) => triangles,
        _ => size / MIN_ASCII_FACET_BYTES,
    };
    Ok(PartSize {
        file_bytes: size,
        triangles,
        known: true,
    })
}

/// Checks triangles read from the file `name` (scaled by `scale` to mm)
/// can be a part: some triangles, at most
/// `MAX_PART_TRIANGLES`, every coordinate finite and
/// within `MAX_COORD_MM`, and not all of zero area.
pub fn check_triangles(name: &str, triangles: &[Triangle], scale: f64) -> Result<(), MeshError> {
    if triangles.is_empty() {
        return Err(MeshError::Empty { path: name.into() });
    }
    if let Some(index) = triangles
        .iter()
        .position(|t| t.iter().flatten().any(|c| !c.is_finite()))
    {
        return Err(MeshError::NonFinite {
            path: name.into(),
            index,
        });
    }
    if triangles.len() > crate::limits::MAX_PART_TRIANGLES {
        return Err(MeshError::TooManyTriangles {
            path: name.into(),
            count: triangles.len() as u64,
        });
    }
    let reach = |t: &Triangle| t.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs())) * scale;
    if let Some(index) = triangles
        .iter()
        .position(|t| reach(t) > crate::limits::MAX_COORD_MM)
    {
        return Err(MeshError::TooFar {
            path: name.into(),
            index,
            distance: reach(&triangles[index]),
        });
    }
    if triangles.iter().all(is_degenerate) {
        return Err(MeshError::AllDegenerate {
            path: name.into(),
            count: triangles.len(),
        });
    }
    Ok(())
}

/// The fewest bytes an ASCII STL facet takes (`facet normal 0 0 0`,
/// `outer loop`, three `vertex 0 0 0`, `endloop`, `endfacet`, one space
/// each between words and lines).
pub(crate) const MIN_ASCII_FACET_BYTES: u64 = 80;

/// The bytes of a binary STL's header: 80 of text, a 4-byte count.
const STL_HEADER: usize = 84;

/// The bytes of a binary STL's triangle record: normal, three vertices
/// (f32) and a 2-byte attribute.
pub(crate) const STL_RECORD: u64 = 50;

/// The length of a binary STL of `triangles` triangles.
pub(crate) fn binary_stl_len(triangles: u64) -> u64 {
    STL_HEADER as u64 + STL_RECORD * triangles
}

/// The first [`STL_HEADER`] bytes of `file` (fewer if it is shorter).
fn read_head(file: &std::fs::File) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut head = Vec::with_capacity(STL_HEADER);
    file.take(STL_HEADER as u64).read_to_end(&mut head)?;
    Ok(head)
}

/// How an STL file is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StlKind {
    /// Binary, with the triangle count of its header.
    Binary { triangles: u64 },
    /// ASCII (`solid ...`).
    Ascii,
}

/// An STL file's kind from its first [`STL_HEADER`] bytes and, for a
/// regular file, its size. Binary files may start with `solid` too, so a
/// file is binary when its size matches the triangle count in its header
/// (a stream, whose size is unknown, when it does not start with `solid`),
/// and ASCII when it starts with `solid`.
fn stl_kind(head: &[u8], size: Option<u64>) -> Result<StlKind, String> {
    let count = (head.len() >= STL_HEADER)
        .then(|| u64::from(u32::from_le_bytes([head[80], head[81], head[82], head[83]])));
    let ascii = head.trim_ascii_start().starts_with(b"solid");
    match (count, size) {
        (Some(n), Some(size)) if binary_stl_len(n) == size => Ok(StlKind::Binary { triangles: n }),
        (Some(n), None) if !ascii => Ok(StlKind::Binary { triangles: n }),
        _ if ascii => Ok(StlKind::Ascii),
        (None, _) => Err(format!(
            "{} bytes, too short for a binary STL header",
            head.len()
        )),
        _ => Err("neither ASCII (`solid ...`) nor binary: the binary triangle count does not match the file size (truncated?)".into()),
    }
}

/// The SHA-256 of `bytes`, lowercase hex: a part file's identity.
pub fn sha256_hex(bytes: &[u8]) -> String {
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// [`read_part`] into a [`Placement`]: the file's coordinates (mm, after
/// `scale`) mapped by its frame, then its side. Without a frame this is
/// `read_part` itself, to the bit.
pub(crate) fn read_part_placed(
    path: &Path,
    scale: f64,
    placement: &Placement,
) -> Result<PartFile, MeshError> {
    if placement.frame.is_none() {
        return read_part(path, scale, placement.side);
    }
    let mut file = read_part(path, scale, Side::Left)?;
    for v in file.part.triangles.iter_mut().flatten() {
        *v = placement.to_analysis(*v);
    }
    // Whatever the frame holds (a translation of 1e17 mm collapses the
    // part in f64 and still ran), the placed part obeys the bound the
    // file's own coordinates do.
    let reach = |t: &Triangle| {
        t.iter().flatten().fold(0.0f64, |m, c| {
            if c.is_finite() {
                m.max(c.abs())
            } else {
                f64::INFINITY
            }
        })
    };
    if let Some(index) = file
        .part
        .triangles
        .iter()
        .position(|t| reach(t) > crate::limits::MAX_COORD_MM)
    {
        return Err(MeshError::PlacedTooFar {
            path: path.display().to_string(),
            index,
            distance: reach(&file.part.triangles[index]),
        });
    }
    file.side = placement.side;
    file.frame = placement.frame.clone();
    Ok(file)
}

/// [`read_part`] of bytes already read from `path`.
pub fn read_part_bytes(
    path: &Path,
    bytes: &[u8],
    scale: f64,
    side: Side,
) -> Result<PartFile, MeshError> {
    let name = path.display().to_string();
    let sha256 = sha256_hex(bytes);
    let part = if crate::scenario::is_scenario_file(path) {
        let text =
            std::str::from_utf8(bytes).map_err(|e| crate::scenario::ScenarioError::Read {
                path: path.to_path_buf(),
                cause: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
            })?;
        let triangles = crate::scenario::parse(text, path)?.triangulate(None);
        Part::from_triangles(&name, triangles, scale, side)?
    } else {
        Part::from_stl_bytes(&name, bytes, scale, side)?
    };
    Ok(PartFile {
        path: path.to_path_buf(),
        sha256,
        scale,
        side,
        frame: Frame::none(),
        assembly: None,
        part,
    })
}

impl Part {
    /// Parses the bytes of an STL file named `name` (for messages).
    pub fn from_stl_bytes(
        name: &str,
        bytes: &[u8],
        scale: f64,
        side: Side,
    ) -> Result<Part, MeshError> {
        let (triangles, bodies) = parse_stl(bytes).map_err(|reason| MeshError::Format {
            path: name.into(),
            reason,
        })?;
        let mut part = Part::from_triangles(name, triangles, scale, side)?;
        part.bodies = bodies;
        Ok(part)
    }

    /// Builds a part from triangles in the part's own frame and units.
    pub fn from_triangles(
        name: &str,
        triangles: Vec<Triangle>,
        scale: f64,
        side: Side,
    ) -> Result<Part, MeshError> {
        check_triangles(name, &triangles, scale)?;
        let file_triangles = triangles.len();
        let kept: Vec<Triangle> = triangles
            .into_iter()
            .map(|t| t.map(|[x, y, z]| [x * scale, side.to_part(y * scale), z * scale]))
            .filter(|t| !is_degenerate(t))
            .collect();
        if kept.is_empty() {
            return Err(MeshError::AllDegenerate {
                path: name.into(),
                count: file_triangles,
            });
        }
        Ok(Part {
            degenerate: file_triangles - kept.len(),
            triangles: kept,
            file_triangles,
            bodies: 1,
        })
    }
}

/// Parses binary or ASCII STL into its triangles and the count of bodies
/// read. Binary files may start with `solid` too, so a file is taken as
/// binary when its size matches the triangle count in its header, and as
/// ASCII otherwise. An ASCII file is read body by body: every `solid ...
/// endsolid` block (`stl_io` alone stops at the first `endsolid`, which
/// read a small case and dropped the console after it).
fn parse_stl(bytes: &[u8]) -> Result<(Vec<Triangle>, usize), String> {
    let kind = stl_kind(
        &bytes[..bytes.len().min(STL_HEADER)],
        Some(bytes.len() as u64),
    )?;
    let bodies: Vec<Vec<u8>> = if let StlKind::Binary { triangles } = kind {
        if triangles > crate::limits::MAX_PART_TRIANGLES as u64 {
            return Err(format!(
                "{triangles} triangles, more than the {} a part may have",
                crate::limits::MAX_PART_TRIANGLES
            ));
        }
        // stl_io takes any file whose first line starts with "solid " as
        // ASCII; the binary header is free text, so blank it.
        let mut copy = bytes.to_vec();
        copy[..80].fill(0);
        vec![copy]
    } else {
        ascii_bodies(bytes)?
            .into_iter()
            .map(|body| {
                // stl_io wants "solid " with a space; exporters also write
                // a bare "solid" line.
                let mut copy = b"solid ".to_vec();
                copy.extend_from_slice(&body[5..]);
                copy
            })
            .collect()
    };
    let mut triangles = Vec::new();
    let count = bodies.len();
    for (k, body) in bodies.into_iter().enumerate() {
        let mut cursor = std::io::Cursor::new(body);
        let stl = stl_io::create_stl_reader(&mut cursor)
            .and_then(|reader| reader.collect::<Result<Vec<_>, _>>())
            .map_err(|e| {
                if count > 1 {
                    format!("body {} of {count}: {e}", k + 1)
                } else {
                    e.to_string()
                }
            })?;
        triangles.extend(stl.into_iter().map(|t| {
            t.vertices
                .map(|v| [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])])
        }));
    }
    Ok((triangles, count))
}

/// An ASCII STL's bodies: each from its `solid` line to the end of its
/// `endsolid` line (the last to the end of the file). Whitespace (and NUL
/// padding) after the last body is nothing; anything else between or
/// after bodies is refused rather than skipped.
fn ascii_bodies(bytes: &[u8]) -> Result<Vec<&[u8]>, String> {
    let is_blank = |b: &[u8]| b.iter().all(|c| c.is_ascii_whitespace() || *c == 0);
    let mut bodies = Vec::new();
    let mut start: Option<usize> = None;
    let mut at = 0;
    while at < bytes.len() {
        let end = bytes[at..]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(bytes.len(), |k| at + k + 1);
        let line = bytes[at..end].trim_ascii_start();
        match start {
            None if is_blank(line) => {}
            None if line.starts_with(b"solid") => start = Some(at + (end - at - line.len())),
            None => {
                return Err(format!(
                    "ASCII STL: text outside a `solid ... endsolid` body after body {} (byte {at})",
                    bodies.len()
                ));
            }
            Some(s) if line.starts_with(b"endsolid") => {
                bodies.push(&bytes[s..end]);
                start = None;
            }
            Some(_) => {}
        }
        at = end;
    }
    if let Some(s) = start {
        bodies.push(&bytes[s..]);
    }
    if bodies.is_empty() {
        return Err("ASCII STL without a `solid` line".into());
    }
    Ok(bodies)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary_stl(tris: &[[[f32; 3]; 3]], header: &[u8]) -> Vec<u8> {
        let mut out = vec![0u8; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            out.extend([0u8; 12]);
            for v in t {
                for c in v {
                    out.extend(c.to_le_bytes());
                }
            }
            out.extend([0u8; 2]);
        }
        out
    }

    const TRI: [[f32; 3]; 3] = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 1.0]];

    #[test]
    fn binary_with_solid_header_reads_as_binary() {
        let bytes = binary_stl(&[TRI, TRI], b"solid but binary");
        assert_eq!(parse_stl(&bytes).unwrap().0.len(), 2);
    }

    #[test]
    fn ascii_with_crlf_reads() {
        let text = "solid x\r\nfacet normal 0 0 0\r\nouter loop\r\nvertex 0 1 0\r\nvertex 1 1 0\r\nvertex 0 1 1\r\nendloop\r\nendfacet\r\nendsolid x\r\n";
        assert_eq!(parse_stl(text.as_bytes()).unwrap(), (vec![TRI64], 1));
    }

    const TRI64: Triangle = [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 1.0]];

    fn ascii_body(name: &str, facets: usize, dx: f64) -> String {
        let mut s = format!("solid {name}\n");
        for k in 0..facets {
            let x = dx + k as f64;
            s += &format!(
                "  facet normal 0 -1 0\n    outer loop\n      vertex {x} 1 0\n      vertex {} 1 0\n      vertex {x} 1 1\n    endloop\n  endfacet\n",
                x + 1.0
            );
        }
        s + &format!("endsolid {name}\n")
    }

    /// CAD exporters write one `solid` block per body; every one is read
    /// (trimesh's models/multibody.stl gave 12 of its 32 triangles before).
    #[test]
    fn every_body_of_an_ascii_stl_is_read() {
        let text = ascii_body("case", 2, 0.0) + &ascii_body("console", 5, 100.0) + "\n\n";
        let (triangles, bodies) = parse_stl(text.as_bytes()).unwrap();
        assert_eq!((triangles.len(), bodies), (7, 2));
        assert_eq!(
            triangles[2][0],
            [100.0, 1.0, 0.0],
            "the second body's first facet"
        );
        let part = Part::from_stl_bytes("t", text.as_bytes(), 1.0, Side::Left).unwrap();
        assert_eq!((part.file_triangles, part.bodies), (7, 2));
        // A bare `solid` line and CRLF line ends, as some exporters write.
        let crlf = (ascii_body("", 1, 0.0) + &ascii_body("b", 1, 5.0)).replace('\n', "\r\n");
        assert_eq!(parse_stl(crlf.as_bytes()).unwrap().0.len(), 2);
        // A broken second body is an error naming it, not a silent stop.
        let broken = ascii_body("a", 1, 0.0) + "solid b\n  facet normal 0 0 0\n    outer loop\n";
        let err = parse_stl(broken.as_bytes()).unwrap_err();
        assert!(err.contains("body 2 of 2"), "{err}");
        // Text after the last body that is not a body is refused.
        let trailing = ascii_body("a", 1, 0.0) + "garbage\n";
        assert!(
            parse_stl(trailing.as_bytes())
                .unwrap_err()
                .contains("outside")
        );
    }

    #[test]
    fn truncated_binary_is_refused() {
        let mut bytes = binary_stl(&[TRI, TRI], b"part");
        bytes.truncate(bytes.len() - 10);
        assert!(parse_stl(&bytes).is_err());
    }

    #[test]
    fn scale_side_and_degenerates() {
        let t = TRI.map(|v| v.map(f64::from));
        let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let part = Part::from_triangles("t", vec![t, flat], 10.0, Side::Right).unwrap();
        assert_eq!(part.degenerate, 1);
        assert_eq!(part.triangles[0][0], [0.0, -10.0, 0.0]);
        let err = Part::from_triangles("t", vec![[[f64::NAN; 3]; 3]], 1.0, Side::Left).unwrap_err();
        assert!(matches!(err, MeshError::NonFinite { index: 0, .. }));
        assert!(matches!(
            Part::from_triangles("t", vec![], 1.0, Side::Left),
            Err(MeshError::Empty { .. })
        ));
    }
}

/// One file of an assembly.
#[derive(Debug, Clone, PartialEq)]
pub struct AssemblyFile {
    /// The file as given.
    pub path: PathBuf,
    /// SHA-256 of its bytes (lowercase hex).
    pub sha256: String,
    /// Triangles in the file.
    pub triangles: usize,
    /// Of those, skipped for zero area.
    pub degenerate: usize,
    /// Bodies read from it ([`crate::mesh::Part::bodies`]).
    pub bodies: usize,
    /// Disregarded by the regulation (`--ignore`): not in the height grid.
    pub ignored: bool,
}
/// The files of a part read from several, and where each triangle came
/// from.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// Every file, in the order given: the analysed files, then the
    /// `--ignore` files not among them.
    pub files: Vec<AssemblyFile>,
    /// Per triangle of the merged part, the index of its file in `files`.
    pub file_of: Vec<u32>,
}
/// Why the files of an assembly cannot be read as one part.
#[derive(Debug, thiserror::Error)]
pub enum AssemblyError {
    /// No file to analyse.
    #[error("no part file to analyse (every file given is --ignore'd)")]
    NothingToAnalyse,
    /// A file is given twice.
    #[error("{} is given twice", path.display())]
    Repeated {
        /// The file.
        path: PathBuf,
    },
    /// An assembly holds more files than a node's attribution can name.
    #[error("{0} files: at most {max} can be analysed as one part", max = u32::MAX)]
    TooMany(usize),
}
