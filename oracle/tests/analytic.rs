//! The oracle against parts whose contacts are known in closed form.

mod util;

use kneeform::scenario::tessellate;
use kneeform_oracle::{
    OracleOptions, Part, SlideEnd, StartStatus, StartTrace, evaluate, trace_start,
};
use util::{knots, linspace};

const R: f64 = 60.0;

/// Tolerance on a witness coordinate along which the knee-form and the
/// mesh are tangent (e.g. z, where the rounded front meets a surface that
/// is straight in z). A gap error `d` moves such a witness by
/// `sqrt(2 R d)`: parry's ~1e-6 mm gives ~0.011 mm, seen up to 0.0083 mm.
const TANGENT_TOL: f64 = 0.03;

/// Tolerance on a witness coordinate along which the gap grows only
/// slowly (e.g. along a plane tilted by k = 0.2 from the face: 5x the gap
/// error). Witnesses come from GJK's simplex and are less exact than the
/// travel they go with: seen 1.7e-4 mm.
const WITNESS_TOL: f64 = 1e-3;

/// Tolerance on a gap (level against the analytic surface at the travel
/// reported): parry3d-f64's time of impact is a lower bound within a few
/// 1e-6 mm on these coordinates (seen 2e-6 mm).
const GAP_TOL: f64 = 1e-5;
const ANGLES: [f64; 5] = [-30.0, -13.0, 0.0, 21.0, 30.0];

fn placed(trace: &StartTrace) -> f64 {
    assert_eq!(trace.status, StartStatus::Placed, "{trace:?}");
    trace.yr_star.unwrap()
}

#[test]
fn flat_wall_gives_its_level_and_no_slide_contact() {
    let c = 37.5;
    let xs = linspace(-600.0, 600.0, 13);
    let zs = linspace(-400.0, 400.0, 9);
    let part = Part::from_triangles(&tessellate(&xs, &zs, |_, _| c)).unwrap();
    let starts = [[-200.0, -100.0], [0.0, 0.0], [150.0, 100.0], [333.3, 17.0]];
    let traces = evaluate(&part, &starts, &ANGLES, &OracleOptions::default()).unwrap();
    assert_eq!(traces.len(), ANGLES.len() * starts.len());
    for trace in &traces {
        let yr = placed(trace);
        assert!((yr - c).abs() < 1e-4, "{trace:?}");
        assert!(trace.contacts.is_empty(), "{trace:?}");
        assert_eq!(trace.slide_end, SlideEnd::Cleared);
    }
    let away = trace_start(&part, [2000.0, 0.0], 0.0, &OracleOptions::default()).unwrap();
    assert_eq!(away.status, StartStatus::NotPlaced);
    assert!(away.contacts.is_empty() && away.yr_star.is_none());
}

/// Default options with a coarser bisection tolerance, so that long
/// contact curves stay a few hundred casts in tests.
fn options() -> OracleOptions {
    OracleOptions {
        witness_tolerance: 0.5,
        ..OracleOptions::default()
    }
}

/// Checks what every trace must satisfy: contacts ordered by travel with
/// non-increasing levels, the witness on the knee-form's y-extent, and the
/// slide level never above `yr* - eps`.
fn assert_well_formed(trace: &StartTrace, options: &OracleOptions) {
    let yr = trace.yr_star.unwrap();
    let mut last = (0.0, yr - options.eps);
    for c in &trace.contacts {
        assert!(c.travel >= last.0 - 1e-6, "{c:?} after {last:?}");
        assert!(c.face_level <= last.1 + 1e-12, "{c:?} after {last:?}");
        // The witness lies on the knee-form, up to its tangential error.
        let w = c.witness;
        assert!(w[1] <= c.face_level + TANGENT_TOL, "{c:?}");
        assert!(
            w[1] >= c.face_level - options.knee_form.width - TANGENT_TOL,
            "{c:?}"
        );
        last = (c.travel, c.face_level);
        // Every contact has its rate: >= 0 (infinite at a riser), with a
        // finite stated error.
        assert!(c.rate >= 0.0, "{c:?}");
        assert!(c.rate_error.is_finite() && c.rate_error >= 0.0, "{c:?}");
    }
}

/// The plane `y = c + k (x - x_r)`, `k > 0`: it comes closer towards -x.
fn tilted_wall(c: f64, k: f64, x_r: f64) -> Part {
    let xs = linspace(-600.0, 600.0, 25);
    let zs = linspace(-400.0, 400.0, 9);
    Part::from_triangles(&tessellate(&xs, &zs, |i, _| c + k * (xs[i] - x_r))).unwrap()
}

