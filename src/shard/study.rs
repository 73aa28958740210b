//! The files of a study's shard: `verify --shard K/N` and `converge
//! --shard K/N` (with `--approach direct` too) write one
//! [`crate::harness::StudyPart`] as `shard.json` and `shard.bin`;
//! [`merge_study`] reads N of them, checks that they are every shard of
//! one study exactly once, and merges them (the harness's one merge, which
//! the unsharded study goes through too).
//!
//! * `shard.json` ([`StudyRecord`]): which shard of how many, the study's
//!   start count and this shard's start indices, the options
//!   (`StudySettings`), the study's `verify.json` or `converge.json` as
//!   the shard knows it (`"study": {"kind": "verify", "summary": ...}`;
//!   kinds `verify`, `converge`, `verify-direct`, `converge-direct`:
//!   the part's SHA-256, every parameter and the shard's own timings; no
//!   statistics, fits or verdict, which are the merge's),
//!   its clock readings, and the SHA-256 of `shard.bin` and of its common
//!   part;
//! * `shard.bin`, little-endian: the common part (the grid the starts are
//!   nodes of, the angles, every start of the study as f64 bits), then per
//!   pitch its tie band and timings and, per start-angle pair of the
//!   shard (angle-major), the pair's status, node, every metric value and
//!   point its comparison holds, the grid's colliding nodes and the exact
//!   strikes snapped to nodes: all a comparison is assembled from (a
//!   direct study's: its row's status, levels, contact and counts, and
//!   whether the engine's level differed; its tie band is zero).
//!
//! Every value is stored as its bits, so a merge sees exactly what the
//! shard computed.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{
    Shard, ShardDir, ShardError, first_difference, hex_sha256, io_error, read_record, read_set,
};
use crate::frame::Approach;
use crate::grid::GridSpec;
use crate::harness::codec::{Reader, put_f64, put_f64s, put_points, put_u64};
use crate::harness::metrics::TieBand;
use crate::harness::pairs::PitchPart;
use crate::harness::sharded::{StudyKind, StudySettings, StudySummary};
use crate::harness::{Study, StudyPart, studies_of, study_named};
use crate::output::{OutputDir, WriteError};

/// `shard.json` of a study's shard.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyRecord {
    /// The format of the shard's files (`FORMAT`; 5: pairs carry their
    /// miss at half and at a quarter of the pitch and the points they set
    /// apart; 6: and their undecided contacts, as points and as nodes; 7:
    /// each pitch, per angle, the analysis's struck nodes nearest to its exact
    /// strikes).
    pub format: u32,
    /// Which shard of how many.
    pub shard: Shard,
    /// The study's starts, all shards together.
    pub starts: usize,
    /// This shard's starts: indices into the study's.
    pub start_indices: Vec<usize>,
    /// The options every shard of the study shares.
    pub settings: StudySettings,
    /// The study's summary as the shard knows it, and its kind.
    #[serde(deserialize_with = "summary_of_its_kind")]
    pub study: StudySummary,
    /// Seconds sampling the grid.
    pub sample_s: f64,
    /// Seconds of the oracle on this shard's starts.
    pub oracle_s: f64,
    /// SHA-256 of `shard.bin` (hex).
    pub data_sha256: String,
    /// SHA-256 of `shard.bin`'s common part: grid, angles, starts.
    pub common_sha256: String,
    /// SHA-256 of this record's own content, keys sorted, compact JSON,
    /// this field left out.
    #[serde(default)]
    pub record_sha256: String,
}

/// The format [`write_study_shard`] writes and [`merge_study`] reads.
pub(crate) const FORMAT: u32 = 7;

const MAGIC: &[u8; 16] = b"kneeform study 7";

/// The largest `shard.bin` read (bytes): far beyond a study's (a few
/// hundred bytes per start and angle), short of exhausting memory.
const MAX_BIN_BYTES: u64 = 8 << 30;

