//! The report's interactive 3D view: the part with the composite painted
//! on it, drawn by WebGL 2 in the page itself (no library, no network).
//!
//! The page carries three things, base64 in one JSON block:
//!
//! * the part's triangles (vehicle coordinates, as the static views draw
//!   them), vertices shared, as little-endian `f32` offsets from the
//!   bounding box's centre and `u32` indices;
//! * the grid's nodes as an RGBA PNG, one pixel per node (row `j`, column
//!   `i`): red the composite count, green and blue the node's depth on the
//!   grid in 16-bit fixed point over the colliding nodes' depth range;
//! * each node's set of striking angles as an RGBA PNG, `ceil(bytes / 3)`
//!   pixels per node (red, green, blue; alpha 255), bit `a % 8` of byte `a / 8` for the run's angle `a`
//!   ([`Run::angle_bits`]), for reading a picked point's angles.
//!
//! The fragment shader paints a surface point by the static oblique view's
//! rule ([`super::views`]): the count of its nearest node in x and z (the
//! run's grid axes), when the point lies within
//! [`OBLIQUE_Y_TOL_PITCHES`] pitches of the node's depth; grey otherwise.
//! A click casts a ray against the triangles and reads the node under the
//! hit. Where WebGL 2 is missing the figure says so and the static
//! pictures stand; a print hides it.

use std::collections::HashMap;

use maud::{Markup, PreEscaped, html};
use serde_json::json;

use crate::frame::Approach;

use super::error::ReportError;
use super::html::base64;
use super::run::{AngleBits, Run};
use super::views::{OBLIQUE_Y_TOL_PITCHES, composite_colour, ramp_len, run_oblique_camera};

/// The most triangles the page carries (about 17 MB of base64 at the
/// worst, no vertex shared); a larger part is drawn simplified
/// ([`simplified`]).
pub const MAX_TRIANGLES: usize = 400_000;
/// The triangles of a simplified part: its face towards the knee-form as
/// the height field of a grid coarser than the run's (every `k`-th node),
/// two triangles a cell, within a quarter of [`MAX_TRIANGLES`] (the
/// page stays a few MB).
const SIMPLIFIED_TRIANGLES: usize = MAX_TRIANGLES / 4;
/// Zones labelled on the view, largest first (every zone is named on a
/// pick).
const LABELLED_ZONES: usize = 12;
/// The most grid nodes the page carries: WebGL 2 guarantees textures of
/// 2048 x 2048 only, and most browsers allow 8192 or more.
pub(crate) const MAX_NODES: usize = 8192 * 8192;

/// The 3D view's figure: a canvas, its controls' help, the readout of a
/// picked point, and the data; or a note saying why there is none.
pub(crate) fn view3d_figure(
    run: &Run,
    angle_bits: Option<&AngleBits>,
) -> Result<Markup, ReportError> {
    let spec = run.spec;
    if spec.len() > MAX_NODES {
        return Ok(html! {
            p class="note" {
                "No interactive 3D view: the grid has " (spec.len())
                " nodes, more than the page carries (" (MAX_NODES)
                " nodes); the pictures above show the same colours."
            }
            "\n"
        });
    }
    let simple = (run.part.triangles.len() > MAX_TRIANGLES).then(|| simplified(run));
    let triangles = simple
        .as_ref()
        .map_or(&run.part.triangles, |s| &s.triangles);
    let data = scene_json(run, triangles, simple.as_ref(), angle_bits)?;
    // `</` cannot appear in the JSON's strings (base64 and numbers), so the
    // script element holds it whole.
    let data = data.replace("</", "<\\/");
    Ok(html! {
        figure class="view3d" id="view3d" data-state="loading" {
            "\n"
            canvas width="1100" height="640" aria-label="interactive 3D view of the part" {}
            "\n"
            figcaption {
                span class="view3d-status" { "Interactive 3D view: loading." }
                noscript { " Scripts are off: the pictures above show the same colours." }
                " Drag to turn, shift-drag (or right-drag) to move, wheel to zoom, double-click to reset; click a point to read its coordinates (vehicle frame, mm), its grid node and the angles that strike it. Colours as above; a surface point is painted by its nearest node in "
                (if run.summary.approach == Approach::Direct { "y" } else { "x" })
                " and z when it lies within " (OBLIQUE_Y_TOL_PITCHES) " pitches of the node's depth."
                " Inside the view: the vehicle axes (x, y, z), the colour legend (angles struck), a scale bar at the depth of the view's centre, and the largest struck zones by their ids (zones.csv); a pick names its zone."
                @if let Some(s) = &simple {
                    " "
                    strong { "Simplified:" }
                    " the part's " (s.original) " triangles are more than the page carries ("
                    (MAX_TRIANGLES) "), so it is drawn as its face towards the knee-form, sampled every "
                    (s.pitch) " mm (every " (s.stride) " grid nodes) and joined into "
                    (s.triangles.len()) " triangles; its other faces are not drawn, and a point is painted when within "
                    (s.depth_tol) " mm of its node's depth. The colours are still the run's grid nodes."
                }
            }
            "\n"
            p class="view3d-pick mono" { "No point picked." }
            "\n"
            script type="application/json" id="view3d-data" { (PreEscaped(data)) }
            "\n"
            script { (PreEscaped(SCRIPT)) }
            "\n"
        }
        "\n"
    })
}

