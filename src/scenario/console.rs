//! The closed form of the `console` primitive ([`super::Console`]): a
//! console side the size of the paper's (1500 x 600 mm) as a height field
//! with the features R21 worries about: a global bulge, waves, a ridge with
//! a wavy top, switch-like bosses and a shallow depression behind a
//! protrusion. `scenarios/console.toml`, the benchmark part, is this plus a
//! thin rib, a groove and a diagonal ridge.
//!
//! Analysis frame: the surface faces -y, so a feature standing proud
//! towards the knee has a *smaller* y.

/// The console's extent in x and z (mm), from its own `(0, 0)`.
pub(super) const CONSOLE_SIZE: [f64; 2] = [1500.0, 600.0];

/// A smooth bump of unit height and radius `r` at `(cx, cz)`: `cos^2`
/// falloff, zero outside.
fn bump(x: f64, z: f64, cx: f64, cz: f64, r: f64) -> f64 {
    let d = (x - cx).hypot(z - cz) / r;
    if d >= 1.0 {
        0.0
    } else {
        (d * std::f64::consts::FRAC_PI_2).cos().powi(2)
    }
}

/// A smoothed box of unit height: flat top over `half` half-widths, `cos^2`
/// shoulders of width `edge`.
fn boss(x: f64, z: f64, c: [f64; 2], half: [f64; 2], edge: f64) -> f64 {
    let axis = |u: f64, c: f64, h: f64| {
        let d = ((u - c).abs() - h).max(0.0) / edge;
        if d >= 1.0 {
            0.0
        } else {
            (d * std::f64::consts::FRAC_PI_2).cos().powi(2)
        }
    };
    axis(x, c[0], half[0]) * axis(z, c[1], half[1])
}

/// The console's surface y(x, z) in mm, for x in [0, 1500], z in [0, 600].
pub(super) fn console_height(x: f64, z: f64) -> f64 {
    use std::f64::consts::TAU;
    let [lx, lz] = CONSOLE_SIZE;
    // A bulge towards the knee in the middle of the panel.
    let u = (x / lx - 0.5) * 2.0;
    let v = (z / lz - 0.5) * 2.0;
    let mut y = 25.0 * (u * u + 0.5 * v * v);
    // Waves along x, growing towards the front.
    y += (2.0 + 3.0 * (1.0 - x / lx)) * (TAU * x / 160.0).sin() * bump(x, z, 400.0, 150.0, 260.0);
    // A narrow ridge with a wavy top (the paper's Fig. 6).
    let ridge = boss(x, z, [900.0, 420.0], [350.0, 8.0], 10.0);
    y -= ridge * (12.0 + 3.0 * (TAU * x / 90.0).sin());
    // Switch-like bosses standing 5-10 mm proud.
    for (k, cx) in [1150.0, 1220.0, 1290.0].into_iter().enumerate() {
        y -= (5.0 + 2.5 * k as f64) * boss(x, z, [cx, 200.0], [20.0, 12.0], 3.0);
    }
    // A protrusion with a shallow depression behind it (the paper's Fig. 2b).
    y -= 10.0 * bump(x, z, 600.0, 450.0, 70.0);
    y += 5.0 * bump(x, z, 760.0, 450.0, 80.0);
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn features_stand_proud_towards_the_knee() {
        // The ridge and the bosses have a smaller y than their surroundings.
        assert!(console_height(900.0, 420.0) < console_height(900.0, 380.0) - 5.0);
        // The tallest boss stands 10 mm proud, less the bulge's 1 mm slope.
        assert!(console_height(1290.0, 200.0) < console_height(1290.0, 250.0) - 8.5);
    }
}
