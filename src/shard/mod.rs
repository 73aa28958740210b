//! Fan-out of one analysis over its angles: `analyze --shard K/N` computes
//! push and slide at every N-th angle only (the run's angles `a` with
//! `a % N == K - 1`, so every shard gets a share of the low and high
//! angles) and writes a self-describing partial result; [`merge`] puts N
//! such shards back together into the results the unsharded run writes,
//! byte for byte (clock readings aside), without the part.
//!
//! A shard directory holds two files:
//!
//! * `shard.json` ([`ShardRecord`]): which shard of how many, the indices
//!   of its angles, the summary of the whole run as far as a shard knows
//!   it (the part's identity, the setup, the full angle list, the grid,
//!   the memory estimate), the warnings that do not depend on the result,
//!   and the SHA-256 of `shard.bin` and of its common part;
//! * `shard.bin`: what the writers need and the summary does not hold, in
//!   little-endian binary: the height grid (f64 bits), an assembly's file
//!   per node, the blind spots, then per angle of the shard its placed
//!   starts, its colliding mask (one bit per node) and which blind spots
//!   it meets (one bit each).
//!
//! Every shard samples the same grid and finds the same blind spots (they
//! are deterministic), so the common part is the same in all of them:
//! [`merge`] refuses shards whose common part, part, setup or shard count
//! differ, a shard given twice and a shard missing, each in one line.
//!
//! **Invariant:** a merged result is computed from the shards' masks by
//! the same functions an analysis uses (the composite, the blind spots
//! met, the warnings, the summary's counts), so it is the unsharded run's.
//!
//! A verification or a convergence study fans out over its starts
//! instead (`verify --shard K/N`, `converge --shard K/N`): [`study`]
//! writes and merges those shards, which `kneeform merge` tells from an
//! analysis's by their `shard.json` ([`study::shard_kind`]).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::analysis::Analysis;
use crate::blind::BlindSpot;
use crate::engine::AngleMask;
use crate::frame::{Frame, Placement};
use crate::grid::{GridSpec, HeightGrid};
use crate::output::{OutputDir, RunResults, WriteError};
use crate::partition::{Shard, ShardSyntax};
use crate::summary::{AngleSummary, SampleCheck, Summary};

#[cfg(feature = "harness")]
pub mod study;

/// The SHA-256 (hex) of a `shard.json`'s content with its
/// `record_sha256` left out (keys sorted, compact JSON): what
/// `record_sha256` holds, so that an edited `shard.json` (a per-angle
/// area, a dropped warning) is refused as `shard.bin` is by its checksum.
pub(crate) fn record_digest(value: &serde_json::Value) -> String {
    let mut v = value.clone();
    if let Some(o) = v.as_object_mut() {
        o.remove("record_sha256");
    }
    hex_sha256(&serde_json::to_vec(&v).unwrap_or_default())
}

/// `record` as `shard.json`'s text, its `record_sha256` set
/// ([`record_digest`]).
pub(crate) fn sealed_json(mut record: serde_json::Value) -> String {
    let digest = record_digest(&record);
    if let Some(o) = record.as_object_mut() {
        o.insert("record_sha256".into(), digest.into());
    }
    serde_json::to_string_pretty(&record).unwrap_or_default() + "\n"
}

/// `shard.json`'s text parsed, its `record_sha256` checked against its
/// content; the reason when it does not hold.
pub(crate) fn unsealed_json(text: &[u8]) -> Result<serde_json::Value, String> {
    let value: serde_json::Value =
        serde_json::from_slice(text).map_err(|e| format!("not a kneeform shard.json: {e}"))?;
    match value.get("record_sha256").and_then(|d| d.as_str()) {
        Some(d) if d == record_digest(&value) => Ok(value),
        Some(_) => Err("edited: its content is not what its record_sha256 says".into()),
        None => Err("no record_sha256 (written by an older kneeform? run the shard again)".into()),
    }
}

/// Why shards cannot be written or merged.
#[derive(Debug, thiserror::Error)]
pub enum ShardError {
    /// Not `K/N`.
    #[error(transparent)]
    Syntax(#[from] ShardSyntax),
    /// More shards than angles: some shard would have nothing to do.
    #[error("{shards} shards of {angles} angles: at most one shard per angle")]
    TooMany {
        /// N.
        shards: usize,
        /// The run's angles.
        angles: usize,
    },
    /// A file of a shard directory cannot be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A shard's files are not what a shard writes.
    #[error("{}: {reason}", path.display())]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong, in words.
        reason: String,
    },
    /// Shards of different runs, or not every shard exactly once.
    #[error("{0}")]
    Mismatch(String),
}

