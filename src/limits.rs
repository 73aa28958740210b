//! The bounds every user-given number and every file is held to, in one
//! place, so that no arithmetic on them can wrap, overflow to infinity or
//! end in NaN, and no allocation is asked for that the machine cannot make.
//!
//! Each bound is far beyond any real knee-form inspection (a part is at most
//! a few metres, a pitch at least a few micrometres) and close enough that
//! every derived integer (node indices, grid sizes, byte counts) stays
//! exact in an `f64` and well inside an `i64`/`usize`. A refused value is
//! named with its bound in one line; the few bounds a user could need
//! beyond are set by a flag (`--max-memory`), the others are documented
//! here and in `--help`.

/// The longest deflection window (mm): half the knee-form's default
/// triangle side; a window longer than the knee-form measures a deflection
/// it has long left behind.
pub(crate) const MAX_WINDOW_MM: f64 = 100.0;

/// The most pitches a deflection window may span: each start's slide list
/// under the window rule holds that many columns of its footprint's rows.
pub(crate) const MAX_WINDOW_PITCHES: f64 = 1024.0;

/// The finest pitch (mm): 1 um, a hundredth of the finest pitch any study
/// here needed (0.25 mm).
pub(crate) const MIN_PITCH_MM: f64 = 1e-3;

/// The coarsest pitch (mm): half a metre, coarser than the knee-form.
pub(crate) const MAX_PITCH_MM: f64 = 500.0;

/// The largest knee-form length (triangle side, radius, thickness) and
/// blind-spot depth (mm): 10 m.
pub(crate) const MAX_LENGTH_MM: f64 = 1e4;

/// The largest coordinate a part or grid may have, in absolute value
/// (mm): 10 km (a 2 m part read in micrometres still reads, to be warned
/// of), so that a node index `x / pitch` stays below 1e10 at the finest
/// pitch and is exact as an `f64` and an `i64`.
pub(crate) const MAX_COORD_MM: f64 = 1e7;

/// The largest file-units-to-mm factor (`--scale`), and the inverse of the
/// smallest: 1e6 (from km to mm, from nm to mm).
pub(crate) const MAX_SCALE: f64 = 1e6;

/// The most knee-form angles in one run: every twentieth of a degree over
/// +-90, far more than the regulation's 61 whole degrees.
pub const MAX_ANGLES: usize = 3601;

/// The most nodes a grid may have, whatever the memory allowed: 2^30, a
/// 33 m x 33 m part at 1 mm or 1 m x 1 m at 0.03 mm. Beyond it, node
/// counts times bytes per node no longer fit a machine of today.
pub(crate) const MAX_GRID_NODES: usize = 1 << 30;

/// The most worker threads (`--threads`): more than any machine of today
/// has CPUs, and few enough to start in a blink.
pub const MAX_THREADS: usize = 1024;

/// The largest part file read (bytes): 8 GiB, a binary STL of 170 million
/// triangles. Checked on the file's size before reading, and on the bytes
/// read for what is not a regular file (a pipe, `/dev/zero`).
pub const MAX_PART_FILE_BYTES: u64 = 8 << 30;

/// The most bytes read from a part that is not a regular file (a pipe,
/// `/dev/stdin`), whose size cannot be known before reading: 1 GiB, a
/// binary STL of 21 million triangles. Save a larger part to a file.
pub(crate) const MAX_STREAM_BYTES: u64 = 1 << 30;

/// The most triangles a part may have: 170 million, the binary STL that
/// fills [`MAX_PART_FILE_BYTES`]; 460 times the paper's console.
pub(crate) const MAX_PART_TRIANGLES: usize = 170_000_000;

/// The largest `summary.json` (or other run JSON file) read: 64 MiB; the
/// paper workload's is 12 KB.
pub(crate) const MAX_RUN_JSON_BYTES: u64 = 64 << 20;

/// The largest run table or figure read back by `report`
/// (`verify.csv`, `converge.csv`, a PNG): 1 GiB.
pub(crate) const MAX_RUN_TABLE_BYTES: u64 = 1 << 30;

/// Refuses what is not a regular file (a FIFO, on which opening waits
/// for a writer for ever; a device such as `/dev/zero`; a directory)
/// before it is opened: `ErrorKind::InvalidInput`, "not a regular file"
/// (`IsADirectory` for a directory).
pub(crate) fn regular_file(path: &std::path::Path) -> std::io::Result<()> {
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "is a directory",
        ));
    }
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a pipe or a device): save it to a file first",
        ));
    }
    Ok(())
}

/// Refuses a device (`/dev/zero`, a disk) or a socket before it is
/// opened: what a part may not be. A part may be a pipe (`/dev/stdin`),
/// read as a stream.
pub(crate) fn not_a_device(path: &std::path::Path) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = std::fs::metadata(path)?.file_type();
        if kind.is_char_device() || kind.is_block_device() || kind.is_socket() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file (a device): a part is a file, or a pipe",
            ));
        }
    }
    #[cfg(not(unix))]
    let _ = path;
    Ok(())
}

