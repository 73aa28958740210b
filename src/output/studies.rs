//! A study's result files, for either study and approach
//! ([`write_study`]; [`write_study_files`] into a staged directory, for a
//! merge of its shards): a verification's, a convergence study's, and the
//! same two for the direct approach. Built with the `harness` feature.

use std::path::Path;

use super::results::write_json;
use super::{OutputDir, WriteError};
use crate::harness::{Convergence, DirectConvergence, DirectVerification, Study, Verification};

/// Writes `study`'s files into `dir`, which appears with all of them or is
/// left as it was.
pub fn write_study(dir: &Path, study: &Study) -> Result<(), WriteError> {
    staged(dir, |out| write_study_files(out, study))
}

/// Writes [`write_study`]'s files into the staged directory `out`
/// (`kneeform merge` of a study's shards).
pub fn write_study_files(out: &OutputDir, study: &Study) -> Result<(), WriteError> {
    match study {
        Study::Verify(v) => write_verification_files(out, v),
        Study::Converge(c) => write_convergence_files(out, c),
        Study::VerifyDirect(v) => write_direct_verification_files(out, v),
        Study::ConvergeDirect(c) => write_direct_convergence_files(out, c),
    }
}

/// A verification's files: `verify.csv` (one row per start and angle) and
/// `verify.json`.
fn write_verification_files(
    out: &OutputDir,
    verification: &Verification,
) -> Result<(), WriteError> {
    write_rows(&out.path("verify.csv"), &verification.comparison.rows)?;
    write_json(&out.path("verify.json"), &verification.summary)
}

/// A convergence study's files: `converge.csv` (every metric at every
/// pitch), `verify_<pitch>mm.csv` (each pitch's per-start rows),
/// `converge.json` and the plots.
fn write_convergence_files(out: &OutputDir, convergence: &Convergence) -> Result<(), WriteError> {
    let results = &convergence.results;
    let tolerance = convergence.summary.tolerance_mm;
    let path = out.path("converge.csv");
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(&path)?;
        csv.write_record([
            "pitch_mm", "metric", "max", "p95", "mean", "n", "seconds", "area_iou", "pass",
        ])?;
        for r in results {
            let pass = tolerance.map_or(String::new(), |t| r.comparison.passes(t).to_string());
            for (metric, s) in &r.comparison.stats {
                csv.write_record([
                    r.pitch.to_string(),
                    metric.clone(),
                    s.max.to_string(),
                    s.p95.to_string(),
                    s.mean.to_string(),
                    s.n.to_string(),
                    r.seconds.to_string(),
                    r.comparison.area_iou.to_string(),
                    pass.clone(),
                ])?;
            }
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(WriteError::at(&path))?;
    // Every pitch's per-start rows, as `verify.csv` has them: where each
    // figure of converge.csv comes from.
    for r in results {
        write_rows(
            &out.path(format!("verify_{}mm.csv", r.pitch)),
            &r.comparison.rows,
        )?;
    }
    write_json(&out.path("converge.json"), &convergence.summary)?;
    super::write_plots(out.path(".").as_path(), results, &convergence.fits)
}

/// A direct verification's files: `verify.csv` (one row per position and
/// angle) and `verify.json` (`"approach": "direct"`).
fn write_direct_verification_files(
    out: &OutputDir,
    verification: &DirectVerification,
) -> Result<(), WriteError> {
    write_rows(&out.path("verify.csv"), &verification.comparison.rows)?;
    write_json(&out.path("verify.json"), &verification.summary)
}

/// A direct convergence study's files: `converge.csv` (both metrics at
/// every pitch), `verify_<pitch>mm.csv` (each pitch's rows) and
/// `converge.json` (`"approach": "direct"`).
fn write_direct_convergence_files(
    out: &OutputDir,
    convergence: &DirectConvergence,
) -> Result<(), WriteError> {
    let tolerance = convergence.summary.tolerance_mm;
    let path = out.path("converge.csv");
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(&path)?;
        csv.write_record([
            "approach",
            "pitch_mm",
            "metric",
            "max",
            "p95",
            "median",
            "mean",
            "n",
            "both",
            "grid_only",
            "exact_only",
            "oracle_failed",
            "engine_mismatch",
            "pass",
        ])?;
        for r in &convergence.results {
            let c = &r.comparison.counts;
            let pass = tolerance.map_or(String::new(), |t| r.comparison.passes(t).to_string());
            for (metric, s) in &r.comparison.stats {
                csv.write_record([
                    "direct".to_string(),
                    r.pitch.to_string(),
                    metric.clone(),
                    s.max.to_string(),
                    s.p95.to_string(),
                    s.median.to_string(),
                    s.mean.to_string(),
                    s.n.to_string(),
                    c.both.to_string(),
                    c.grid_only.to_string(),
                    c.exact_only.to_string(),
                    c.oracle_failed.to_string(),
                    c.engine_mismatch.to_string(),
                    pass.clone(),
                ])?;
            }
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(WriteError::at(&path))?;
    for r in &convergence.results {
        write_rows(
            &out.path(format!("verify_{}mm.csv", r.pitch)),
            &r.comparison.rows,
        )?;
    }
    write_json(&out.path("converge.json"), &convergence.summary)
}

/// Stages `dir`, has `write` fill it and commits it: `dir` appears with
/// every file or is left as it was.
fn staged(
    dir: &Path,
    write: impl FnOnce(&OutputDir) -> Result<(), WriteError>,
) -> Result<(), WriteError> {
    let commit_error = |source| WriteError::Commit {
        path: dir.to_path_buf(),
        source,
    };
    let out = OutputDir::stage(dir).map_err(commit_error)?;
    write(&out)?;
    out.commit().map(drop).map_err(commit_error)
}

/// Writes serialisable rows as CSV with a header.
fn write_rows(path: &Path, rows: &[impl serde::Serialize]) -> Result<(), WriteError> {
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(path)?;
        for row in rows {
            csv.serialize(row)?;
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(WriteError::at(path))
}