/// `shard.json`: one shard's description of itself.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardRecord {
    /// The format of the shard's files (1).
    pub format: u32,
    /// Which shard of how many.
    pub shard: Shard,
    /// Its angles: indices into `summary.angles_deg`.
    pub angle_indices: Vec<usize>,
    /// The warnings that do not depend on the masks (about the part and
    /// the angles), as the whole run prints them.
    pub base_warnings: Vec<String>,
    /// SHA-256 of `shard.bin` (hex).
    pub data_sha256: String,
    /// SHA-256 of `shard.bin`'s common part: grid, files, blind spots.
    pub common_sha256: String,
    /// SHA-256 of this record's own content, keys sorted, compact JSON,
    /// this field left out.
    #[serde(default)]
    pub record_sha256: String,
    /// The whole run's summary as this shard knows it: every parameter
    /// and the part's identity; counts of its own angles only.
    pub summary: Summary,
}

/// The format [`write_shard`] writes and [`merge`] reads.
pub(crate) const FORMAT: u32 = 2;

const MAGIC: &[u8; 16] = b"kneeform shard 2";

/// Writes `analysis`, computed at one shard's angles only
/// (`analysis.angles`, [`Analysis::of_source_at`]), as that shard:
/// `shard.json` and `shard.bin` in the staged directory `out`.
pub fn write_shard(out: &OutputDir, analysis: &Analysis) -> Result<(), WriteError> {
    let shard = analysis.angles;
    let indices = shard.indices(analysis.masks.len());
    let mut bin = Vec::new();
    bin.extend_from_slice(MAGIC);
    let spec = analysis.grid.spec;
    for v in [spec.nx as u64, spec.nz as u64] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    for v in [spec.i_origin, spec.j_origin] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    bin.extend_from_slice(&spec.pitch.to_bits().to_le_bytes());
    bin.push(u8::from(analysis.node_file.is_some()));
    bin.extend_from_slice(&(analysis.blind_spots.len() as u64).to_le_bytes());
    for h in &analysis.grid.h {
        bin.extend_from_slice(&h.to_bits().to_le_bytes());
    }
    for f in analysis.node_file.iter().flatten() {
        bin.extend_from_slice(&f.to_le_bytes());
    }
    for b in &analysis.blind_spots {
        for v in [b.i as u64, b.j as u64] {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        for v in [
            b.x,
            b.z,
            b.depth_missed_mm,
            b.width_mm,
            b.resolving_pitch_mm,
            b.y,
        ] {
            bin.extend_from_slice(&v.to_bits().to_le_bytes());
        }
    }
    let common_sha256 = hex_sha256(&bin);
    bin.extend_from_slice(&(indices.len() as u64).to_le_bytes());
    for &a in &indices {
        let m = &analysis.masks[a];
        bin.extend_from_slice(&(a as u64).to_le_bytes());
        bin.extend_from_slice(&(m.placed as u64).to_le_bytes());
        pack_bits(&mut bin, m.mask.iter().map(|&v| v != 0));
        pack_bits(&mut bin, m.probes_met.iter().copied());
    }
    let summary = analysis.summary();
    let tail = result_warnings(
        &analysis.blind_spots,
        &analysis.composite,
        &analysis.placement(),
    )
    .len();
    let warnings = &summary.warnings;
    let record = ShardRecord {
        format: FORMAT,
        shard,
        angle_indices: indices,
        base_warnings: warnings[..warnings.len().saturating_sub(tail)].to_vec(),
        data_sha256: hex_sha256(&bin),
        common_sha256,
        record_sha256: String::new(),
        summary,
    };
    let path = out.path("shard.bin");
    std::fs::write(&path, &bin).map_err(WriteError::at(&path))?;
    let path = out.path("shard.json");
    let value = serde_json::to_value(&record).map_err(WriteError::at(&path))?;
    std::fs::write(&path, sealed_json(value)).map_err(WriteError::at(&path))
}

/// The warnings an analysis adds once its masks are known: blind spots
/// met, nothing struck.
fn result_warnings(blind: &[BlindSpot], composite: &[u16], placement: &Placement) -> Vec<String> {
    let struck = composite.iter().filter(|&&c| c > 0).count();
    crate::sanity::blind_spot_warnings(blind, placement)
        .into_iter()
        .chain(crate::sanity::result_warnings(struck))
        .map(|w| w.to_string())
        .collect()
}

/// N shards merged: the whole run's results and summary.
#[derive(Debug)]
pub struct Merged {
    /// The height grid.
    pub grid: HeightGrid,
    /// Every angle's mask, in the run's order.
    pub masks: Vec<AngleMask>,
    /// The composite.
    pub composite: Vec<u16>,
    /// An assembly's file per node.
    pub node_file: Option<Vec<u32>>,
    /// The part's frame and side.
    pub placement: Placement,
    /// The blind spots, with the angles meeting them.
    pub blind_spots: Vec<BlindSpot>,
    /// The whole run's summary (timings: each stage's longest among the
    /// shards, push and slide their sum; `write_s` the merge's writing).
    pub summary: Summary,
}

impl Merged {
    /// The results, as the writers take them.
    pub fn results(&self) -> RunResults<'_> {
        RunResults {
            grid: &self.grid,
            masks: &self.masks,
            composite: &self.composite,
            node_file: self.node_file.as_deref(),
            placement: &self.placement,
            blind_spots: &self.blind_spots,
            triangle_side: self.summary.triangle_side_mm,
        }
    }
}

