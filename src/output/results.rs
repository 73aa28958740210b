//! An analysis's result files ([`write_analysis`], or [`write_results`]
//! from its results merged from shards); the studies' are
//! [`super::studies`]'s.

use std::io::{BufWriter, Write};
use std::path::Path;
use std::time::Instant;

use super::{OutputDir, WriteError};
use crate::analysis::Analysis;
use crate::blind::BlindSpot;
use crate::engine::AngleMask;
use crate::frame::Placement;
use crate::grid::HeightGrid;
use crate::summary::Summary;

/// What [`write_analysis`] writes besides the default files
/// (`composite.csv.gz`, the images, `zones.csv`, `blind_spots.csv`,
/// `summary.json`): the large ones, only when asked, so that a run a user
/// keeps stays small (about 2 MB for the bundled console at its default
/// pitch, where the four below add some 60 MB).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Also `colliding_points.csv`, one row per colliding node per angle
    /// (`analyze --points-csv`): the sets `composite.csv`'s `angle_mask`
    /// holds, some fifty times larger.
    pub points_csv: bool,
    /// The composite as plain `composite.csv` instead of
    /// `composite.csv.gz` (`analyze --csv`): the same bytes, uncompressed
    /// (about 50 bytes a colliding node, 11 MB on the console).
    pub plain_csv: bool,
    /// Also `colliding_area.stl` (`analyze --stl`): the area as binary
    /// STL, 100 bytes a triangle (22 MB on the console).
    pub stl: bool,
    /// Also `colliding_area.ply` (`analyze --ply`): the area as a binary
    /// PLY mesh coloured by count (about 45 bytes a colliding node).
    pub ply: bool,
}

/// An analysis's results as the writers take them: from an
/// [`Analysis`], or from the shards of one, merged (`kneeform merge`).
#[derive(Debug, Clone, Copy)]
pub struct RunResults<'a> {
    /// The height grid.
    pub grid: &'a HeightGrid,
    /// The colliding mask per angle, in the run's order.
    pub masks: &'a [AngleMask],
    /// Per node, the angles at which it collides.
    pub composite: &'a [u16],
    /// An assembly's file per node.
    pub node_file: Option<&'a [u32]>,
    /// Where the part's frame is.
    pub placement: &'a Placement,
    /// The blind spots, with the angles meeting them.
    pub blind_spots: &'a [BlindSpot],
    /// The knee-form's triangle side L (mm), for the composite's title.
    pub triangle_side: f64,
}

impl<'a> RunResults<'a> {
    /// The results of `analysis`.
    pub fn of(analysis: &'a Analysis, placement: &'a Placement) -> RunResults<'a> {
        RunResults {
            grid: &analysis.grid,
            masks: &analysis.masks,
            composite: &analysis.composite,
            node_file: analysis.node_file.as_deref(),
            placement,
            blind_spots: &analysis.blind_spots,
            triangle_side: analysis.setup.knee.triangle_side,
        }
    }
}

/// Writes the files of an analysis into the staged directory `out`: the
/// composite as compressed CSV (plain with `options.plain_csv`; with
/// `options.points_csv`, the colliding points too), the colliding area as
/// STL and PLY when asked, the depth and composite images, and
/// `summary.json` last, with the writing time. Returns the summary written.
pub fn write_analysis(
    out: &OutputDir,
    analysis: &Analysis,
    options: &WriteOptions,
) -> Result<Summary, WriteError> {
    let t = Instant::now();
    let placement = analysis.placement();
    write_results(
        out,
        &RunResults::of(analysis, &placement),
        analysis.summary(),
        options,
        t,
    )
}

