//! The fuzz targets' bodies, one function per target: the libFuzzer
//! targets (`fuzz_targets/*.rs`, nightly) and the seeded stable run in the
//! test suite (`tests/fuzz_seeded.rs`) both call these, so CI exercises
//! exactly the calls the fuzzer does. Each takes untrusted bytes and must
//! return: an `Err` from the library is a fine answer; a panic, an abort, a
//! hang or a memory blow-up is a bug. Each says whether the library
//! accepted the input, so the seeded run can show that it reaches past the
//! parsers.

use std::path::Path;

use kneeform::Side;
use kneeform::input::read_part_bytes;
use kneeform::scenario;
use kneeform::summary::Summary;

/// The most triangles the fuzzer tessellates per input: a scenario may
/// legitimately ask for up to `scenario::MAX_TRIANGLES` (20 million,
/// gigabytes), which would only measure the allocator; 200 000 keeps each
/// input within milliseconds in a release build.
pub const FUZZ_MAX_TRIANGLES: usize = 200_000;

/// `data` read as an STL part (binary or ASCII); whether it was read.
pub fn stl(data: &[u8]) -> bool {
    read_part_bytes(Path::new("fuzz.stl"), data, 1.0, Side::Left).is_ok()
}

/// `data` parsed as a scenario file and, when it parses into at most
/// `max_triangles` triangles, tessellated (checking the count it
/// announced) and read as a `.toml` part; whether it was read as a part.
pub fn scenario(data: &[u8], max_triangles: usize) -> bool {
    let path = Path::new("fuzz.toml");
    let small = match std::str::from_utf8(data).map(|text| scenario::parse(text, path)) {
        Ok(Ok(file)) => {
            let count = file.triangle_count(None);
            let small = count <= max_triangles;
            if small {
                let triangles = file.triangulate(None);
                assert_eq!(
                    triangles.len(),
                    count,
                    "triangle_count disagrees with triangulate"
                );
            }
            small
        }
        // Not UTF-8, or refused: read_part_bytes must refuse it as well.
        Ok(Err(_)) | Err(_) => true,
    };
    // read_part_bytes tessellates whatever parses, so it only runs where
    // the tessellation above did.
    small && read_part_bytes(path, data, 1.0, Side::Left).is_ok()
}

/// `data` read as a `summary.json` with the checks `kneeform report`
/// relies on ([`Summary::from_json`]) and, when it is accepted, its grid
/// placed the way the report places it; an accepted summary must also
/// read back unchanged from what serde writes for it (the writer and the
/// reader agree). Whether it was accepted.
pub fn summary(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(summary) = Summary::from_json(text) else {
        return false;
    };
    let _ = kneeform::report::grid_spec(&summary);
    let written = serde_json::to_string(&summary).expect("an accepted summary serialises");
    let reread = Summary::from_json(&written).expect("a written summary reads back");
    assert_eq!(
        reread, summary,
        "a summary changed on writing and reading back"
    );
    true
}

/// `data` read as a `--frame @FILE` matrix file; whether it made a frame.
/// An accepted frame maps a point there and back within rounding.
pub fn frame(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(frame) =
        kneeform::frame::Frame::from_matrix_text(text, Path::new("fuzz.txt"), "@fuzz.txt")
    else {
        return false;
    };
    let p = [12.5, -3.0, 400.0];
    let v = frame.to_vehicle(p);
    // A translation near f64's end overflows: the placed-coordinate bound
    // refuses such a part (read_part_placed), so nothing to map back.
    if !v.iter().all(|c| c.is_finite()) {
        return true;
    }
    let back = frame.to_part(v);
    let scale = p
        .iter()
        .chain(&frame.to_vehicle(p))
        .fold(1.0f64, |m, c| m.max(c.abs()));
    assert!(
        back.iter()
            .zip(p)
            .all(|(a, b)| (a - b).abs() <= 1e-6 * scale),
        "a frame does not map back: {p:?} -> {back:?}"
    );
    true
}

/// `data` read as an analysis shard's `shard.json`, resealed (its own
/// SHA-256 made its content's again, so that the checks past it are
/// reached) and checked as `merge` checks it before sizing anything by
/// it; whether it was accepted.
pub fn shard_json(data: &[u8]) -> bool {
    let Some(sealed) = kneeform::shard::reseal(data) else {
        return false;
    };
    kneeform::shard::check_record(&sealed).is_ok()
}

/// `data` read as a `kneeform batch` manifest, its items planned as
/// `batch` plans them (against a directory that does not exist, so that
/// nothing is read or written); whether it was accepted. An accepted
/// manifest's every item has a part and runs `analyze`.
pub fn manifest(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(items) =
        kneeform::manifest::plan(text, Path::new("/nonexistent-kneeform-fuzz"), &|flag| {
            flag == "--report"
        })
    else {
        return false;
    };
    assert!(
        items
            .iter()
            .all(|i| !i.parts.is_empty() && i.argv.first().is_some_and(|a| a == "analyze")),
        "an accepted manifest plans an item without a part"
    );
    true
}

/// The byte that separates a study shard input's `shard.json` from its
/// `shard.bin` (no JSON text holds a raw NUL).
pub const STUDY_SHARD_SEPARATOR: u8 = 0;

/// `data` read as a study shard (`verify` or `converge --shard`): its
/// `shard.json`, a NUL byte, its `shard.bin`. The record's digest of
/// `shard.bin` and its own digest are made the content's again, so that
/// the checks past them are reached, then both files are checked and
/// decoded as `merge` does; whether the shard was accepted.
pub fn study_shard(data: &[u8]) -> bool {
    let (json, bin) = match data.iter().position(|&b| b == STUDY_SHARD_SEPARATOR) {
        Some(k) => (&data[..k], &data[k + 1..]),
        None => (data, &[][..]),
    };
    let Ok(mut value) = serde_json::from_slice::<serde_json::Value>(json) else {
        return false;
    };
    if let Some(map) = value.as_object_mut() {
        map.insert(
            "data_sha256".into(),
            kneeform::input::sha256_hex(bin).into(),
        );
    }
    let Some(sealed) = kneeform::shard::reseal(value.to_string().as_bytes()) else {
        return false;
    };
    let Ok(record) = kneeform::shard::study::check_study_record(&sealed) else {
        return false;
    };
    kneeform::shard::study::check_study_bin(bin, &record).is_ok()
}
