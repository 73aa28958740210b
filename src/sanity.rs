//! Sanity checks of a run's inputs and result: the mistakes a new user
//! makes that would otherwise end in exit 0 with a wrong answer.
//!
//! * `part_warnings`: a part far smaller or larger than a knee-form (its
//!   units: `--scale`), a surface that faces the other way (`--side`);
//! * `angle_warnings`: angles outside the regulation's -30..+30 degrees;
//! * `result_warnings`: a result with no colliding node at all.
//!
//! Each is a [`Warning`], one line of text, printed by the CLI before the
//! work it concerns and recorded in `summary.json` (`warnings`), so that a
//! reader of the results sees it too. None stops a run: every one of them
//! can be what the user meant.
//!
//! **Invariant:** the checks read the inputs and the result; they change
//! neither.

use crate::frame::Side;
use crate::kneeform::{Footprint, KneeForm};
use crate::mesh::Part;

/// The regulation's knee-form angles: -30..+30 degrees (SPEC, "The
/// knee-form").
pub(crate) const REGULATION_ANGLE_DEG: f64 = 30.0;

/// A part whose larger xz extent is below the knee-form's divided by this
/// is "much smaller than a knee-form". The knee-form's default footprint
/// is about 320 mm across, so this is 16 mm: a console side read in metres
/// (1.5 "mm") is caught, a small real switch or trim part (30 mm and up) is
/// not.
pub(crate) const SMALL_FACTOR: f64 = 20.0;

/// A part whose larger xz extent is below the knee-form's divided by this
/// (but not by [`SMALL_FACTOR`]) is "smaller than a knee-form": 80 mm with
/// the default knee-form. The bundled console side read in inches is 59
/// "mm" across and struck at 61 angles as if it were a switch: nothing
/// else in its results looks wrong. A real part of that size (a switch, a
/// bezel) gets the warning too, which says so: a warning, not a refusal.
pub(crate) const UNITS_FACTOR: f64 = 4.0;

/// A part whose larger xz extent is above the knee-form's times this is
/// "much larger than a knee-form": with the default knee-form, 9.6 m, more
/// than any car's interior (a part in micrometres, or scaled twice).
pub(crate) const LARGE_FACTOR: f64 = 30.0;

/// The part "faces +y" when the area of its triangles facing +y (by their
/// winding, the STL convention) is more than this times the area facing
/// -y. A closed solid has as much of each (ratio 1) and is not flagged; an
/// open surface exported for the analysis is nearly all one way.
pub(crate) const FACING_RATIO: f64 = 3.0;

/// The part is "edge-on" when the area its triangles present along x or
/// along z (area-weighted normals) is more than this times the area they
/// present along y, the push axis: a plate lying flat, a panel modelled
/// facing sideways. A console side or a closed solid presents about as
/// much or more along y and is not flagged.
pub(crate) const EDGE_ON_RATIO: f64 = 2.0;