/// Writes `part` as its shard: `shard.json` and `shard.bin` in the staged
/// directory `out`.
pub fn write_study_shard(out: &OutputDir, part: &StudyPart) -> Result<(), WriteError> {
    let mut bin = Vec::new();
    bin.extend_from_slice(MAGIC);
    let spec = part.spec;
    put_u64(&mut bin, spec.nx as u64);
    put_u64(&mut bin, spec.nz as u64);
    put_u64(&mut bin, spec.i_origin as u64);
    put_u64(&mut bin, spec.j_origin as u64);
    put_f64(&mut bin, spec.pitch);
    put_f64s(&mut bin, &part.angles_deg);
    put_points(&mut bin, &part.starts);
    let common_sha256 = hex_sha256(&bin);
    put_u64(&mut bin, part.pitches.len() as u64);
    for p in &part.pitches {
        for v in [p.pitch, p.band.sigma, p.band.m, p.grid_s, p.seconds] {
            put_f64(&mut bin, v);
        }
        put_u64(&mut bin, p.nodes as u64);
        put_u64(&mut bin, p.covering.len() as u64);
        for points in &p.covering {
            put_points(&mut bin, points);
        }
        put_u64(&mut bin, p.pairs.len() as u64);
        p.pairs.put(&mut bin);
    }
    let record = StudyRecord {
        format: FORMAT,
        shard: part.shard,
        starts: part.starts.len(),
        start_indices: part.shard.indices(part.starts.len()),
        settings: part.settings.clone(),
        study: part.summary.clone(),
        sample_s: part.sample_s,
        oracle_s: part.oracle_s,
        data_sha256: hex_sha256(&bin),
        common_sha256,
        record_sha256: String::new(),
    };
    let path = out.path("shard.bin");
    std::fs::write(&path, &bin).map_err(WriteError::at(&path))?;
    let path = out.path("shard.json");
    std::fs::write(&path, super::sealed_json(to_json(&record))).map_err(WriteError::at(&path))
}

/// What a shard directory holds, by its `shard.json`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardKind {
    /// An analysis's (`analyze --shard`).
    Analysis,
    /// A study's (`verify --shard`, `converge --shard`, either approach),
    /// in words.
    Study(&'static str),
}

impl std::fmt::Display for ShardKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ShardKind::Analysis => "an analysis (analyze --shard)",
            ShardKind::Study(words) => words,
        })
    }
}

/// The kind of the shard in `dir`, from its `shard.json`.
pub fn shard_kind(dir: &Path) -> Result<ShardKind, ShardError> {
    let path = dir.join("shard.json");
    let text = crate::limits::read_bounded(&path, crate::limits::MAX_RUN_JSON_BYTES).map_err(
        |source| ShardError::Io {
            path: path.clone(),
            source,
        },
    )?;
    let value: serde_json::Value =
        serde_json::from_slice(&text).map_err(|e| ShardError::Corrupt {
            path: path.clone(),
            reason: format!("not a kneeform shard.json: {e}"),
        })?;
    let Some(kind) = value.get("study").map(|s| s.get("kind")) else {
        return Ok(ShardKind::Analysis);
    };
    match kind.and_then(|k| study_named(k.as_str()?)) {
        Some((approach, kind)) => Ok(ShardKind::Study(studies_of(approach).shard_words(kind))),
        None => Err(ShardError::Corrupt {
            path,
            reason: format!("a study of unknown kind {kind:?}"),
        }),
    }
}

/// One study shard directory, read, checked and decoded.
struct StudyFiles {
    dir: PathBuf,
    record: StudyRecord,
    part: StudyPart,
}

impl ShardDir for StudyFiles {
    fn shard(&self) -> Shard {
        self.record.shard
    }
    fn dir(&self) -> &Path {
        &self.dir
    }
}

/// Reads the study shard directories `dirs` (one per shard, in any
/// order) and merges them into the whole study, as the unsharded command
/// computes it (clock readings aside).
pub fn merge_study(dirs: &[PathBuf]) -> Result<Study, ShardError> {
    let first_identity = std::cell::OnceCell::new();
    let shards = read_set(
        dirs,
        "study",
        read_study,
        |first, s| match first_difference(
            first_identity.get_or_init(|| identity(&first.record)),
            &identity(&s.record),
        ) {
            Some(key) => Err(ShardError::Mismatch(format!(
                "{} and {} are shards of different studies (their `{key}` differ)",
                first.dir.display(),
                s.dir.display()
            ))),
            None => Ok(()),
        },
    )?;
    // In shard order: shard K's share is parts[K - 1].
    let mut shards = shards;
    shards.sort_by_key(|s| s.record.shard.index);
    let parts: Vec<StudyPart> = shards.into_iter().map(|s| s.part).collect();
    let merged = crate::harness::study::merge(parts);
    merged.ok_or_else(|| ShardError::Mismatch("the shards hold no study".into()))
}