/// A part too large for the page, drawn as the height field of its face
/// towards the knee-form.
struct Simplified {
    /// The triangles, vehicle coordinates.
    triangles: Vec<crate::mesh::Triangle>,
    /// The part's own triangle count.
    original: usize,
    /// Every `stride`-th node of the run's grid.
    stride: usize,
    /// The sampling pitch (mm): `stride` x the run's.
    pitch: f64,
    /// How far from its node's depth a surface point is still painted
    /// (mm): [`OBLIQUE_Y_TOL_PITCHES`] of the sampling pitch, since the
    /// simplified surface departs from the part by up to about that.
    depth_tol: f64,
}

/// `run`'s part as the height field of its face towards the knee-form:
/// the part sampled (as the analysis samples it: the first hit along the
/// knee-form's push) on the nodes of every `k`-th column and row of the
/// run's grid, `k` the smallest keeping two triangles a cell within
/// [`SIMPLIFIED_TRIANGLES`], each cell with four finite corners split
/// along its `(i, j)-(i+1, j+1)` diagonal.
fn simplified(run: &Run) -> Simplified {
    use crate::frame::Side;
    use crate::grid::{GridSpec, HeightGrid};
    let spec = run.spec;
    let axes = run.axes;
    // The grid's depth grows away from the knee-form but for a right side
    // pushed in -y, whose depth is mirrored here and back.
    let flip = axes.approach == Approach::Slide && axes.side == Side::Right;
    let to_grid = |v: [f64; 3]| {
        let mut g = axes.grid(v);
        if flip {
            g[1] = -g[1];
        }
        g
    };
    let to_vehicle = |g: [f64; 3]| {
        let depth = if flip { -g[1] } else { g[1] };
        match axes.approach {
            Approach::Slide => [g[0], depth, g[2]],
            Approach::Direct => [-depth, axes.side.to_part(g[0]), g[2]],
        }
    };
    let cells = (spec.nx * spec.nz) as f64;
    let stride = ((2.0 * cells / SIMPLIFIED_TRIANGLES as f64).sqrt().ceil() as usize).max(1);
    let k = stride as i64;
    let coarse = GridSpec {
        pitch: spec.pitch * stride as f64,
        i_origin: spec.i_origin.div_euclid(k),
        j_origin: spec.j_origin.div_euclid(k),
        nx: spec.nx / stride + 2,
        nz: spec.nz / stride + 2,
    };
    let in_grid: Vec<crate::mesh::Triangle> =
        run.part.triangles.iter().map(|t| t.map(to_grid)).collect();
    let h = HeightGrid::sample(&in_grid, coarse);
    let mut triangles = Vec::new();
    let node = |i: usize, j: usize| {
        let y = h.h[j * coarse.nx + i];
        y.is_finite()
            .then(|| to_vehicle([coarse.x(i), y, coarse.z(j)]))
    };
    for j in 0..coarse.nz - 1 {
        for i in 0..coarse.nx - 1 {
            if let (Some(a), Some(b), Some(c), Some(d)) = (
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            ) {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
    }
    Simplified {
        triangles,
        original: run.part.triangles.len(),
        stride,
        pitch: coarse.pitch,
        depth_tol: OBLIQUE_Y_TOL_PITCHES * coarse.pitch,
    }
}

/// The struck zones ([`crate::zones::components`] of the composite, ids
/// as `zones.csv`'s): per node its zone's id (0 off every zone) as an
/// RGBA PNG (red, green, blue the id's three bytes), and the largest
/// zones' ids, areas and centroids (vehicle coordinates) for labels.
fn zones_scene(run: &Run) -> Result<(Vec<u8>, Vec<serde_json::Value>), ReportError> {
    let spec = run.spec;
    let composite = &run.composite;
    let zones = crate::zones::components(&composite.count, spec.nx, spec.nz);
    let mut px = vec![0u8; spec.len() * 4];
    for p in px.chunks_exact_mut(4) {
        p[3] = 255;
    }
    let mut labels = Vec::new();
    for (k, nodes) in zones.iter().enumerate() {
        let id = (k + 1) as u32;
        let (mut sum, mut n) = ([0.0; 3], 0usize);
        for &node in nodes {
            px[node * 4..node * 4 + 3].copy_from_slice(&id.to_be_bytes()[1..]);
            let y = composite.y[node];
            if y.is_finite() {
                let g = [spec.x(node % spec.nx), y, spec.z(node / spec.nx)];
                for a in 0..3 {
                    sum[a] += g[a];
                }
                n += 1;
            }
        }
        if k < LABELLED_ZONES && n > 0 {
            let g = sum.map(|s| s / n as f64);
            let v = match run.axes.approach {
                Approach::Slide => g,
                Approach::Direct => [-g[1], run.axes.side.to_part(g[0]), g[2]],
            };
            labels.push(json!({
                "id": id,
                "area_mm2": nodes.len() as f64 * spec.pitch * spec.pitch,
                "at": v,
            }));
        }
    }
    Ok((rgba_png(spec.nx, spec.nz, &px)?, labels))
}

/// The scene as JSON: geometry, node textures, the ramp, the grid's
/// placement, the zones and the first camera.
fn scene_json(
    run: &Run,
    triangles: &[crate::mesh::Triangle],
    simple: Option<&Simplified>,
    angle_bits: Option<&AngleBits>,
) -> Result<String, ReportError> {
    let (centre, radius, positions, indices) = mesh(triangles);
    let spec = run.spec;
    let composite = &run.composite;
    let (lo, hi) = composite
        .count
        .iter()
        .zip(&composite.y)
        .filter(|(c, y)| **c > 0 && y.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, &y)| {
            (lo.min(y), hi.max(y))
        });
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
    let range = (hi - lo).max(1e-9);
    let mut nodes = vec![0u8; spec.len() * 4];
    for (k, px) in nodes.chunks_exact_mut(4).enumerate() {
        let c = composite.count[k];
        let y = composite.y[k];
        let q = if c > 0 && y.is_finite() {
            ((y - lo) / range * 65535.0).round().clamp(0.0, 65535.0) as u16
        } else {
            0
        };
        px.copy_from_slice(&[c.min(255) as u8, (q >> 8) as u8, q as u8, 255]);
    }
    let nodes_png = rgba_png(spec.nx, spec.nz, &nodes)?;
    let (masks_png, words) = match angle_bits {
        None => (None, 0),
        Some(bits) => {
            // Three bytes a pixel, alpha 255: a browser premultiplies a
            // pixel's colour by its alpha, which would lose the bits.
            let words = bits.bytes.div_ceil(3);
            let mut px = vec![255u8; spec.len() * words * 4];
            for k in 0..spec.len() {
                for (b, &byte) in bits.bits[k * bits.bytes..][..bits.bytes].iter().enumerate() {
                    px[(k * words + b / 3) * 4 + b % 3] = byte;
                }
                for b in bits.bytes..words * 3 {
                    px[(k * words + b / 3) * 4 + b % 3] = 0;
                }
            }
            (Some(rgba_png(spec.nx * words, spec.nz, &px)?), words)
        }
    };
    let n = ramp_len(run);
    let ramp: Vec<u8> = (1..=n)
        .flat_map(|c| {
            let [r, g, b] = composite_colour(c as u16, n);
            [r, g, b, 255]
        })
        .collect();
    let to_grid: [f64; 9] = match run.axes.approach {
        // Rows of the vehicle -> grid map ([`GridAxes::grid`]).
        Approach::Slide => [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        Approach::Direct => [
            0.0,
            run.axes.side.to_part(1.0),
            0.0,
            -1.0,
            0.0,
            0.0,
            0.0,
            0.0,
            1.0,
        ],
    };
    let forward = run_oblique_camera(run.axes).forward;
    let (zones_png, zones) = zones_scene(run)?;
    Ok(json!({
        "centre": centre,
        "radius": radius,
        "positions": base64(&positions),
        "indices": base64(&indices),
        "triangles": triangles.len(),
        "simplified": simple.map(|s| json!({
            "original_triangles": s.original,
            "stride": s.stride,
            "pitch": s.pitch,
        })),
        "zones_png": base64(&zones_png),
        "zones": zones,
        "pitch": spec.pitch,
        "origin": [spec.i_origin, spec.j_origin],
        "size": [spec.nx, spec.nz],
        "to_grid": to_grid,
        "depth_range": [lo, hi],
        "depth_tol": simple.map_or(OBLIQUE_Y_TOL_PITCHES * spec.pitch, |s| s.depth_tol),
        "nodes_png": base64(&nodes_png),
        "masks_png": masks_png.as_deref().map(base64),
        "mask_words": words,
        "ramp": base64(&ramp),
        "angles": run.summary.angles_deg,
        "view": [forward.x, forward.y, forward.z],
        "frame": !run.frame.is_none(),
    })
    .to_string())
}

/// The triangles as shared vertices: the bounding box's centre, the
/// radius of its sphere, the vertices' `f32` offsets from the centre and
/// the triangles' `u32` indices (little-endian bytes). Vertices are shared
/// where their offsets are equal to the bit.
fn mesh(triangles: &[crate::mesh::Triangle]) -> ([f64; 3], f64, Vec<u8>, Vec<u8>) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in triangles.iter().flatten() {
        for a in 0..3 {
            lo[a] = lo[a].min(v[a]);
            hi[a] = hi[a].max(v[a]);
        }
    }
    if triangles.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    let centre = [0, 1, 2].map(|a| 0.5 * (lo[a] + hi[a]));
    let radius = (0..3)
        .map(|a| (hi[a] - lo[a]).powi(2))
        .sum::<f64>()
        .sqrt()
        .max(1.0)
        * 0.5;
    let mut shared: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut indices = Vec::with_capacity(triangles.len() * 12);
    for p in triangles.iter().flatten() {
        let v = [0, 1, 2].map(|a| (p[a] - centre[a]) as f32);
        let key = v.map(f32::to_bits);
        let next = shared.len() as u32;
        let index = *shared.entry(key).or_insert_with(|| {
            for c in v {
                positions.extend_from_slice(&c.to_le_bytes());
            }
            next
        });
        indices.extend_from_slice(&index.to_le_bytes());
    }
    (centre, radius, positions, indices)
}

/// RGBA pixels (`width` x `height`, row-major) as PNG bytes.
fn rgba_png(width: usize, height: usize, pixels: &[u8]) -> Result<Vec<u8>, ReportError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Best);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(bytes)
}