/// One finding, as one line of text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Warning {
    /// The part is much smaller than the knee-form.
    #[error(
        "the part is {extent_mm:.3} mm across, much smaller than the {knee_mm:.0} mm knee-form: if its file is in metres, pass --scale 1000 (in cm, --scale 10; in inches, --scale 25.4)"
    )]
    TooSmall {
        /// The part's larger extent in x and z (mm, after `--scale`).
        extent_mm: f64,
        /// The knee-form footprint's larger extent (mm).
        knee_mm: f64,
    },
    /// The part is smaller than a quarter of the knee-form: a large part
    /// modelled in inches or centimetres, read as mm?
    #[error(
        "the part is {extent_mm:.1} mm across, under a quarter of the {knee_mm:.0} mm knee-form: if it is a console side or door panel modelled in inches, pass --scale 25.4 (in cm, --scale 10); a small part (a switch, a bezel) of that size is analysed as it is"
    )]
    Small {
        /// The part's larger extent in x and z (mm, after `--scale`).
        extent_mm: f64,
        /// The knee-form footprint's larger extent (mm).
        knee_mm: f64,
    },
    /// The part is much larger than the knee-form.
    #[error(
        "the part is {extent_mm:.0} mm across, {ratio:.0} times the {knee_mm:.0} mm knee-form: is its file in micrometres, or --scale applied twice?"
    )]
    TooLarge {
        /// The part's larger extent in x and z (mm, after `--scale`).
        extent_mm: f64,
        /// The knee-form footprint's larger extent (mm).
        knee_mm: f64,
        /// `extent_mm / knee_mm`.
        ratio: f64,
    },
    /// Most of the surface faces away from the side analysed.
    #[error(
        "{percent:.0}% of the part's surface (area-weighted normals) faces {faces}, but --side {side} analyses the face towards {analysed}: if the knee comes from {faces}, pass --side {other}"
    )]
    WrongSide {
        /// The side analysed.
        side: &'static str,
        /// The other side.
        other: &'static str,
        /// Where the analysed face points (`-y` or `+y`).
        analysed: &'static str,
        /// Where most of the surface points.
        faces: &'static str,
        /// The share of the surface facing that way (%).
        percent: f64,
    },
    /// Most of the surface faces along x or z, not towards the knee.
    #[error(
        "the part's surface faces mostly along {axis} ({percent:.0}% of its area, {y_percent:.0}% along y, the axis the knee is pushed on): the knee-form meets it edge-on; {advice}"
    )]
    EdgeOn {
        /// The axis most of the surface faces along (`x` or `z`, in the
        /// frame the part is analysed in).
        axis: &'static str,
        /// The share of the area facing along it (%).
        percent: f64,
        /// The share facing along y (%).
        y_percent: f64,
        /// What to do, in words: the `--frame` that turns that face
        /// towards the knee.
        advice: String,
    },
    /// Some angles are beyond the regulation's range.
    #[error(
        "angles {angles} degrees are outside the regulation's -30..+30: their results are not the regulation's"
    )]
    AnglesOutsideRegulation {
        /// The angles, listed.
        angles: String,
    },
    /// Features between the nodes, unseen by the grid, that the
    /// knee-form meets.
    #[error(
        "{count} blind spots the knee-form meets (angles {angles}): the part sticks out up to {depth_mm:.2} mm past the grid's nodes where the grid cannot see it, first at x = {x:.1}, y = {y:.1}, z = {z:.1} mm (part coordinates); their strikes are missing from the result; {resolves} (blind_spots.csv)"
    )]
    BlindSpotsMet {
        /// Cells the knee-form meets.
        count: usize,
        /// The largest depth missed among them (mm).
        depth_mm: f64,
        /// The angles at which they are met, listed.
        angles: String,
        /// The first one's lowest point, in the part's coordinates: x (mm).
        x: f64,
        /// Its y (mm).
        y: f64,
        /// Its z (mm).
        z: f64,
        /// Which pitch resolves every one of them, in words
        /// (`resolving_phrase`).
        resolves: String,
    },
    /// Nothing is struck.
    #[error(
        "no grid node is struck at any angle: if the part should be struck, check its units (--scale) and which face the knee meets (--side)"
    )]
    NothingStruck,
}

/// The knee-form footprint's larger extent in x or z at angle 0 (mm):
/// `L sqrt(3)/2 + 2R` by `L + 2R`.
pub(crate) fn knee_extent(knee: &KneeForm) -> f64 {
    let fp = Footprint::new(knee, 0.0);
    let (x0, x1) = fp.x_range();
    let (z0, z1) = fp.z_range();
    (x1 - x0).max(z1 - z0)
}

/// The areas of the part's surface facing +y and -y in the part's own
/// frame (mm^2): each triangle's area times the y component of its unit
/// normal by winding (counter-clockwise seen from outside), summed by sign.
///
/// Mirroring the right side (y -> -y) reverses a triangle's winding as it
/// mirrors it, so the y component of the winding normal is the same in the
/// analysis frame as in the part's: the sums read the part as it is.
pub(crate) fn facing_areas(part: &Part) -> (f64, f64) {
    axis_facing_areas(part)[1]
}

/// The areas of the part's surface facing +axis and -axis, for the axes
/// x, y and z (mm^2): each triangle's area times each component of its
/// unit normal by winding, summed by sign ([`facing_areas`] for y).
fn axis_facing_areas(part: &Part) -> [(f64, f64); 3] {
    let mut areas = [(0.0, 0.0); 3];
    for t in &part.triangles {
        let [a, b, c] = t.map(nalgebra::Vector3::from);
        // Half of (b - a) x (c - a): the projected areas, signed.
        let n = 0.5 * (b - a).cross(&(c - a));
        for (k, area) in areas.iter_mut().enumerate() {
            if n[k] > 0.0 {
                area.0 += n[k];
            } else {
                area.1 -= n[k];
            }
        }
    }
    areas
}