/// Writes `results` and `summary` (its `write_s` and `total_s` set from
/// `started`, `peak_rss_mib` measured) into the staged directory `out`:
/// [`write_analysis`]'s files.
pub fn write_results(
    out: &OutputDir,
    results: &RunResults,
    mut summary: Summary,
    options: &WriteOptions,
    started: Instant,
) -> Result<Summary, WriteError> {
    let placement = results.placement;
    let (grid, masks, counts) = (results.grid, results.masks, results.composite);
    let node_file = results.node_file;
    let file =
        |name: &str,
         write: &(dyn Fn(&mut BufWriter<std::fs::File>) -> std::io::Result<()> + Sync)| {
            let path = out.path(name);
            std::fs::File::create(&path)
                .and_then(|f| {
                    let mut w = BufWriter::new(f);
                    write(&mut w)?;
                    w.flush()
                })
                .map_err(WriteError::at(&path))
        };
    // The files are independent: three groups of about equal time are
    // written in parallel. Each file's bytes do not depend on it; the
    // first error in the order below is the one reported.
    let tables = || -> Result<(), WriteError> {
        if options.points_csv {
            file("colliding_points.csv", &|w| {
                Ok(super::write_colliding_points(
                    w, grid, masks, placement, node_file,
                )?)
            })?;
        }
        if options.plain_csv {
            file(super::COMPOSITE_CSV, &|w| {
                Ok(super::write_composite(
                    w, grid, masks, counts, placement, node_file,
                )?)
            })
        } else {
            // gzip's header carries no time or name: the same result
            // gives the same bytes.
            file(super::COMPOSITE_CSV_GZ, &|w| {
                let mut gz = flate2::write::GzEncoder::new(w, flate2::Compression::default());
                super::write_composite(&mut gz, grid, masks, counts, placement, node_file)?;
                gz.finish().map(drop)
            })
        }
    };
    let meshes = || -> Result<(), WriteError> {
        if options.stl {
            file("colliding_area.stl", &|w| {
                super::write_colliding_area(w, grid, counts, placement).map(drop)
            })?;
        }
        if options.ply {
            file("colliding_area.ply", &|w| {
                super::write_colliding_area_ply(w, grid, counts, masks.len(), placement).map(drop)
            })?;
        }
        Ok(())
    };
    let pictures = || -> Result<(), WriteError> {
        super::write_depth_png(&out.path("depth.png"), grid, placement)?;
        let title = format!(
            "Composite colliding area, {} angles (L = {} mm)",
            masks.len(),
            super::png::tick(&results.triangle_side)
        );
        let blind: Vec<(usize, usize)> = results.blind_spots.iter().map(|b| (b.i, b.j)).collect();
        super::write_composite_png(
            &out.path("composite.png"),
            grid,
            counts,
            masks.len(),
            &title,
            placement,
            &blind,
        )?;
        write_blind_spots(&out.path("blind_spots.csv"), results.blind_spots, placement)
    };
    let (tables, (meshes, pictures)) = rayon::join(tables, || rayon::join(meshes, pictures));
    tables?;
    meshes?;
    pictures?;
    summary.zones = crate::zones::zones(grid, counts, masks, results.blind_spots, placement);
    write_zones(&out.path(ZONES_CSV), &summary.zones)?;
    let t_ = &mut summary.timings;
    t_.write_s = started.elapsed().as_secs_f64();
    t_.total_s = t_.read_s + t_.sample_s + t_.blind_s + t_.push_slide_s + t_.check_s + t_.write_s;
    summary.peak_rss_mib = crate::memory::peak_rss_bytes().map(|b| b / (1024.0 * 1024.0));
    write_json(&out.path(super::SUMMARY_JSON), &summary)?;
    Ok(summary)
}

/// The struck zones' table, one row per zone ([`crate::zones`]).
pub const ZONES_CSV: &str = "zones.csv";

/// Writes `zones.csv`: one row per struck zone, largest first: its id,
/// node count and area (mm^2), bounding box and centroid (mm, the part's
/// own coordinates, to 1 um), the angles striking it as runs, its largest
/// count, whether a blind spot touches it, and for a speck the zone it
/// lies beside.
fn write_zones(path: &Path, zones: &[crate::zones::Zone]) -> Result<(), WriteError> {
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(path)?;
        csv.write_record([
            "zone",
            "nodes",
            "area_mm2",
            "x_min",
            "y_min",
            "z_min",
            "x_max",
            "y_max",
            "z_max",
            "x_centroid",
            "y_centroid",
            "z_centroid",
            "angles",
            "max_count",
            "blind_spot",
            "speck_beside",
        ])?;
        let um = super::csv::micrometres;
        for z in zones {
            let mut row = vec![z.id.to_string(), z.nodes.to_string(), um(z.area_mm2)];
            row.extend(
                z.bbox_min
                    .iter()
                    .chain(&z.bbox_max)
                    .chain(&z.centroid)
                    .map(|&v| um(v)),
            );
            row.extend([
                z.angle_runs.clone(),
                z.max_count.to_string(),
                z.touches_blind_spot.to_string(),
                z.beside.map_or_else(String::new, |b| b.to_string()),
            ]);
            csv.write_record(row)?;
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(WriteError::at(path))
}

/// Writes `blind_spots.csv`: one row per blind spot ([`crate::blind`]),
/// where (cell `i, j` of the analysis grid; `x, y, z` of its lowest point,
/// mm, in the part's coordinates through `placement`), how deep and wide,
/// the pitch resolving it, and the angles at which the knee-form meets it
/// (`;`-separated, empty when none).
fn write_blind_spots(
    path: &Path,
    spots: &[BlindSpot],
    placement: &Placement,
) -> Result<(), WriteError> {
    (|| -> csv::Result<()> {
        let mut csv = csv::Writer::from_path(path)?;
        csv.write_record(crate::blind::CSV_COLUMNS)?;
        for b in spots {
            let angles: Vec<String> = b.met_angles_deg.iter().map(f64::to_string).collect();
            let [x, y, z] = b.in_part(placement);
            // Lengths to 1 um, as composite.csv's: a node's `i * p` is
            // written as the reader means it, not as its double.
            let um = super::csv::micrometres;
            csv.write_record([
                b.i.to_string(),
                b.j.to_string(),
                um(x),
                um(y),
                um(z),
                um(b.depth_missed_mm),
                um(b.width_mm),
                b.resolving_pitch_mm.to_string(),
                angles.join(";"),
            ])?;
        }
        csv.flush()?;
        Ok(())
    })()
    .map_err(WriteError::at(path))
}

/// Writes `value` as pretty JSON with a final newline, its figures
/// rounded ([`crate::summary::json_text`]).
pub(super) fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<(), WriteError> {
    let text = crate::summary::json_text(value).map_err(WriteError::at(path))?;
    std::fs::write(path, text).map_err(WriteError::at(path))
}