/// One shard directory, read and checked against its own checksums.
struct ShardFiles {
    dir: PathBuf,
    record: ShardRecord,
    bin: Vec<u8>,
    common_end: usize,
    header: Header,
}

/// What every shard of a run holds alike, decoded.
struct Common {
    grid: HeightGrid,
    node_file: Option<Vec<u32>>,
    blind_spots: Vec<BlindSpot>,
}

/// One angle of a shard, decoded: its index among the run's angles, its
/// placed starts, its mask and the blind spots it meets.
struct ShardAngle {
    index: usize,
    placed: usize,
    mask: Vec<u8>,
    probes: Vec<bool>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Header {
    spec: GridSpec,
    has_files: bool,
    blind: usize,
}

/// Reads the shard directories `dirs` (one per shard, in any order) and
/// merges them into the whole run's results.
pub fn merge(dirs: &[PathBuf]) -> Result<Merged, ShardError> {
    let first_identity = std::cell::OnceCell::new();
    let shards = read_set(dirs, "run", read_shard, |first, s| {
        let identity = first_identity.get_or_init(|| identity(&first.record.summary));
        if let Some(key) = first_difference(identity, &self::identity(&s.record.summary)) {
            return Err(ShardError::Mismatch(format!(
                "{} and {} are shards of different runs (their summaries' `{key}` differ)",
                first.dir.display(),
                s.dir.display()
            )));
        }
        if let Some(what) = check_difference(
            first.record.summary.sample_check.as_ref(),
            s.record.summary.sample_check.as_ref(),
        ) {
            return Err(ShardError::Mismatch(format!(
                "{} and {} are shards of different runs (their sample checks differ in {what}: the shards of one run share --no-check and every other flag)",
                first.dir.display(),
                s.dir.display()
            )));
        }
        if s.record.common_sha256 != first.record.common_sha256 || s.header != first.header {
            return Err(ShardError::Mismatch(format!(
                "{} and {} are shards of different runs (their grids or blind spots differ)",
                first.dir.display(),
                s.dir.display()
            )));
        }
        Ok(())
    })?;
    let first = &shards[0];
    let summary = &first.record.summary;
    let angles = &summary.angles_deg;
    let header = first.header;
    let spec = header.spec;
    let n = spec.len();
    let Common {
        grid,
        node_file,
        mut blind_spots,
    } = first.common(n)?;
    let mut masks: Vec<Option<AngleMask>> = vec![None; angles.len()];
    let mut per_angle: Vec<Option<AngleSummary>> = vec![None; angles.len()];
    for s in &shards {
        for ShardAngle {
            index: a,
            placed,
            mask,
            probes,
        } in s.angles(n)?
        {
            let colliding = mask.iter().filter(|&&v| v != 0).count();
            let row = &s.record.summary.per_angle[a];
            if row.placed_starts != placed || row.colliding_nodes != colliding {
                return Err(s.corrupt(format!(
                    "angle {}'s counts in shard.json are not those of its mask",
                    angles[a]
                )));
            }
            per_angle[a] = Some(row.clone());
            masks[a] = Some(AngleMask {
                angle_deg: angles[a],
                mask,
                placed,
                colliding,
                probes_met: probes,
            });
        }
    }
    let masks: Vec<AngleMask> = masks
        .into_iter()
        .zip(angles)
        .map(|(m, a)| m.ok_or_else(|| ShardError::Mismatch(format!("no shard holds angle {a}"))))
        .collect::<Result<_, _>>()?;
    let composite = crate::engine::composite(&masks);
    let met = crate::analysis::probes_met(&masks, blind_spots.len());
    for (b, met) in blind_spots.iter_mut().zip(met) {
        b.met_angles_deg = met;
    }
    let mut merged = summary.clone();
    merged.per_angle = per_angle.into_iter().flatten().collect();
    let area = spec.pitch * spec.pitch;
    let composite_nodes = composite.iter().filter(|&&c| c > 0).count();
    merged.composite_nodes = composite_nodes;
    merged.composite_area_mm2 = composite_nodes as f64 * area;
    if let Some(files) = &node_file {
        let mut per_file = vec![0usize; merged.files.len()];
        for (&f, _) in files.iter().zip(&composite).filter(|&(_, &c)| c > 0) {
            if let Some(count) = per_file.get_mut(f as usize) {
                *count += 1;
            }
        }
        for (f, nodes) in merged.files.iter_mut().zip(per_file) {
            f.colliding_nodes = nodes;
            f.colliding_area_mm2 = nodes as f64 * area;
        }
    }
    merged.blind_spots_met = blind_spots
        .iter()
        .filter(|b| !b.met_angles_deg.is_empty())
        .count();
    let frame = merged
        .frame
        .as_ref()
        .map_or(Ok(Frame::none()), Frame::from_record)
        .map_err(|e| first.corrupt(format!("frame: {e}")))?;
    let placement = Placement {
        side: merged.side,
        frame,
        approach: merged.approach,
    };
    merged.warnings = first.record.base_warnings.clone();
    merged
        .warnings
        .extend(result_warnings(&blind_spots, &composite, &placement));
    let t = &mut merged.timings;
    for s in &shards {
        let st = &s.record.summary.timings;
        t.read_s = t.read_s.max(st.read_s);
        t.sample_s = t.sample_s.max(st.sample_s);
        t.blind_s = t.blind_s.max(st.blind_s);
    }
    t.push_slide_s = shards
        .iter()
        .map(|s| s.record.summary.timings.push_slide_s)
        .sum();
    t.check_s = shards
        .iter()
        .map(|s| s.record.summary.timings.check_s)
        .sum();
    // Each shard checked the run's check angles it holds.
    let checks: Vec<_> = shards
        .iter()
        .filter_map(|s| s.record.summary.sample_check.clone())
        .collect();
    merged.sample_check = if checks.len() == shards.len() {
        crate::summary::SampleCheck::merged(&checks, &merged.angles_deg)
    } else {
        None
    };
    merged.run_unix_time = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    Ok(Merged {
        grid,
        masks,
        composite,
        node_file,
        placement,
        blind_spots,
        summary: merged,
    })
}

/// A shard directory as a merge has read it.
pub(crate) trait ShardDir {
    /// Which shard it holds.
    fn shard(&self) -> Shard;
    /// Where it was read from.
    fn dir(&self) -> &Path;
}

impl ShardDir for ShardFiles {
    fn shard(&self) -> Shard {
        self.record.shard
    }
    fn dir(&self) -> &Path {
        &self.dir
    }
}

/// Reads the shard directories `dirs` (one per shard, in any order) with
/// `read` and checks that they are every shard of one `set` (a run, a
/// study) exactly once: one shard count N, each index once, and each
/// directory `same` as the first (`same(first, other)`).
pub(crate) fn read_set<T: ShardDir>(
    dirs: &[PathBuf],
    set: &str,
    read: impl Fn(&Path) -> Result<T, ShardError>,
    same: impl Fn(&T, &T) -> Result<(), ShardError>,
) -> Result<Vec<T>, ShardError> {
    let shards = dirs
        .iter()
        .map(|d| read(d))
        .collect::<Result<Vec<_>, _>>()?;
    let sets: Vec<(Shard, &Path)> = shards.iter().map(|s| (s.shard(), s.dir())).collect();
    check_set(&sets, set, |k| same(&shards[0], &shards[k]))?;
    Ok(shards)
}

/// Checks that `shards` (each one's K/N and directory; the first is the
/// reference) are every shard of one `set` ("run", "study") exactly once:
/// one N, no K twice, none missing. `same(k)` refuses shard `k` when it
/// belongs to another set than the first's. The first refusal found,
/// shard by shard in the order given, is the one returned.
fn check_set(
    shards: &[(Shard, &Path)],
    set: &str,
    same: impl Fn(usize) -> Result<(), ShardError>,
) -> Result<(), ShardError> {
    let Some(&(first, first_dir)) = shards.first() else {
        return Err(ShardError::Mismatch("no shard directory given".into()));
    };
    let count = first.count;
    let mut owner: Vec<Option<&Path>> = vec![None; count];
    for (k, &(shard, dir)) in shards.iter().enumerate() {
        if shard.count != count {
            return Err(ShardError::Mismatch(format!(
                "{} is shard {shard}, {} shard {}/{count}: shards of one {set} have one N",
                dir.display(),
                first_dir.display(),
                first.index
            )));
        }
        same(k)?;
        match owner[shard.index - 1] {
            Some(other) => {
                return Err(ShardError::Mismatch(format!(
                    "shard {shard} is given twice: {} and {}",
                    other.display(),
                    dir.display()
                )));
            }
            None => owner[shard.index - 1] = Some(dir),
        }
    }
    if let Some(missing) = owner.iter().position(Option::is_none) {
        return Err(ShardError::Mismatch(format!(
            "shard {}/{count} is missing: merge needs the directory of every shard",
            missing + 1
        )));
    }
    Ok(())
}

/// A summary with what differs between the shards of one run left out:
/// their own counts, clocks and machines.
fn identity(summary: &Summary) -> serde_json::Value {
    let mut v = serde_json::to_value(summary).unwrap_or_default();
    if let Some(map) = v.as_object_mut() {
        for key in [
            "run_unix_time",
            "per_angle",
            "composite_nodes",
            "composite_area_mm2",
            "blind_spots_met",
            "memory_estimate_mib",
            "peak_rss_mib",
            "sample_check",
            "threads",
            "timings",
            "warnings",
        ] {
            map.remove(key);
        }
        if let Some(files) = map.get_mut("files").and_then(|f| f.as_array_mut()) {
            for f in files.iter_mut().filter_map(|f| f.as_object_mut()) {
                f.remove("colliding_nodes");
                f.remove("colliding_area_mm2");
            }
        }
    }
    v
}

/// What differs between two shards' sample checks of what the merged
/// summary states of the whole run's (whether it ran, its starts, seed and
/// tolerance); `None` when they agree. Their figures and angles are each
/// shard's own.
fn check_difference(a: Option<&SampleCheck>, b: Option<&SampleCheck>) -> Option<&'static str> {
    let (a, b) = match (a, b) {
        (None, None) => return None,
        (Some(a), Some(b)) => (a, b),
        _ => return Some("presence"),
    };
    [
        ("status", a.status == b.status),
        (
            "starts",
            a.starts == b.starts && a.start_positions == b.start_positions,
        ),
        ("seed", a.seed == b.seed),
        (
            "tolerance",
            a.tolerance_mm.to_bits() == b.tolerance_mm.to_bits(),
        ),
    ]
    .into_iter()
    .find(|(_, same)| !same)
    .map(|(what, _)| what)
}