/// The viewer: WebGL 2, written here. It sets the figure's `data-state`
/// to `drawn` (with `data-part-pixels` and `data-coloured-pixels`, the
/// canvas pixels showing the part and those painted with a ramp colour,
/// counted once after the first frame) or `unavailable` (and says why).
const SCRIPT: &str = include_str!("view3d.js");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Part;

    /// The shared vertices and indices give back every triangle (to f32),
    /// a vertex shared by two triangles is stored once, and the centre and
    /// radius are the bounding box's.
    #[test]
    fn the_mesh_shares_vertices_and_gives_back_every_triangle() {
        let tris = vec![
            [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 0.0, 20.0]],
            [[10.0, 0.0, 0.0], [10.0, 4.0, 20.0], [0.0, 0.0, 20.0]],
        ];
        let part = Part {
            file_triangles: tris.len(),
            triangles: tris.clone(),
            degenerate: 0,
            bodies: 1,
        };
        let (centre, radius, positions, indices) = mesh(&part.triangles);
        assert_eq!(centre, [5.0, 2.0, 10.0]);
        assert!((radius - 0.5 * (100.0f64 + 16.0 + 400.0).sqrt()).abs() < 1e-12);
        let floats: Vec<f32> = positions
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        let index: Vec<usize> = indices
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()) as usize)
            .collect();
        assert_eq!(floats.len(), 4 * 3, "four distinct vertices");
        assert_eq!(index.len(), 6);
        for (t, tri) in tris.iter().enumerate() {
            for (v, p) in tri.iter().enumerate() {
                let k = index[3 * t + v];
                for a in 0..3 {
                    assert_eq!(f64::from(floats[3 * k + a]) + centre[a], p[a]);
                }
            }
        }
    }
}
