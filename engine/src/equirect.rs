//! Kage's equirectangular convention, which the environment maps, the SH projection and the
//! reference share: a leaf module (it imports no other), so that the scene's sun maps and the SH
//! code can both use it without one depending on the other.
use glam::DVec3;
use std::f64::consts::PI;

/// Exact solid angle of one texel in row `row` of a `width`×`height` equirectangular map:
/// `(2π / width)·(cos θ0 − cos θ1)` with `θ = π·row / height` at the row's top and bottom edges.
/// A texel outside the map covers no solid angle (0).
pub fn equirect_texel_solid_angle(width: u32, height: u32, row: u32) -> f64 {
    if width == 0 || row >= height {
        return 0.0;
    }
    let theta = |r: u32| PI * f64::from(r) / f64::from(height);
    (2.0 * PI / f64::from(width)) * (theta(row).cos() - theta(row + 1).cos())
}

/// The direction at equirectangular coordinates `(u, v)` (README, "Conventions"):
/// `θ = πv`, `φ = 2πu`, direction `(sin θ sin φ, cos θ, −sin θ cos φ)`; the inverse of
/// `u = atan2(x, −z)/(2π)`, `v = acos(y)/π`. So u = 0 looks down −Z, u = 0.25 down +X, and
/// v = 0 (row 0) is straight up.
pub fn equirect_direction(u: f64, v: f64) -> DVec3 {
    let (sin_t, cos_t) = (PI * v).sin_cos();
    let (sin_p, cos_p) = (2.0 * PI * u).sin_cos();
    DVec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}