/// The first top-level key whose value differs between `a` and `b`.
fn first_difference(a: &serde_json::Value, b: &serde_json::Value) -> Option<String> {
    let (a, b) = (a.as_object()?, b.as_object()?);
    a.keys()
        .chain(b.keys())
        .find(|k| a.get(*k) != b.get(*k))
        .cloned()
}

fn hex_sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Appends `bits` packed eight to a byte, the first in the lowest bit.
fn pack_bits(out: &mut Vec<u8>, bits: impl Iterator<Item = bool>) {
    let mut byte = 0u8;
    let mut k = 0;
    for bit in bits {
        byte |= u8::from(bit) << (k % 8);
        k += 1;
        if k % 8 == 0 {
            out.push(byte);
            byte = 0;
        }
    }
    if k % 8 != 0 {
        out.push(byte);
    }
}

fn unpack_bits(bytes: &[u8], n: usize) -> impl Iterator<Item = bool> + '_ {
    (0..n).map(move |k| bytes[k / 8] >> (k % 8) & 1 == 1)
}

/// The length of a header: magic, nx, nz, i0, j0, pitch, files flag,
/// blind spot count.
const HEADER_LEN: usize = 16 + 5 * 8 + 1 + 8;
/// Per blind spot: i, j and six f64.
const BLIND_LEN: usize = 8 * 8;