/// The checks of a part read for `side` against `knee`: its size and its
/// facing (see [`SMALL_FACTOR`], [`UNITS_FACTOR`], [`LARGE_FACTOR`],
/// [`FACING_RATIO`]).
pub(crate) fn part_warnings(part: &Part, side: Side, knee: &KneeForm) -> Vec<Warning> {
    let mut warnings = Vec::new();
    let bbox = part.bbox();
    let extent_mm = (bbox.max[0] - bbox.min[0]).max(bbox.max[2] - bbox.min[2]);
    let knee_mm = knee_extent(knee);
    if extent_mm < knee_mm / SMALL_FACTOR {
        warnings.push(Warning::TooSmall { extent_mm, knee_mm });
    } else if extent_mm < knee_mm / UNITS_FACTOR {
        warnings.push(Warning::Small { extent_mm, knee_mm });
    } else if extent_mm > knee_mm * LARGE_FACTOR {
        warnings.push(Warning::TooLarge {
            extent_mm,
            knee_mm,
            ratio: extent_mm / knee_mm,
        });
    }
    let (plus, minus) = facing_areas(part);
    let (analysed_area, away_area) = match side {
        Side::Left => (minus, plus),
        Side::Right => (plus, minus),
    };
    if away_area > FACING_RATIO * analysed_area {
        let (side, other, analysed, faces) = match side {
            Side::Left => ("left", "right", "-y", "+y"),
            Side::Right => ("right", "left", "+y", "-y"),
        };
        warnings.push(Warning::WrongSide {
            side,
            other,
            analysed,
            faces,
            percent: 100.0 * away_area / (plus + minus),
        });
    }
    warnings
}

/// The check of a part analysed by the slide (the knee pushed along y)
/// for a surface met edge-on ([`EDGE_ON_RATIO`]), with the `--frame` that
/// would face it, as the part's own axes, where `framed` is false (no
/// `--frame` given); with one, the advice is to check it.
pub(crate) fn facing_axis_warning(part: &Part, framed: bool) -> Option<Warning> {
    let facing = axis_facing_areas(part);
    let area = facing.map(|(plus, minus)| plus + minus);
    let total: f64 = area.iter().sum();
    let (k, along) = if area[0] >= area[2] {
        (0, area[0])
    } else {
        (2, area[2])
    };
    if total.is_nan() || total <= 0.0 || along <= EDGE_ON_RATIO * area[1] {
        return None;
    }
    // The rotation whose vehicle y is the part's axis k, signed so that
    // the side facing +k (the larger share) faces the knee of the left
    // side, at -y.
    let plus = facing[k].0 >= facing[k].1;
    let (axis, frame) = match (k, plus) {
        (0, true) => ("x", "y,-x,z"),
        (0, false) => ("x", "-y,x,z"),
        (_, true) => ("z", "x,-z,y"),
        (_, false) => ("z", "x,z,-y"),
    };
    let advice = if framed {
        "check --frame: it should turn the face the knee meets towards y".to_string()
    } else {
        format!(
            "if its large faces are the ones the knee meets, pass --frame {frame} (the part's axes as the vehicle's x, y, z), or model it facing y"
        )
    };
    Some(Warning::EdgeOn {
        axis,
        percent: 100.0 * along / total,
        y_percent: 100.0 * area[1] / total,
        advice,
    })
}