#[test]
fn tilted_wall_gives_the_level_under_the_front_of_the_footprint() {
    // y = c + k (x - x_r): the wall comes closer towards -x, so the push
    // touches under the footprint's front point (x0 - R, z0) at any angle
    // within +-30 degrees.
    let (c, k, x_r) = (10.0, 0.2, 0.0);
    let part = tilted_wall(c, k, x_r);
    let starts = [[-100.0, 0.0], [50.0, 35.0], [200.0, -120.0]];
    let options = OracleOptions {
        x_min: -300.0,
        ..options()
    };
    for trace in evaluate(&part, &starts, &ANGLES, &options).unwrap() {
        let [x0, z0] = trace.start;
        let yr = placed(&trace);
        assert!((yr - (c + k * (x0 - R - x_r))).abs() < 1e-4, "{trace:?}");
        let w = trace.push_witness.unwrap();
        assert!((w[0] - (x0 - R)).abs() < TANGENT_TOL, "{trace:?}");
        assert!((w[2] - z0).abs() < TANGENT_TOL, "{trace:?}");
        // Every move in -x collides: contacts start at once and run along
        // the wall, each at the front point, until the grid's -x edge.
        assert_well_formed(&trace, &options);
        assert_eq!(trace.slide_end, SlideEnd::PastXMin, "{trace:?}");
        let first = trace.contacts[0];
        assert!((first.travel - options.eps / k).abs() < 1e-4, "{first:?}");
        for c_pt in &trace.contacts {
            let w = c_pt.witness;
            assert!((w[1] - (c + k * (w[0] - x_r))).abs() < 1e-6, "{c_pt:?}");
            // The front corner (x0 - R - s, f) is on the wall: exact in s.
            let front = x0 - R - c_pt.travel;
            assert!(
                (c_pt.face_level - (c + k * (front - x_r))).abs() < GAP_TOL,
                "{c_pt:?}"
            );
            assert!(
                (w[0] - (x0 - R - c_pt.travel)).abs() < WITNESS_TOL,
                "{c_pt:?}"
            );
            assert!((w[2] - z0).abs() < TANGENT_TOL, "{c_pt:?}");
            assert!(w[0] >= options.x_min);
        }
        let end = trace.contacts.last().unwrap().witness[0];
        assert!(
            end < options.x_min + 0.5,
            "trace stops short of x_min: {end}"
        );
        for pair in trace.contacts.windows(2) {
            let gap = (0..3)
                .map(|a| (pair[1].witness[a] - pair[0].witness[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(gap <= options.witness_tolerance + 1e-9, "{pair:?}");
        }
    }
}

/// Flat at `y = c` behind `x_w`, then a ramp of slope `k` that sticks out
/// towards -x: `y = c - k (x_w - x)` for `-400 <= x < x_w`.
fn ramp_ahead(c: f64, k: f64, x_w: f64) -> (Part, impl Fn(f64) -> f64) {
    let xs = knots(&[linspace(-400.0, x_w, 36), linspace(x_w, 600.0, 13)]);
    let zs = linspace(-400.0, 400.0, 9);
    let g = move |x: f64| if x < x_w { c - k * (x_w - x) } else { c };
    let part = Part::from_triangles(&tessellate(&xs, &zs, |i, _| g(xs[i]))).unwrap();
    (part, g)
}

#[test]
fn ramp_ahead_gives_the_analytic_first_contact_travel_and_contact_curve() {
    let (c, k, x_w) = (0.0, 0.35, -50.0);
    let (part, g) = ramp_ahead(c, k, x_w);
    let options = options();
    let starts = [[100.0, 0.0], [250.0, -40.0]];
    for trace in evaluate(&part, &starts, &ANGLES, &options).unwrap() {
        let [x0, z0] = trace.start;
        assert!((placed(&trace) - c).abs() < 1e-4, "{trace:?}");
        assert_well_formed(&trace, &options);
        // The front point (x0 - R - s, z0) at level c - eps meets the ramp
        // where it reaches c - eps.
        let first = trace.contacts[0];
        let want = (x0 - R) - (x_w - options.eps / k);
        assert!((first.travel - want).abs() < 1e-4, "{first:?} vs {want}");
        for c_pt in &trace.contacts {
            let w = c_pt.witness;
            assert!((w[1] - g(w[0])).abs() < 1e-6, "{c_pt:?}");
            assert!(
                (c_pt.face_level - g(x0 - R - c_pt.travel)).abs() < GAP_TOL,
                "{c_pt:?}"
            );
            assert!((w[1] - c_pt.face_level).abs() < 1e-4, "{c_pt:?}");
            assert!(
                (w[0] - (x0 - R - c_pt.travel)).abs() < WITNESS_TOL,
                "{c_pt:?}"
            );
            assert!((w[2] - z0).abs() < TANGENT_TOL, "{c_pt:?}");
        }
        // The knee-form rides the ramp to its end at x = -400.
        let last = trace.contacts.last().unwrap();
        assert!(last.witness[0] < -399.0, "{last:?}");
        assert_eq!(trace.slide_end, SlideEnd::Cleared);
    }
}

/// A cylindrical bump along z: `y = yc - sqrt(r^2 - (x - xc)^2)` for
/// `|x - xc| < a`, flat `y = c` elsewhere, with `yc = c + sqrt(r^2 - a^2)`.
#[derive(Copy, Clone)]
struct Bump {
    xc: f64,
    r: f64,
    a: f64,
}

impl Bump {
    fn yc(&self, c: f64) -> f64 {
        c + (self.r * self.r - self.a * self.a).sqrt()
    }
    fn peak(&self, c: f64) -> f64 {
        self.yc(c) - self.r
    }
    fn height(&self, c: f64, x: f64) -> Option<f64> {
        let u = x - self.xc;
        (u.abs() < self.a).then(|| self.yc(c) - (self.r * self.r - u * u).sqrt())
    }
    fn knots(&self) -> Vec<f64> {
        // 0.25 mm chords: the sagitta r (1 - cos) stays below 2e-4 mm.
        linspace(
            self.xc - self.a,
            self.xc + self.a,
            (8.0 * self.a) as usize + 1,
        )
    }
    /// Distance from the witness to the bump's circle in the xy-plane.
    fn off_circle(&self, c: f64, w: [f64; 3]) -> f64 {
        ((w[0] - self.xc).hypot(w[1] - self.yc(c)) - self.r).abs()
    }
}

fn bumps_part(c: f64, bumps: &[Bump]) -> Part {
    let mut runs = vec![linspace(-500.0, 500.0, 11)];
    runs.extend(bumps.iter().map(Bump::knots));
    let mut xs: Vec<f64> = runs.concat();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let zs = linspace(-400.0, 400.0, 9);
    let g = |x: f64| bumps.iter().find_map(|b| b.height(c, x)).unwrap_or(c);
    Part::from_triangles(&tessellate(&xs, &zs, |i, _| g(xs[i]))).unwrap()
}

#[test]
fn cylindrical_bump_is_climbed_along_its_circle_and_left_at_its_peak() {
    let c = 5.0;
    let bump = Bump {
        xc: -100.0,
        r: 80.0,
        a: 40.0,
    };
    let part = bumps_part(c, &[bump]);
    let options = OracleOptions {
        witness_tolerance: 0.1,
        ..OracleOptions::default()
    };
    let starts = [[150.0, 0.0], [200.0, 60.0]];
    for trace in evaluate(&part, &starts, &ANGLES, &options).unwrap() {
        let [x0, z0] = trace.start;
        assert!((placed(&trace) - c).abs() < 1e-4, "{trace:?}");
        assert_well_formed(&trace, &options);
        assert!(trace.contacts.len() > 10, "{trace:?}");
        // The face's front corner (x0 - R - s, f, z0) rides the back of
        // the circle: witness on the circle, at the face level, at z0.
        for c_pt in &trace.contacts {
            let w = c_pt.witness;
            assert!(bump.off_circle(c, w) < 5e-4, "{c_pt:?}");
            assert!((w[1] - c_pt.face_level).abs() < 1e-4, "{c_pt:?}");
            // At the peak the face meets the crest line along z, tangent
            // in x too: any point of the crest under the face is a witness,
            // so x and z are only checked where the circle is 0.01 mm or
            // more below the peak.
            if c_pt.face_level > bump.peak(c) + 0.01 {
                assert!(
                    (w[0] - (x0 - R - c_pt.travel)).abs() < WITNESS_TOL,
                    "{c_pt:?}"
                );
                assert!((w[2] - z0).abs() < TANGENT_TOL, "{c_pt:?}");
            }
            // Only the back half of the bump is ever touched.
            assert!(w[0] >= bump.xc - 1e-3, "{c_pt:?}");
        }
        // First contact where the circle reaches c - eps ...
        let first = trace.contacts[0];
        let g = c - options.eps;
        let x_first = bump.xc + (bump.r.powi(2) - (bump.yc(c) - g).powi(2)).sqrt();
        assert!(
            (first.travel - (x0 - R - x_first)).abs() < 2e-3,
            "{first:?} vs {x_first}"
        );
        // ... the last at the peak, then the knee-form clears the part.
        let last = trace.contacts.last().unwrap();
        assert!((last.face_level - bump.peak(c)).abs() < 1e-4, "{last:?}");
        assert_eq!(trace.slide_end, SlideEnd::Cleared);
    }
}

#[test]
fn run_over_a_depression_jumps_from_a_peak_to_the_next_point_that_sticks_out() {
    // A small bump, then (towards -x) a taller one: after the small peak
    // the knee-form runs straight at that level to the taller bump.
    let c = 0.0;
    let small = Bump {
        xc: 0.0,
        r: 60.0,
        a: 20.0,
    };
    let tall = Bump {
        xc: -250.0,
        r: 100.0,
        a: 60.0,
    };
    let (small_peak, tall_peak) = (small.peak(c), tall.peak(c));
    assert!(tall_peak < small_peak);
    let part = bumps_part(c, &[small, tall]);
    let options = options();
    let trace = trace_start(&part, [150.0, 0.0], 0.0, &options).unwrap();
    placed(&trace);
    assert_well_formed(&trace, &options);
    let split = trace
        .contacts
        .iter()
        .position(|c_pt| c_pt.witness[0] < -100.0)
        .expect("the tall bump is reached");
    let (on_small, on_tall) = trace.contacts.split_at(split);
    assert!(
        on_small
            .iter()
            .all(|c_pt| small.off_circle(c, c_pt.witness) < 5e-4)
    );
    assert!(
        on_tall
            .iter()
            .all(|c_pt| tall.off_circle(c, c_pt.witness) < 5e-4)
    );
    // The jump: the last contact on the small bump is at its peak, the
    // first on the tall one at the same level, where the tall circle
    // reaches it.
    let (before, after) = (on_small.last().unwrap(), on_tall[0]);
    assert!((before.face_level - small_peak).abs() < 1e-4, "{before:?}");
    assert!((after.face_level - small_peak).abs() < 1e-4, "{after:?}");
    let x_hit = tall.xc + (tall.r.powi(2) - (tall.yc(c) - small_peak).powi(2)).sqrt();
    assert!(
        (after.witness[0] - x_hit).abs() < 2e-3,
        "{after:?} vs {x_hit}"
    );
    assert!(
        (after.travel - (150.0 - R - x_hit)).abs() < 2e-3,
        "{after:?}"
    );
    let last = trace.contacts.last().unwrap();
    assert!((last.face_level - tall_peak).abs() < 1e-4, "{last:?}");
}

/// `y = c - d` for `x <= x_e` (sticking out), `y = c` behind, with a
/// vertical riser at `x = x_e` (the knot `x_e` is repeated).
fn step(c: f64, d: f64, x_e: f64) -> Part {
    let xs = knots(&[linspace(-500.0, x_e, 10), linspace(x_e, 500.0, 11)]);
    let mut xs_riser = xs.clone();
    let riser = xs.iter().position(|&x| x == x_e).unwrap();
    xs_riser.insert(riser, x_e);
    let zs = linspace(-400.0, 400.0, 9);
    Part::from_triangles(&tessellate(&xs_riser, &zs, |i, _| {
        if i <= riser { c - d } else { c }
    }))
    .unwrap()
}

#[test]
fn step_stops_the_knee_form_at_its_riser_down_to_the_step_level() {
    let (c, d, x_e) = (20.0, 15.0, -30.0);
    let part = step(c, d, x_e);
    let options = options();
    let starts = [[100.0, 0.0], [180.0, 90.0]];
    for trace in evaluate(&part, &starts, &ANGLES, &options).unwrap() {
        let [x0, z0] = trace.start;
        assert!((placed(&trace) - c).abs() < 1e-4, "{trace:?}");
        assert_well_formed(&trace, &options);
        let s = x0 - R - x_e;
        for c_pt in &trace.contacts {
            assert!((c_pt.travel - s).abs() < 1e-4, "{c_pt:?}");
            assert!((c_pt.witness[0] - x_e).abs() < 1e-4, "{c_pt:?}");
            assert!((c_pt.witness[2] - z0).abs() < TANGENT_TOL, "{c_pt:?}");
            assert!(c_pt.witness[1] >= c - d - 1e-4, "{c_pt:?}");
        }
        // Contacts from c - eps down to the step's level, then it is run over.
        let (first, last) = (trace.contacts[0], trace.contacts.last().unwrap());
        assert!((first.face_level - (c - options.eps)).abs() < 1e-12);
        assert!((last.face_level - (c - d)).abs() < 1e-4, "{last:?}");
        assert_eq!(trace.slide_end, SlideEnd::Cleared);
    }
}

#[test]
fn rounded_front_meets_an_edge_along_y_on_the_circle_of_radius_r() {
    // A block sticking out by d for x <= x_e and z <= z_e, with vertical
    // walls: its corner is an edge parallel to y at (x_e, z_e). A start at
    // z0 = z_e + dz, |dz| < R/2, meets it with the rounded front at travel
    // x0 - x_e - sqrt(R^2 - dz^2), at every angle within +-30 degrees.
    let (c, d, x_e, z_e) = (0.0, 30.0, -40.0, 0.0);
    let xs = knots(&[linspace(-500.0, x_e, 10), linspace(x_e, 500.0, 11)]);
    let zs = knots(&[linspace(-400.0, z_e, 9), linspace(z_e, 400.0, 9)]);
    let i_e = xs.iter().position(|&x| x == x_e).unwrap();
    let j_e = zs.iter().position(|&z| z == z_e).unwrap();
    let mut xs2 = xs.clone();
    xs2.insert(i_e, x_e);
    let mut zs2 = zs.clone();
    zs2.insert(j_e, z_e);
    let block = |i: usize, j: usize| if i <= i_e && j <= j_e { c - d } else { c };
    let part = Part::from_triangles(&tessellate(&xs2, &zs2, block)).unwrap();
    let options = options();
    let x0 = 100.0;
    for dz in [5.0, 12.0, 20.0, 29.0] {
        for &angle in &ANGLES {
            let trace = trace_start(&part, [x0, z_e + dz], angle, &options).unwrap();
            assert!((placed(&trace) - c).abs() < 1e-4, "{trace:?}");
            assert_well_formed(&trace, &options);
            let first = trace.contacts[0];
            let want = x0 - x_e - (R * R - dz * dz).sqrt();
            assert!(
                (first.travel - want).abs() < 1e-4,
                "dz {dz} angle {angle}: {first:?} vs {want}"
            );
            assert!((first.witness[0] - x_e).abs() < 1e-4, "{first:?}");
            assert!((first.witness[2] - z_e).abs() < 1e-4, "{first:?}");
        }
    }
}

#[test]
fn batch_output_is_deterministic_and_equals_single_starts() {
    let c = 0.0;
    let part = bumps_part(
        c,
        &[Bump {
            xc: 0.0,
            r: 60.0,
            a: 20.0,
        }],
    );
    let options = options();
    let starts: Vec<[f64; 2]> = (0..6)
        .map(|i| [60.0 + 30.0 * i as f64, -50.0 + 20.0 * i as f64])
        .collect();
    let angles = [-30.0, 0.0, 30.0];
    let one = evaluate(&part, &starts, &angles, &options).unwrap();
    let two = evaluate(&part, &starts, &angles, &options).unwrap();
    assert_eq!(one, two);
    for (a, &angle) in angles.iter().enumerate() {
        for (s, &start) in starts.iter().enumerate() {
            let single = trace_start(&part, start, angle, &options).unwrap();
            assert_eq!(one[a * starts.len() + s], single);
        }
    }
    let bad = OracleOptions {
        eps: 0.0,
        ..options
    };
    assert!(evaluate(&part, &starts, &angles, &bad).is_err());
}

#[test]
fn cast_budget_exhaustion_fails_the_start_and_keeps_its_contacts() {
    let (part, _) = ramp_ahead(0.0, 0.35, -50.0);
    let options = OracleOptions {
        max_casts: 6,
        ..options()
    };
    let trace = trace_start(&part, [100.0, 0.0], 0.0, &options).unwrap();
    assert_eq!(
        trace.status,
        StartStatus::Failed {
            reason: kneeform_oracle::FailureReason::CastBudgetExhausted
        }
    );
    assert_eq!(trace.casts, 6);
    assert!(trace.yr_star.is_some() && !trace.contacts.is_empty());
    assert_eq!(trace.slide_end, SlideEnd::NotRun);
    // Its strikes are unknown, not absent: never a clear start.
    assert!(matches!(
        trace.strikes(0.0),
        Err(kneeform_oracle::FailureReason::CastBudgetExhausted)
    ));
}

/// Writes triangles as an ASCII STL.
fn ascii_stl(triangles: &[[[f64; 3]; 3]]) -> String {
    let mut out = String::from("solid t\n");
    for t in triangles {
        out.push_str(" facet normal 0 0 0\n  outer loop\n");
        for v in t {
            out.push_str(&format!("   vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        out.push_str("  endloop\n endfacet\n");
    }
    out.push_str("endsolid t\n");
    out
}

#[test]
fn a_right_hand_part_read_as_right_traces_like_its_left_hand_mirror() {
    // A parabolic bump rounded to 1/4 mm terraces, in the analysis frame,
    // and its mirror image y -> -y (a right-hand part facing +y); reading
    // the mirror with Side::Right must give the same traces. Coordinates
    // are multiples of 1/4 mm, exact in f32, so the STL round trip is
    // lossless.
    let xs = knots(&[
        linspace(-500.0, -140.0, 10),
        linspace(-140.0, -60.0, 321),
        linspace(-60.0, 500.0, 15),
    ]);
    let zs = linspace(-400.0, 400.0, 9);
    let g = |x: f64| {
        let u: f64 = x + 100.0;
        if u.abs() < 40.0 {
            -(0.25 * (1600.0 - u * u) / 40.0).round() / 4.0
        } else {
            0.0
        }
    };
    let left = tessellate(&xs, &zs, |i, _| g(xs[i]));
    let mirrored: Vec<[[f64; 3]; 3]> = left.iter().map(|t| t.map(|[x, y, z]| [x, -y, z])).collect();
    let read = |triangles: &[[[f64; 3]; 3]], side| {
        let text = ascii_stl(triangles);
        Part::from_stl_reader(&mut std::io::Cursor::new(text), 1.0, side).unwrap()
    };
    let as_left = read(&left, kneeform_oracle::Side::Left);
    let as_right = read(&mirrored, kneeform_oracle::Side::Right);
    assert_eq!(as_left.bounds(), as_right.bounds());
    let options = options();
    let starts = [[150.0, 0.0], [120.0, -30.0]];
    let a = evaluate(&as_left, &starts, &ANGLES, &options).unwrap();
    let b = evaluate(&as_right, &starts, &ANGLES, &options).unwrap();
    // The mirror swaps each triangle's winding back, so the meshes are the
    // same up to vertex order; GJK may then pick another witness where the
    // contact is not unique (the push's face lies on the flat part), so
    // witnesses are compared to TANGENT_TOL, levels and travels tightly.
    for (a, b) in a.iter().zip(&b) {
        assert_eq!(a.status, b.status);
        assert!((a.yr_star.unwrap() - b.yr_star.unwrap()).abs() < 1e-9);
        assert!(!a.contacts.is_empty());
        assert_eq!(a.contacts.len(), b.contacts.len(), "{a:?}\n{b:?}");
        for (p, q) in a.contacts.iter().zip(&b.contacts) {
            assert!((p.travel - q.travel).abs() < 1e-6, "{p:?} {q:?}");
            assert!((p.face_level - q.face_level).abs() < 1e-9, "{p:?} {q:?}");
            assert!(
                (0..3).all(|k| (p.witness[k] - q.witness[k]).abs() < TANGENT_TOL),
                "{p:?} {q:?}"
            );
        }
    }
}

/// SPEC's default deflection threshold: tan 0.5 degrees.
fn sigma_half_degree() -> f64 {
    0.5f64.to_radians().tan()
}

/// What a rate may exceed its stated error by (float arithmetic). The
/// stated error includes parry's gap error: on the planes below it held
/// with 4e-6 to spare, rates within 8e-4 of the slope (relative), errors
/// stated up to 2.5e-3.
const RATE_TOL: f64 = 1e-9;

#[test]
fn ramp_contacts_have_its_slope_as_their_rate_and_strike_only_when_steeper_than_sigma() {
    // Slopes on either side of tan 0.5 degrees (0.0087) and tan 3 degrees
    // (0.0524). On the tilted wall the knee-form climbs from its first move
    // (the first contact's rate is the chord from the push pose); on the
    // ramp ahead it runs flat and then lands on the ramp.
    let sigmas = [sigma_half_degree(), 3f64.to_radians().tan()];
    let options = OracleOptions {
        x_min: -300.0,
        ..options()
    };
    for k in [0.35, 0.03, 0.012, 0.005] {
        let wall = tilted_wall(10.0, k, 0.0);
        let (ramp, _) = ramp_ahead(0.0, k, -50.0);
        for part in [&wall, &ramp] {
            let starts = [[100.0, 0.0], [150.0, 35.0]];
            for trace in evaluate(part, &starts, &[-30.0, 0.0, 21.0], &options).unwrap() {
                placed(&trace);
                assert_well_formed(&trace, &options);
                assert!(trace.contacts.len() > 10, "{trace:?}");
                for c in &trace.contacts {
                    assert!(
                        (c.rate - k).abs() <= c.rate_error + RATE_TOL,
                        "k {k}: {c:?}"
                    );
                    // A plane leaves only rounding.
                    assert!(c.rate_error < 0.01 * k, "k {k}: {c:?}");
                }
                for sigma in sigmas {
                    let strikes = trace.strikes(sigma).unwrap().count();
                    let want = if k > sigma { trace.contacts.len() } else { 0 };
                    assert_eq!(strikes, want, "k {k} sigma {sigma}");
                }
            }
        }
    }
}

#[test]
fn riser_contacts_have_infinite_rate_and_are_strikes_at_any_threshold() {
    let (c, d, x_e) = (20.0, 15.0, -30.0);
    let part = step(c, d, x_e);
    let options = options();
    let starts = [[100.0, 0.0], [180.0, 90.0]];
    for trace in evaluate(&part, &starts, &ANGLES, &options).unwrap() {
        placed(&trace);
        assert_well_formed(&trace, &options);
        // Every contact is on the riser, at one travel: a drop at constant
        // travel, on one side at least.
        assert!(trace.contacts.len() >= 2, "{trace:?}");
        for c_pt in &trace.contacts {
            assert_eq!(c_pt.rate, f64::INFINITY, "{c_pt:?}");
            assert_eq!(c_pt.rate_error, 0.0, "{c_pt:?}");
        }
        for sigma in [0.0, sigma_half_degree(), 1e12] {
            let strikes: Vec<_> = trace.strikes(sigma).unwrap().copied().collect();
            assert_eq!(strikes, trace.contacts);
        }
    }
    // A start that is not placed strikes nothing.
    let away = trace_start(&part, [2000.0, 0.0], 0.0, &options).unwrap();
    assert_eq!(away.status, StartStatus::NotPlaced);
    assert_eq!(away.strikes(0.0).unwrap().count(), 0);
}

/// The rate of the faceted bump profile under the front point `x`: the
/// slope `dy/dx` of the facet it is on (SPEC's `-df/ds`, since the front
/// point is at `x0 - R - s` and the level follows the profile), as the
/// range of the two facets' slopes when `x` is within `tol` of a knot
/// (there either may be the contact's), and 0 off the bumps.
fn faceted_rate(c: f64, bumps: &[Bump], x: f64, tol: f64) -> (f64, f64) {
    let Some(bump) = bumps.iter().find(|b| (x - b.xc).abs() < b.a + tol) else {
        return (0.0, 0.0);
    };
    let knots = bump.knots();
    let height = |x: f64| bump.height(c, x).unwrap_or(c);
    let slope = |i: usize| match (knots.get(i), knots.get(i + 1)) {
        (Some(&a), Some(&b)) => (height(b) - height(a)) / (b - a),
        _ => 0.0,
    };
    let facets: Vec<f64> = (0..=knots.len())
        .filter(|&i| {
            let lo = if i == 0 {
                f64::NEG_INFINITY
            } else {
                knots[i - 1]
            };
            let hi = knots.get(i).copied().unwrap_or(f64::INFINITY);
            x > lo - tol && x < hi + tol
        })
        .map(|i| if i == 0 { 0.0 } else { slope(i - 1) })
        .collect();
    let lo = facets.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = facets.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo, hi)
}

/// Checks every contact's rate against the faceted profile's, within its
/// stated error, and the strikes at several thresholds wherever the
/// stated error decides them.
fn assert_rates_follow_the_profile(c: f64, bumps: &[Bump], trace: &StartTrace) {
    let x0 = trace.start[0];
    // The front point's x is known to the travel's accuracy: parry's gap
    // error over the slope, ~1e-6 / 0.002 mm at the flattest facet.
    let tol = 2e-3;
    for c_pt in &trace.contacts {
        let (lo, hi) = faceted_rate(c, bumps, x0 - R - c_pt.travel, tol);
        assert!(
            c_pt.rate >= lo - c_pt.rate_error - RATE_TOL
                && c_pt.rate <= hi + c_pt.rate_error + RATE_TOL,
            "{c_pt:?} vs {lo}..{hi}"
        );
    }
    for sigma in [sigma_half_degree(), 0.05, 0.3] {
        let strikes: Vec<f64> = trace.strikes(sigma).unwrap().map(|c| c.travel).collect();
        for c_pt in &trace.contacts {
            let (lo, hi) = faceted_rate(c, bumps, x0 - R - c_pt.travel, tol);
            let struck = strikes.contains(&c_pt.travel);
            if lo - c_pt.rate_error > sigma {
                assert!(struck, "sigma {sigma}: {c_pt:?} vs {lo}");
            }
            if hi + c_pt.rate_error < sigma {
                assert!(!struck, "sigma {sigma}: {c_pt:?} vs {hi}");
            }
        }
    }
}

#[test]
fn bump_rates_follow_its_facets_and_fall_to_zero_at_the_crest() {
    let c = 5.0;
    let bump = Bump {
        xc: -100.0,
        r: 80.0,
        a: 40.0,
    };
    let part = bumps_part(c, &[bump]);
    let options = OracleOptions {
        witness_tolerance: 0.1,
        ..OracleOptions::default()
    };
    let starts = [[150.0, 0.0], [200.0, 60.0]];
    for trace in evaluate(&part, &starts, &ANGLES, &options).unwrap() {
        placed(&trace);
        assert_well_formed(&trace, &options);
        assert_rates_follow_the_profile(c, &[bump], &trace);
        // Rates fall from the foot of the bump, where the circle's slope is
        // a / sqrt(r^2 - a^2) = 0.577, to the crest: the circle's slope
        // only decreases as the knee-form climbs it.
        let first = trace.contacts[0];
        let foot = bump.a / (bump.r.powi(2) - bump.a.powi(2)).sqrt();
        assert!((first.rate - foot).abs() < 0.01, "{first:?} vs {foot}");
        for pair in trace.contacts.windows(2) {
            assert!(
                pair[1].rate <= pair[0].rate + pair[0].rate_error + pair[1].rate_error,
                "{pair:?}"
            );
        }
        // At the crest the rate is that of the last facet, 0.125 / r.
        let last = trace.contacts.last().unwrap();
        assert!(last.rate < 0.125 / bump.r + last.rate_error, "{last:?}");
        assert!(last.rate < 0.5 * sigma_half_degree(), "{last:?}");
    }
}

#[test]
fn run_over_a_depression_leaves_the_crest_flat_and_lands_at_the_next_bumps_slope() {
    let c = 0.0;
    let small = Bump {
        xc: 0.0,
        r: 60.0,
        a: 20.0,
    };
    let tall = Bump {
        xc: -250.0,
        r: 100.0,
        a: 60.0,
    };
    let bumps = [small, tall];
    let part = bumps_part(c, &bumps);
    let options = options();
    let trace = trace_start(&part, [150.0, 0.0], 0.0, &options).unwrap();
    placed(&trace);
    assert_well_formed(&trace, &options);
    assert_rates_follow_the_profile(c, &bumps, &trace);
    let landing = trace
        .contacts
        .iter()
        .position(|c_pt| c_pt.witness[0] < -100.0)
        .expect("the tall bump is reached");
    // The small bump's crest: the knee-form leaves it flat, so its rate is
    // its last facet's, 0.125 / 60 (not a strike at 0.5 degrees).
    let crest = trace.contacts[landing - 1];
    assert!(crest.rate < 0.125 / small.r + crest.rate_error, "{crest:?}");
    assert_eq!(
        trace
            .strikes(sigma_half_degree())
            .unwrap()
            .filter(|c| c.travel == crest.travel)
            .count(),
        0
    );
    // The landing: the tall circle's slope where it reaches the small
    // peak's level, steep enough to strike.
    let after = trace.contacts[landing];
    let u = (tall.r.powi(2) - (tall.yc(c) - small.peak(c)).powi(2)).sqrt();
    let slope = u / (tall.r.powi(2) - u * u).sqrt();
    assert!((after.rate - slope).abs() < 0.01, "{after:?} vs {slope}");
    assert!(slope > sigma_half_degree());
    assert!(
        trace
            .strikes(sigma_half_degree())
            .unwrap()
            .any(|c| c.travel == after.travel)
    );
}