/// An analysis shard's `shard.json` checked as [`merge`] checks it before
/// it reads `shard.bin` (its own digest, its fields, its summary's bounds
/// and its angle indices); the reason when it fails. [`merge`] and the
/// fuzz targets call it.
pub fn check_record(text: &[u8]) -> Result<ShardRecord, String> {
    let record: ShardRecord = unsealed_json(text).and_then(|v| {
        serde_json::from_value(v).map_err(|e| format!("not a kneeform shard.json: {e}"))
    })?;
    if record.format != FORMAT {
        return Err(format!(
            "shard format {}, this kneeform reads {FORMAT}",
            record.format
        ));
    }
    // The summary is bounded as a run's is; then the indices by it.
    let summary_text = serde_json::to_string(&record.summary).unwrap_or_default();
    Summary::from_json(&summary_text).map_err(|e| e.to_string())?;
    let angles = record.summary.angles_deg.len();
    let shard = record.shard;
    if shard.count > crate::limits::MAX_ANGLES || !shard.holds(angles, &record.angle_indices) {
        return Err(format!(
            "shard {}/{} of {angles} angles does not hold angles {:?}",
            shard.index, shard.count, record.angle_indices
        ));
    }
    Ok(record)
}

/// `text` with its `record_sha256` made its content's again: a mutated
/// shard.json that still parses, sealed, so that a fuzzer reaches the
/// checks past the digest.
pub fn reseal(text: &[u8]) -> Option<Vec<u8>> {
    let value: serde_json::Value = serde_json::from_slice(text).ok()?;
    Some(sealed_json(value).into_bytes())
}