/// The fields of a study's summary that a merge computes from every
/// shard's pairs (statistics, fits, the verdict), with their values for a
/// study of no start: a shard's `shard.json` leaves them out, since a
/// shard's own would describe a part of the starts only (and could be
/// infinite, which JSON cannot hold).
fn merged_fields(
    approach: Approach,
    kind: StudyKind,
) -> serde_json::Map<String, serde_json::Value> {
    match studies_of(approach).merged_fields(kind) {
        serde_json::Value::Object(fields) => fields,
        _ => serde_json::Map::new(),
    }
}

/// `record` as `shard.json` holds it: without [`merged_fields`].
fn to_json(record: &StudyRecord) -> serde_json::Value {
    let mut v = serde_json::to_value(record).unwrap_or_default();
    if let Some(summary) = v
        .pointer_mut("/study/summary")
        .and_then(|s| s.as_object_mut())
    {
        for key in merged_fields(record.study.approach, record.study.kind).keys() {
            summary.remove(key);
        }
    }
    v
}

/// `shard.json`'s record, its [`merged_fields`] set to those of a study
/// of no start (the merge sets them from every shard's pairs).
fn from_json(text: &[u8]) -> Result<StudyRecord, String> {
    let v = super::unsealed_json(text)?;
    serde_json::from_value(v).map_err(|e| e.to_string())
}

/// `shard.json`'s `study`: `{"kind": ..., "summary": ...}`, read as the
/// approach whose study the kind names reads it, its merged fields set to
/// those of a study of no start.
fn summary_of_its_kind<'de, D: serde::Deserializer<'de>>(d: D) -> Result<StudySummary, D::Error> {
    use serde::de::Error;
    let mut study = serde_json::Value::deserialize(d)?;
    let word = study.get("kind").and_then(|k| k.as_str()).unwrap_or("");
    let (approach, kind) = study_named(word)
        .ok_or_else(|| D::Error::custom(format!("a study of unknown kind {word:?}")))?;
    let mut summary = study
        .get_mut("summary")
        .map(serde_json::Value::take)
        .ok_or_else(|| D::Error::missing_field("summary"))?;
    if let Some(fields) = summary.as_object_mut() {
        for (key, value) in merged_fields(approach, kind) {
            fields.entry(key).or_insert(value);
        }
    }
    let studies = studies_of(approach);
    let known = studies
        .summary_from_json(kind, summary)
        .map_err(D::Error::custom)?;
    Ok(StudySummary {
        approach,
        kind,
        word: studies.kind_word(kind),
        known,
    })
}

/// What the shards of one study share: the record with its own counts,
/// statistics, clocks and checksum of its data left out.
fn identity(record: &StudyRecord) -> serde_json::Value {
    let mut v = serde_json::to_value(record).unwrap_or_default();
    let study = &record.study;
    let mut derived: Vec<String> = merged_fields(study.approach, study.kind)
        .keys()
        .cloned()
        .collect();
    // The shard's own clock readings.
    let clocks = studies_of(study.approach).clock_fields(study.kind);
    derived.extend(clocks.iter().map(|k| k.to_string()));
    let mut out = serde_json::Map::new();
    if let Some(map) = v.as_object_mut() {
        for key in [
            "shard",
            "start_indices",
            "sample_s",
            "oracle_s",
            "data_sha256",
            "record_sha256",
        ] {
            map.remove(key);
        }
        let study = map.remove("study").unwrap_or_default();
        let mut summary = study.get("summary").cloned().unwrap_or_default();
        if let Some(s) = summary.as_object_mut() {
            for key in &derived {
                s.remove(key);
            }
            // Keyed by the summary's own names, so that a mismatch names
            // the option that differs.
            out.extend(s.clone());
        }
        out.insert(
            "kind".into(),
            study.get("kind").cloned().unwrap_or_default(),
        );
        out.extend(map.clone());
    }
    serde_json::Value::Object(out)
}

fn read_study(dir: &Path) -> Result<StudyFiles, ShardError> {
    let record = read_record(dir, check_study_record)?;
    let bin_path = dir.join("shard.bin");
    let bin = crate::limits::read_bounded(&bin_path, MAX_BIN_BYTES).map_err(io_error(&bin_path))?;
    let part = check_study_bin(&bin, &record).map_err(|reason| ShardError::Corrupt {
        path: bin_path.clone(),
        reason,
    })?;
    Ok(StudyFiles {
        dir: dir.to_path_buf(),
        record,
        part,
    })
}