/// Reads the regular file at `path` whole, refusing one longer than
/// `max_bytes` by its size, before reading anything, and anything that is
/// not a regular file before opening it (`regular_file`).
pub fn read_bounded(path: &std::path::Path, max_bytes: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    regular_file(path)?;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    let too_long = |what: String| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{what}, more than the {max_bytes} bytes read at most"),
        )
    };
    if meta.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "is a directory",
        ));
    }
    if meta.is_file() && meta.len() > max_bytes {
        return Err(too_long(format!("{} bytes", meta.len())));
    }
    let mut bytes = Vec::new();
    file.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_long("not a regular file and longer".into()));
    }
    Ok(bytes)
}

/// The largest text file read whole (bytes): a manifest, a frame's
/// matrix, a scenario, a batch item's fingerprint; far beyond any such
/// file, short of the memory `/dev/zero` given as one would take.
pub(crate) const MAX_TEXT_FILE_BYTES: u64 = 16 << 20;

/// The text of the file at `path`, at most `MAX_TEXT_FILE_BYTES` long
/// ([`read_bounded`]), as UTF-8.
pub fn read_text_bounded(path: &std::path::Path) -> std::io::Result<String> {
    let bytes = read_bounded(path, MAX_TEXT_FILE_BYTES)?;
    String::from_utf8(bytes).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// The file at `path` opened for streaming, when it is a regular file of
/// at most `max_bytes` (a link to `/dev/zero` would be read for ever).
pub(crate) fn open_bounded(
    path: &std::path::Path,
    max_bytes: u64,
) -> std::io::Result<std::fs::File> {
    regular_file(path)?;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "not a regular file",
        ));
    }
    if meta.len() > max_bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "{} bytes, more than the {max_bytes} bytes read at most",
                meta.len()
            ),
        ));
    }
    Ok(file)
}

/// `len` copies of `value`, or an error where the allocation fails,
/// rather than the abort of `vec![value; len]`: for buffers sized by a
/// file or a user's number.
pub(crate) fn try_filled<T: Clone>(len: usize, value: T) -> Result<Vec<T>, OutOfMemory> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| OutOfMemory {
        bytes: len.saturating_mul(std::mem::size_of::<T>()),
    })?;
    v.resize(len, value);
    Ok(v)
}

/// An allocation the machine refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cannot allocate {:.2} GiB", *bytes as f64 / f64::from(1u32 << 30))]
pub struct OutOfMemory {
    /// The bytes asked for.
    pub bytes: usize,
}

/// `seconds` as a clock reading: `1h02m03s`, `2m03s` or `3s`.
pub fn duration_words(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match (s / 3600, s / 60 % 60, s % 60) {
        (0, 0, s) => format!("{s}s"),
        (0, m, s) => format!("{m}m{s:02}s"),
        (h, m, s) => format!("{h}h{m:02}m{s:02}s"),
    }
}

/// A number given by the user, echoed (in a message or a file) exactly
/// but briefly: its shortest round-trip decimal, in exponent form beyond
/// 1e-6 .. 1e15 (`1e-320`, not its 330 digits; `-1e300`, not 301).
pub fn echo(value: f64) -> String {
    let a = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-6..1e15).contains(&a) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// A number for a message: short, whatever its size (`1e-300`, not three
/// hundred digits; `0.25`, not `2.5e-1`).
pub fn short(value: f64) -> String {
    let a = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-4..1e7).contains(&a) {
        let s = format!("{value:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s.is_empty() || s == "-" || s == "-0" {
            "0".into()
        } else {
            s.into()
        }
    } else {
        format!("{value:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn echoed_numbers_are_exact_and_brief() {
        for (v, text) in [
            (1e-320, "1e-320"),
            (-1e300, "-1e300"),
            (299.5, "299.5"),
            (290.0, "290"),
            (0.0, "0"),
        ] {
            assert_eq!(echo(v), text);
            assert_eq!(echo(v).parse::<f64>().unwrap(), v);
        }
    }

    #[test]
    fn short_numbers_stay_short() {
        assert_eq!(short(1e-300), "1e-300");
        assert_eq!(short(1e300), "1e300");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(-3.0), "-3");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(f64::NAN), "NaN");
        assert_eq!(short(f64::NEG_INFINITY), "-inf");
        assert_eq!(short(1.24), "1.24");
    }

    #[test]
    fn the_finest_grid_indices_are_exact() {
        let index = MAX_COORD_MM / MIN_PITCH_MM;
        assert!(index < 2f64.powi(52));
        assert!((MAX_GRID_NODES as f64) < 2f64.powi(52));
    }
}