/// The error of reading `path`.
pub(crate) fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> ShardError {
    let path = path.to_path_buf();
    move |source| ShardError::Io { path, source }
}

/// A shard directory's `shard.json`, read within its bound and checked
/// by `check` (a reason when it fails, reported against the file).
pub(crate) fn read_record<R>(
    dir: &Path,
    check: impl FnOnce(&[u8]) -> Result<R, String>,
) -> Result<R, ShardError> {
    let path = dir.join("shard.json");
    let text = crate::limits::read_bounded(&path, crate::limits::MAX_RUN_JSON_BYTES)
        .map_err(io_error(&path))?;
    check(&text).map_err(|reason| ShardError::Corrupt { path, reason })
}

fn read_shard(dir: &Path) -> Result<ShardFiles, ShardError> {
    let io = io_error;
    let record = read_record(dir, check_record)?;
    let bin_path = dir.join("shard.bin");
    let header = {
        let mut head = [0u8; HEADER_LEN];
        use std::io::Read;
        crate::limits::regular_file(&bin_path)
            .and_then(|()| std::fs::File::open(&bin_path))
            .and_then(|mut f| f.read_exact(&mut head))
            .map_err(io(&bin_path))?;
        parse_header(&head).ok_or_else(|| ShardError::Corrupt {
            path: bin_path.clone(),
            reason: "not a kneeform shard.bin (its header)".into(),
        })?
    };
    let n = header.spec.len();
    let expected = expected_len(&header, record.angle_indices.len());
    let bin = crate::limits::read_bounded(&bin_path, expected as u64).map_err(io(&bin_path))?;
    let bad_bin = |reason: &str| ShardError::Corrupt {
        path: bin_path.clone(),
        reason: reason.into(),
    };
    if bin.len() != expected {
        return Err(bad_bin("its length is not what its header says"));
    }
    if hex_sha256(&bin) != record.data_sha256 {
        return Err(bad_bin("its SHA-256 is not the one shard.json records"));
    }
    let summary = &record.summary;
    let origin_ok = grid_matches(summary, &header.spec);
    // An assembly's shards hold its files per node, and only its.
    if !origin_ok || header.has_files == summary.files.is_empty() {
        return Err(bad_bin("its grid is not the one shard.json describes"));
    }
    let common_end =
        HEADER_LEN + n * (8 + if header.has_files { 4 } else { 0 }) + header.blind * BLIND_LEN;
    Ok(ShardFiles {
        dir: dir.to_path_buf(),
        record,
        bin,
        common_end,
        header,
    })
}