/// A study shard's `shard.json` checked as [`merge_study`] checks it
/// before it reads `shard.bin` (its own digest, its fields, its format,
/// its start count and indices, bounded before they size anything); the
/// reason when it fails. [`merge_study`] and the fuzz targets call it.
pub fn check_study_record(text: &[u8]) -> Result<StudyRecord, String> {
    let record = from_json(text).map_err(|e| format!("a study shard.json: {e}"))?;
    if record.format != FORMAT {
        return Err(format!(
            "study shard format {}, this kneeform reads {FORMAT}",
            record.format
        ));
    }
    let shard = record.shard;
    if record.starts > crate::limits::MAX_GRID_NODES
        || !shard.holds(record.starts, &record.start_indices)
    {
        return Err(format!(
            "shard {}/{} of {} starts does not hold starts {:?}",
            shard.index, shard.count, record.starts, record.start_indices
        ));
    }
    Ok(record)
}

/// A study shard's `shard.bin` checked against its checked `record`
/// (its SHA-256, then every value it holds) and decoded; the reason when
/// it fails. [`merge_study`] and the fuzz targets call it.
pub fn check_study_bin(bin: &[u8], record: &StudyRecord) -> Result<StudyPart, String> {
    if hex_sha256(bin) != record.data_sha256 {
        return Err("its SHA-256 is not the one shard.json records".into());
    }
    decode(bin, record)
}

/// The study part `bin` holds, checked against its `record`.
fn decode(bin: &[u8], record: &StudyRecord) -> Result<StudyPart, String> {
    let mut r = Reader::new(bin);
    if r.take(16)? != MAGIC {
        return Err("not a kneeform study shard.bin (its header)".into());
    }
    let (nx, nz) = (r.len()?, r.len()?);
    let (i_origin, j_origin) = (r.u64()? as i64, r.u64()? as i64);
    let pitch = r.f64()?;
    let spec = GridSpec {
        pitch,
        i_origin,
        j_origin,
        nx,
        nz,
    };
    let angles_deg = r.f64s()?;
    let starts = r.points()?;
    if hex_sha256(&bin[..r.at]) != record.common_sha256 {
        return Err("its common part's SHA-256 is not the one shard.json records".into());
    }
    let (summary_angles, summary_pitches) = record.study.known.angles_and_pitches();
    let studies = studies_of(record.study.approach);
    let same = |a: &[f64], b: &[f64]| {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    };
    if starts.len() != record.starts
        || !same(&angles_deg, summary_angles)
        || !same(&summary_pitches, &record.settings.pitches_mm)
        || summary_pitches.first().map(|p| p.to_bits()) != Some(pitch.to_bits())
    {
        return Err("its grid, angles or starts are not the ones shard.json describes".into());
    }
    let share = record.start_indices.len();
    let expected_pairs = share * angles_deg.len();
    let pitch_count = r.len()?;
    if pitch_count != summary_pitches.len() {
        return Err(format!(
            "{pitch_count} pitches where shard.json names {}",
            summary_pitches.len()
        ));
    }
    let mut pitches = Vec::with_capacity(pitch_count);
    for &expected in &summary_pitches {
        let p = r.f64()?;
        let band = TieBand {
            sigma: r.f64()?,
            m: r.f64()?,
            pitch: p,
        };
        let (grid_s, seconds) = (r.f64()?, r.f64()?);
        let nodes = r.len()?;
        let angles = r.len()?;
        if angles != 0 && angles != angles_deg.len() {
            return Err(format!(
                "pitch {p} mm holds covering nodes of {angles} angles where shard.json names {}",
                angles_deg.len()
            ));
        }
        let covering = (0..angles)
            .map(|_| r.points())
            .collect::<Result<Vec<_>, _>>()?;
        let count = r.len()?;
        if p.to_bits() != expected.to_bits() || count != expected_pairs {
            return Err(format!(
                "pitch {p} mm holds {count} start-angle pairs where shard.json says {expected} mm and {expected_pairs}"
            ));
        }
        // Pair k: the share's start k % share at angle k / share.
        let at = |k: usize| {
            let s = record.start_indices[k % share.max(1)];
            (starts[s], angles_deg[k / share.max(1)])
        };
        let pairs = studies.read_pairs(&mut r, count, &at)?;
        pitches.push(PitchPart {
            pitch: p,
            pairs,
            band,
            grid_s,
            seconds,
            nodes,
            covering,
        });
    }
    if r.at != bin.len() {
        return Err("it holds more than its header says".into());
    }
    Ok(StudyPart {
        shard: record.shard,
        spec,
        starts,
        angles_deg,
        pitches,
        settings: record.settings.clone(),
        summary: record.study.clone(),
        sample_s: record.sample_s,
        oracle_s: record.oracle_s,
    })
}