/// The angles (degrees) beyond the regulation's range, as one warning.
pub(crate) fn angle_warnings(angles_deg: &[f64]) -> Vec<Warning> {
    // Within rounding of a range's step arithmetic, 30 is 30.
    let mut outside: Vec<f64> = angles_deg
        .iter()
        .copied()
        .filter(|a| a.abs() > REGULATION_ANGLE_DEG + 1e-9)
        .collect();
    if outside.is_empty() {
        return Vec::new();
    }
    outside.sort_by(f64::total_cmp);
    // A warning is one line: a long list is said by its count and ends.
    let angles = if outside.len() > 8 {
        format!(
            "{}, {}, ..., {} ({} in all)",
            outside[0],
            outside[1],
            outside[outside.len() - 1],
            outside.len()
        )
    } else {
        outside
            .iter()
            .map(f64::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    vec![Warning::AnglesOutsideRegulation { angles }]
}

/// The blind spots the knee-form meets (contacts the grid cannot see), as
/// one warning; where they are is said in the part's coordinates, through
/// `placement` (the spots lie in the analysis grid's frame).
pub(crate) fn blind_spot_warnings(
    spots: &[crate::blind::BlindSpot],
    placement: &crate::frame::Placement,
) -> Vec<Warning> {
    let near: Vec<&crate::blind::BlindSpot> = spots
        .iter()
        .filter(|s| !s.met_angles_deg.is_empty())
        .collect();
    let Some(first) = near.first() else {
        return Vec::new();
    };
    let mut angles: Vec<f64> = near.iter().flat_map(|s| s.met_angles_deg.clone()).collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    let [x, y, z] = first.in_part(placement);
    vec![Warning::BlindSpotsMet {
        count: near.len(),
        depth_mm: near.iter().map(|s| s.depth_missed_mm).fold(0.0, f64::max),
        angles: angle_list(&angles),
        x,
        y,
        z,
        resolves: resolving_phrase(
            near.iter()
                .map(|s| s.resolving_pitch_mm)
                .fold(f64::INFINITY, f64::min),
        ),
    }]
}

/// The advice for blind spots resolved at `pitch` mm: a pitch kneeform
/// accepts, rounded down to three significant digits (rounded up, it might
/// not resolve them), or, below [`crate::limits::MIN_PITCH_MM`], that none
/// does (a feature narrower than that: an edge seen edge-on, a sheet of no
/// thickness).
pub(crate) fn resolving_phrase(pitch: f64) -> String {
    let min = crate::limits::MIN_PITCH_MM;
    if pitch.is_nan() || pitch < min {
        return format!(
            "no pitch kneeform accepts (down to {min} mm) resolves them: they are narrower than that (an edge seen edge-on, a sheet of no thickness)"
        );
    }
    let digits = 2 - pitch.log10().floor() as i32;
    let scale = 10f64.powi(digits);
    let readable = ((pitch * scale).floor() / scale).max(min);
    format!("--pitch {} resolves them", crate::limits::short(readable))
}

/// Angles as ranges of whole degrees where they run on: `-30..-12, 0, 7`.
fn angle_list(sorted: &[f64]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut k = 0;
    while k < sorted.len() {
        let mut end = k;
        while end + 1 < sorted.len() && (sorted[end + 1] - sorted[end] - 1.0).abs() < 1e-9 {
            end += 1;
        }
        parts.push(if end > k + 1 {
            format!("{}..{}", sorted[k], sorted[end])
        } else if end == k + 1 {
            format!("{}, {}", sorted[k], sorted[end])
        } else {
            sorted[k].to_string()
        });
        k = end + 1;
    }
    parts.join(", ")
}

/// The checks of a result: `composite_nodes` is the number of nodes
/// struck at some angle.
pub(crate) fn result_warnings(composite_nodes: usize) -> Vec<Warning> {
    if composite_nodes == 0 {
        vec![Warning::NothingStruck]
    } else {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resolving_pitch_is_one_the_tool_accepts_and_reads_short() {
        assert_eq!(resolving_phrase(0.5), "--pitch 0.5 resolves them");
        assert_eq!(resolving_phrase(0.0078125), "--pitch 0.00781 resolves them");
        assert_eq!(resolving_phrase(0.15625), "--pitch 0.156 resolves them");
        assert_eq!(resolving_phrase(1.0), "--pitch 1 resolves them");
        for tiny in [5.774e-10, 3.7e-9, 1.9e-9, 0.0, f64::NAN] {
            assert!(
                resolving_phrase(tiny).starts_with("no pitch kneeform accepts"),
                "{tiny}"
            );
        }
    }
    use crate::mesh::Triangle;

    /// A w x w square in the plane y = 0, wound to face -y (`toward_minus`)
    /// or +y, plus `back` times its area wound the other way (at y = 50).
    fn sheet(w: f64, toward_minus: bool, back: f64) -> Vec<Triangle> {
        // (0,0,0) -> (w,0,0) -> (0,0,w): u x v = (0, -w^2, 0), facing -y.
        let face = |y: f64, s: f64, minus: bool| -> Vec<Triangle> {
            let a = [0.0, y, 0.0];
            let b = [s, y, 0.0];
            let c = [0.0, y, s];
            let d = [s, y, s];
            if minus {
                vec![[a, b, c], [b, d, c]]
            } else {
                vec![[a, c, b], [b, c, d]]
            }
        };
        let mut t = face(0.0, w, toward_minus);
        if back > 0.0 {
            t.extend(face(50.0, w * back.sqrt(), !toward_minus));
        }
        t
    }

    fn part(t: Vec<Triangle>, side: Side) -> Part {
        Part::from_triangles("sheet", t, 1.0, side).unwrap()
    }

    #[test]
    fn facing_areas_follow_the_winding_in_the_parts_own_frame() {
        let (plus, minus) = facing_areas(&part(sheet(10.0, true, 0.0), Side::Left));
        assert_eq!((plus, minus), (0.0, 100.0));
        // Read as the right side (mirrored), the same file still faces -y.
        let (plus, minus) = facing_areas(&part(sheet(10.0, true, 0.0), Side::Right));
        assert_eq!((plus, minus), (0.0, 100.0));
        let (plus, minus) = facing_areas(&part(sheet(10.0, false, 0.25), Side::Left));
        assert!((plus - 100.0).abs() < 1e-9 && (minus - 25.0).abs() < 1e-9);
    }

    /// The bundled console side modelled in inches (1,500 mm: 59 "mm"
    /// across) is warned of, naming `--scale 25.4`; a part just over a
    /// quarter of the knee-form, and the console in mm, are not.
    #[test]
    fn a_part_under_a_quarter_of_the_knee_form_is_warned_of_its_units() {
        let knee = KneeForm::default();
        let quarter = knee_extent(&knee) / UNITS_FACTOR;
        let small = |w: &Warning| matches!(w, Warning::Small { .. });
        let w = part_warnings(
            &part(sheet(1500.0 / 25.4, true, 0.0), Side::Left),
            Side::Left,
            &knee,
        );
        assert!(w.iter().any(small), "{w:?}");
        assert!(w[0].to_string().contains("--scale 25.4"), "{}", w[0]);
        let p = part(sheet(quarter * 1.01, true, 0.0), Side::Left);
        assert!(part_warnings(&p, Side::Left, &knee).is_empty());
        let p = part(sheet(quarter * 0.99, true, 0.0), Side::Left);
        assert!(part_warnings(&p, Side::Left, &knee).iter().any(small));
        let p = part(sheet(1500.0, true, 0.0), Side::Left);
        assert!(part_warnings(&p, Side::Left, &knee).is_empty());
    }

    #[test]
    fn a_surface_facing_away_from_the_side_is_flagged_and_a_solid_is_not() {
        let knee = KneeForm::default();
        let wrong = |w: &Warning| matches!(w, Warning::WrongSide { .. });
        // Facing +y, analysed as left: flagged, and the message says what to do.
        let w = part_warnings(
            &part(sheet(400.0, false, 0.0), Side::Left),
            Side::Left,
            &knee,
        );
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].to_string().contains("--side right"), "{}", w[0]);
        // The same file as the right side: fine.
        let p = part(sheet(400.0, false, 0.0), Side::Right);
        assert!(part_warnings(&p, Side::Right, &knee).is_empty());
        // Facing -y read as the right side: flagged the other way.
        let p = part(sheet(400.0, true, 0.0), Side::Right);
        let w = part_warnings(&p, Side::Right, &knee);
        assert!(w.iter().any(wrong) && w[0].to_string().contains("--side left"));
        // Just under the ratio (a back face of a third of the front): not
        // flagged; a closed solid (equal areas): not flagged.
        let p = part(sheet(400.0, false, 0.34), Side::Left);
        assert!(!part_warnings(&p, Side::Left, &knee).iter().any(wrong));
        let p = part(sheet(400.0, false, 0.32), Side::Left);
        assert!(part_warnings(&p, Side::Left, &knee).iter().any(wrong));
        let p = part(sheet(400.0, false, 1.0), Side::Left);
        assert!(part_warnings(&p, Side::Left, &knee).is_empty());
    }

    /// Issue 24, item 8: a plate facing z (and one facing x) was analysed
    /// edge-on with no hint. Each is flagged with the frame that faces it,
    /// and that frame, applied, silences the warning; a surface facing y
    /// and a closed box of even sides are not flagged.
    #[test]
    fn a_part_facing_away_from_the_push_axis_is_flagged_with_its_frame() {
        use crate::frame::Frame;
        // A 200 x 200 mm square in the plane y = 0, turned to face each
        // axis by a frame's inverse.
        let square = sheet(200.0, true, 0.0);
        for (faces, frame) in [
            ("x,-z,y", "x,-z,y"),
            ("y,-x,z", "y,-x,z"),
            ("x,z,-y", "x,z,-y"),
            ("-y,x,z", "-y,x,z"),
        ] {
            let f = Frame::parse(faces).unwrap();
            // The plate as modelled: the vehicle-facing square mapped back.
            let modelled: Vec<Triangle> = square.iter().map(|t| t.map(|v| f.to_part(v))).collect();
            let p = part(modelled.clone(), Side::Left);
            let w = facing_axis_warning(&p, false).expect("edge-on");
            assert!(
                w.to_string().contains(&format!("--frame {frame}")),
                "{faces}: {w}"
            );
            assert!(
                facing_axis_warning(&p, true)
                    .unwrap()
                    .to_string()
                    .contains("check --frame")
            );
            // Placed by the suggested frame, it faces y: no warning.
            let placed: Vec<Triangle> = modelled
                .iter()
                .map(|t| t.map(|v| f.to_vehicle(v)))
                .collect();
            assert_eq!(
                facing_axis_warning(&part(placed, Side::Left), false),
                None,
                "{faces}"
            );
        }
        assert_eq!(facing_axis_warning(&part(square, Side::Left), false), None);
        // A closed cube: a third of its area along each axis (the
        // winding does not matter to how much faces along an axis).
        let mut cube = Vec::new();
        for k in 0..3 {
            for offset in [0.0, 100.0] {
                let at = |u: f64, v: f64| {
                    let mut p = [0.0; 3];
                    p[k] = offset;
                    p[(k + 1) % 3] = u;
                    p[(k + 2) % 3] = v;
                    p
                };
                cube.push([at(0.0, 0.0), at(100.0, 0.0), at(0.0, 100.0)]);
                cube.push([at(100.0, 0.0), at(100.0, 100.0), at(0.0, 100.0)]);
            }
        }
        assert_eq!(facing_axis_warning(&part(cube, Side::Left), false), None);
    }

    #[test]
    fn parts_far_from_a_knee_forms_size_are_flagged() {
        let knee = KneeForm::default();
        assert!((knee_extent(&knee) - 320.0).abs() < 1e-9);
        let size =
            |w: f64| part_warnings(&part(sheet(w, true, 0.0), Side::Left), Side::Left, &knee);
        // A 1.5 m console read in metres.
        let w = size(1.5);
        assert!(matches!(w[..], [Warning::TooSmall { .. }]), "{w:?}");
        assert!(w[0].to_string().contains("--scale 1000"));
        assert!(matches!(size(15.9)[..], [Warning::TooSmall { .. }]));
        assert!(matches!(size(16.1)[..], [Warning::Small { .. }]));
        assert!(size(79.9).len() == 1 && size(80.1).is_empty());
        assert!(size(1500.0).is_empty() && size(9_500.0).is_empty());
        assert!(matches!(size(1.5e6)[..], [Warning::TooLarge { .. }]));
        // A smaller knee-form moves the bounds.
        let small = KneeForm {
            triangle_side: 20.0,
            radius: 6.0,
            thickness: 12.0,
        };
        let p = part(sheet(10.0, true, 0.0), Side::Left);
        assert!(part_warnings(&p, Side::Left, &small).is_empty());
    }

    #[test]
    fn angles_beyond_thirty_degrees_and_an_empty_result_are_flagged() {
        assert!(angle_warnings(&[-30.0, 0.0, 30.0, 30.0 + 1e-12]).is_empty());
        let w = angle_warnings(&[-45.0, 0.0, 30.5]);
        assert_eq!(w.len(), 1);
        assert!(w[0].to_string().contains("-45, 30.5"), "{}", w[0]);
        let many: Vec<f64> = (-900..=900).map(|a| f64::from(a) / 10.0).collect();
        let w = angle_warnings(&many)[0].to_string();
        assert!(
            w.contains("angles -90, -89.9, ..., 90 (1200 in all) degrees"),
            "{w}"
        );
        assert_eq!(result_warnings(0), [Warning::NothingStruck]);
        assert!(result_warnings(1).is_empty());
    }
}
