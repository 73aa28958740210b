//! The evidence report: one self-contained HTML file that shows what was
//! analysed, how, what the knee-form can strike, and how accurate that is.
//!
//! * [`write_report`]: a run directory (and any verification directories)
//!   in, the page out; [`ReportOptions`] says where things are, [`Report`]
//!   what was drawn;
//! * [`grid_spec`], [`STRIKE_RULE_KEYS`], [`MAIN_BORDER`]: what a reader
//!   of the run's files and of the page needs to check them.
//!
//! Inside: `error` ([`ReportError`], the leaf every part of the report
//! returns), `render` (the CPU renderer: orthographic, z-buffered, Lambert
//! shading, and its pixel ↔ part mapping), `views` (the report's views of
//! the part and how they are painted), `run` and `verify` (reading the run
//! and verification files back), `undecided` (where a verification's
//! grid boundary is undecided: hatched on the picture, and the zones it
//! touches), `document` (the page, a `maud` template)
//! and `html` (number formatting and citations).
//!
//! **Invariant:** every value the report shows from a run comes from the
//! run's files, cited by file and JSON pointer (`data-src`); the part is
//! drawn from the very file the run analysed (its SHA-256 is checked).

use std::path::{Path, PathBuf};

mod compare;
mod diff;
mod document;
mod error;
mod html;
mod render;
mod run;
mod undecided;
mod verify;
mod view3d;
mod views;

pub use self::diff::{NodeState, RevisionDiff, ZoneChange, ZoneDiff, diff_runs, write_diff};
pub use self::document::MAIN_BORDER;
pub use self::error::ReportError;
pub use self::run::grid_spec;
pub use self::verify::STRIKE_RULE_KEYS;

use self::render::RgbImage;
use self::run::{NodeCounts, Run};
use self::verify::Verification;
use self::views::{render_views, small_multiple_angles};

/// The images of the run directory embedded in the report, when present.
const RUN_FIGURES: [&str; 2] = ["composite.png", "depth.png"];

/// What to report on.
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// The `analyze` output directory.
    pub run_dir: PathBuf,
    /// `verify` or `converge` output directories.
    pub verify_dirs: Vec<PathBuf>,
    /// The part file, when not where the run's `input_file` says.
    pub part: Option<PathBuf>,
    /// The run directory's name on the page, when `run_dir` is not (e.g. a
    /// staging directory about to be renamed).
    pub run_name: Option<PathBuf>,
    /// Another `analyze` run of the same part with the other approach
    /// (`--approach`), shown side by side with this one.
    pub compare: Option<PathBuf>,
}

impl ReportOptions {
    /// A report on `run_dir` alone, its part read as STL.
    pub fn new(run_dir: impl Into<PathBuf>) -> ReportOptions {
        ReportOptions {
            run_dir: run_dir.into(),
            verify_dirs: Vec::new(),
            part: None,
            run_name: None,
            compare: None,
        }
    }
}

/// What a written report drew.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The part file drawn: the one the run analysed, its SHA-256 checked.
    pub part_path: PathBuf,
    /// Triangles in the part file.
    pub triangles: usize,
    /// Wall-clock time of rendering the views (seconds).
    pub render_s: f64,
}