fn parse_header(head: &[u8; HEADER_LEN]) -> Option<Header> {
    if &head[..16] != MAGIC {
        return None;
    }
    let u = |k: usize| u64::from_le_bytes(head[16 + 8 * k..24 + 8 * k].try_into().expect("8"));
    let (nx, nz) = (usize::try_from(u(0)).ok()?, usize::try_from(u(1)).ok()?);
    let (i_origin, j_origin) = (u(2) as i64, u(3) as i64);
    let pitch = f64::from_bits(u(4));
    let has_files = match head[56] {
        0 => false,
        1 => true,
        _ => return None,
    };
    let blind = usize::try_from(u64::from_le_bytes(head[57..65].try_into().expect("8"))).ok()?;
    let nodes = nx.checked_mul(nz)?;
    let pitch_ok = (crate::limits::MIN_PITCH_MM..=crate::limits::MAX_PITCH_MM).contains(&pitch);
    if !(1..=crate::limits::MAX_GRID_NODES).contains(&nodes) || blind > nodes || !pitch_ok {
        return None;
    }
    Some(Header {
        spec: GridSpec {
            pitch,
            i_origin,
            j_origin,
            nx,
            nz,
        },
        has_files,
        blind,
    })
}

/// The length of a `shard.bin` of `header` holding `angles` angles (at
/// most 2^30 nodes and 3601 angles: no overflow).
fn expected_len(header: &Header, angles: usize) -> usize {
    let n = header.spec.len();
    let per_node = 8 + if header.has_files { 4 } else { 0 };
    let per_angle = 16 + n.div_ceil(8) + header.blind.div_ceil(8);
    HEADER_LEN + n * per_node + header.blind * BLIND_LEN + 8 + angles * per_angle
}

/// Whether the summary's grid is `spec` (the summary's origin is
/// `pitch * index`, written by the same arithmetic).
fn grid_matches(summary: &Summary, spec: &GridSpec) -> bool {
    summary.grid_size == [spec.nx, spec.nz]
        && summary.pitch_mm.to_bits() == spec.pitch.to_bits()
        && summary.grid_origin[0].to_bits() == spec.x(0).to_bits()
        && summary.grid_origin[1].to_bits() == spec.z(0).to_bits()
}

impl ShardFiles {
    fn corrupt(&self, reason: String) -> ShardError {
        ShardError::Corrupt {
            path: self.dir.join("shard.bin"),
            reason,
        }
    }

    /// The grid, an assembly's files per node and the blind spots.
    fn common(&self, n: usize) -> Result<Common, ShardError> {
        let mut at = HEADER_LEN;
        let word = |k: usize| u64::from_le_bytes(self.bin[k..k + 8].try_into().expect("8"));
        let h: Vec<f64> = (0..n).map(|k| f64::from_bits(word(at + 8 * k))).collect();
        at += 8 * n;
        let node_file = self.header.has_files.then(|| {
            (0..n)
                .map(|k| {
                    let p = at + 4 * k;
                    u32::from_le_bytes(self.bin[p..p + 4].try_into().expect("4"))
                })
                .collect::<Vec<u32>>()
        });
        if node_file.is_some() {
            at += 4 * n;
        }
        let spec = self.header.spec;
        let mut blind = Vec::with_capacity(self.header.blind);
        for _ in 0..self.header.blind {
            let f = |k: usize| f64::from_bits(word(at + 16 + 8 * k));
            let (i, j) = (word(at) as usize, word(at + 8) as usize);
            if i + 1 >= spec.nx || j + 1 >= spec.nz {
                return Err(
                    self.corrupt(format!("blind spot ({i}, {j}) is not a cell of the grid"))
                );
            }
            blind.push(BlindSpot {
                i,
                j,
                x: f(0),
                z: f(1),
                depth_missed_mm: f(2),
                width_mm: f(3),
                resolving_pitch_mm: f(4),
                y: f(5),
                met_angles_deg: Vec::new(),
            });
            at += BLIND_LEN;
        }
        debug_assert_eq!(at, self.common_end);
        Ok(Common {
            grid: HeightGrid { spec, h },
            node_file,
            blind_spots: blind,
        })
    }