/// Reads the run and verification directories, renders the views and
/// assembles the page; returns it with what it drew.
fn build_report(options: &ReportOptions) -> Result<(String, Report), ReportError> {
    let mut run = Run::read(&options.run_dir, options.part.as_deref())?;
    let verifications = options
        .verify_dirs
        .iter()
        .map(|d| Verification::read(d))
        .collect::<Result<Vec<_>, _>>()?;
    // Refused before any rendering: another part's accuracy must never
    // appear as this run's.
    for v in &verifications {
        v.check_against(&run.summary_json)?;
    }
    let angles = small_multiple_angles(&run.summary.angles_deg);
    // The angle sets, read once: the small multiples and the 3D view.
    let angle_bits = run.angle_bits()?;
    let masks = run.angle_masks(&angles, angle_bits.as_ref())?;
    let masks: Vec<(f64, NodeCounts)> = angles.into_iter().zip(masks).collect();
    let views = render_views(&run, &masks);
    // A run of the same approach is another revision of the part: what
    // changed, on the earlier one's grid; a run of the other approach is
    // the side-by-side comparison.
    if let Some(dir) = &options.compare {
        let same = |a: &Path, b: &Path| {
            std::fs::canonicalize(a)
                .ok()
                .is_some_and(|a| std::fs::canonicalize(b).ok() == Some(a))
        };
        if same(dir, &options.run_dir) {
            return Err(ReportError::Inconsistent {
                path: dir.clone(),
                reason: "it is the report's run itself: --compare takes another run (an earlier revision of the part, or the other approach)".into(),
            });
        }
    }
    let revision = match &options.compare {
        Some(dir) if same_approach(dir, &run)? => {
            let diff = diff::diff_runs(dir, &options.run_dir)?;
            let png = diff::picture_png(&diff)?;
            Some((diff, png))
        }
        _ => None,
    };
    let comparison = match &options.compare {
        None => None,
        Some(_) if revision.is_some() => None,
        Some(dir) => {
            let other = Run::read(dir, options.part.as_deref())?;
            let comparison = compare::Comparison::new(&run, other)?;
            let pngs = comparison
                .figures
                .iter()
                .map(|f| encode_png(&f.image))
                .collect::<Result<Vec<_>, _>>()?;
            Some((comparison, pngs))
        }
    };
    let mut pngs = vec![
        encode_png(&views.side.image)?,
        encode_png(&views.oblique.image)?,
    ];
    for (_, figure) in &views.per_angle {
        pngs.push(encode_png(&figure.image)?);
    }
    let run_figures: Vec<(String, Vec<u8>)> = RUN_FIGURES
        .iter()
        .filter_map(|name| {
            crate::limits::read_bounded(&run.dir.join(name), crate::limits::MAX_RUN_TABLE_BYTES)
                .ok()
                .map(|b| (name.to_string(), b))
        })
        .collect();
    if let Some(name) = &options.run_name {
        run.dir.clone_from(name);
    }
    let view3d = view3d::view3d_figure(&run, angle_bits.as_ref())?;
    let html = document::document(&document::Inputs {
        run: &run,
        view3d,
        verifications: &verifications,
        views: &views,
        pngs: &pngs,
        run_figures: &run_figures,
        comparison: comparison.as_ref().map(|(c, pngs)| (c, pngs.as_slice())),
        revision: revision.as_ref().map(|(d, png)| (d, png.as_slice())),
    });
    let report = Report {
        part_path: run.part_path,
        triangles: run.part.triangles.len(),
        render_s: views.render_s,
    };
    Ok((html, report))
}

/// Whether the run in `dir` has `run`'s approach (another revision of the
/// part, for `--compare`), from its `summary.json`.
fn same_approach(dir: &Path, run: &Run) -> Result<bool, ReportError> {
    let (_, _, other) = run::read_summary(&dir.join(crate::output::SUMMARY_JSON))?;
    Ok(other.approach == run.summary.approach)
}

/// Builds the report and writes it to `out` through a temporary file in the
/// same directory, renamed into place: `out` is never half written.
pub fn write_report(options: &ReportOptions, out: &Path) -> Result<Report, ReportError> {
    let (html, report) = build_report(options)?;
    let io = |source| ReportError::Io {
        path: out.to_path_buf(),
        source,
    };
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(io)?;
    }
    crate::output::write_file_atomically(out, |file| {
        std::io::Write::write_all(file, html.as_bytes())
    })
    .map_err(io)?;
    Ok(report)
}

/// An RGB image as PNG bytes.
fn encode_png(image: &RgbImage) -> Result<Vec<u8>, ReportError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, image.width as u32, image.height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&image.pixels)?;
    writer.finish()?;
    Ok(bytes)
}