    /// The shard's angles, decoded.
    fn angles(&self, n: usize) -> Result<Vec<ShardAngle>, ShardError> {
        let word = |k: usize| u64::from_le_bytes(self.bin[k..k + 8].try_into().expect("8"));
        let mut at = self.common_end;
        let count = word(at) as usize;
        at += 8;
        if count != self.record.angle_indices.len() {
            return Err(self.corrupt("its angle count is not shard.json's".into()));
        }
        let mut out = Vec::with_capacity(count);
        for &expected in &self.record.angle_indices {
            let (a, placed) = (word(at) as usize, word(at + 8) as usize);
            at += 16;
            if a != expected {
                return Err(self.corrupt(format!("angle {a} where shard.json says {expected}")));
            }
            let mask: Vec<u8> = unpack_bits(&self.bin[at..], n).map(u8::from).collect();
            at += n.div_ceil(8);
            let probes: Vec<bool> = unpack_bits(&self.bin[at..], self.header.blind).collect();
            at += self.header.blind.div_ceil(8);
            out.push(ShardAngle {
                index: a,
                placed,
                mask,
                probes,
            });
        }
        Ok(out)
    }
}

/// Writes the merged results `merged` into the staged directory `out`, as
/// `analyze` writes a run.
pub fn write_merged(
    out: &OutputDir,
    merged: &Merged,
    options: &crate::output::WriteOptions,
) -> Result<Summary, WriteError> {
    let started = std::time::Instant::now();
    crate::output::write_results(
        out,
        &merged.results(),
        merged.summary.clone(),
        options,
        started,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shard_holds_its_indices_checked_without_building_them() {
        let s = Shard { index: 2, count: 3 };
        for items in [3, 4, 7, 100] {
            assert!(s.holds(items, &s.indices(items)), "{items}");
        }
        // More shards than items: no writer writes one.
        assert!(!s.holds(2, &s.indices(2)));
        assert!(s.holds(7, &[1, 4]));
        assert!(!s.holds(7, &[1, 4, 7]), "one too many");
        assert!(!s.holds(7, &[1, 5]), "a wrong index");
        assert!(!s.holds(8, &[1, 4]), "one too few: 7 is the shard's");
        // Numbers no writer would write are refused, never sized.
        let huge = Shard {
            index: 1,
            count: usize::MAX,
        };
        assert!(!huge.holds(7, &[0]));
        assert!(!Shard { index: 0, count: 3 }.holds(7, &[]));
        assert!(!Shard { index: 4, count: 3 }.holds(7, &[]));
        assert!(!Shard { index: 1, count: 1 }.holds(usize::MAX, &[]));
    }

    #[test]
    fn an_edited_record_is_told_by_its_own_digest() {
        let record = serde_json::json!({"format": 2, "area": 0.1, "warnings": ["a", "b"]});
        let text = sealed_json(record);
        assert!(unsealed_json(text.as_bytes()).is_ok());
        for (from, to) in [("0.1", "0.10000000000000002"), ("\"a\",", ""), ("2,", "3,")] {
            let edited = text.replacen(from, to, 1);
            assert_ne!(edited, text, "{from}");
            assert!(
                unsealed_json(edited.as_bytes())
                    .unwrap_err()
                    .contains("edited"),
                "{from}"
            );
        }
        // Whitespace is not content.
        let compact = text.replace("\n  ", "");
        assert!(unsealed_json(compact.as_bytes()).is_ok());
    }

    #[test]
    fn shards_take_every_nth_angle() {
        let s = Shard::parse("2/3").unwrap();
        assert_eq!(s.indices(7), [1, 4]);
        assert_eq!(Shard::parse("1/1").unwrap().indices(3), [0, 1, 2]);
        assert_eq!(Shard::parse("3/3").unwrap().indices(2), Vec::<usize>::new());
        for bad in ["0/3", "4/3", "1", "a/b", "1/0", "-1/2", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn bits_pack_and_unpack() {
        let bits = [true, false, true, true, false, false, false, false, true];
        let mut out = Vec::new();
        pack_bits(&mut out, bits.iter().copied());
        assert_eq!(out, [0b1101, 1]);
        assert_eq!(unpack_bits(&out, 9).collect::<Vec<_>>(), bits);
    }
}
