//! Synthetic environment maps: one round sun of uniform radiance, alone on black or over a
//! uniform sky and ground. They are the hard case of environment lighting (a small, very bright
//! source whose shadows must stay sharp), with a ground truth that is easy to reason about.
//!
//! Directions follow the map convention ([`super::envmap`]): a sun at elevation e above the
//! horizon and azimuth a sits at (cos e · sin a, sin e, −cos e · cos a), so azimuth 0 is −Z (the
//! left edge of the map, behind the default scene's teapot seen from its camera) and azimuth 90°
//! is +X. Texels whose centre lies within the sun's angular radius of its direction take the
//! sun's radiance; the others the sky's (above the horizon) or the ground's (below).
use super::{EnvMap, SceneError};
use glam::DVec3;

/// A sun map's description (`kage env sun` takes the same parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunMap {
    /// Map width in texels (height is half of it).
    pub width: u32,
    /// Degrees above the horizon, −90 to 90.
    pub elevation_deg: f64,
    /// Degrees from −Z towards +X.
    pub azimuth_deg: f64,
    /// Angular radius of the sun's disk, degrees (0 < r ≤ 45).
    pub radius_deg: f64,
    /// The sun's radiance, RGB.
    pub radiance: [f32; 3],
    /// Radiance of every other texel above the horizon.
    pub sky: [f32; 3],
    /// Radiance of every texel below the horizon.
    pub ground: [f32; 3],
}

impl SunMap {
    /// The issue-style sun: 2° radius, radiance 2000, nothing else, 1024×512.
    pub const DEFAULT: SunMap = SunMap {
        width: 1024,
        elevation_deg: 45.0,
        azimuth_deg: 90.0,
        radius_deg: 2.0,
        radiance: [2000.0; 3],
        sky: [0.0; 3],
        ground: [0.0; 3],
    };

    /// The sun's unit direction.
    pub fn direction(&self) -> DVec3 {
        let (e, a) = (self.elevation_deg.to_radians(), self.azimuth_deg.to_radians());
        DVec3::new(e.cos() * a.sin(), e.sin(), -e.cos() * a.cos())
    }

    /// The map; a parameter out of range is an error naming it.
    pub fn map(&self) -> Result<EnvMap, SceneError> {
        let bad = |what: String| Err(SceneError::invalid(format!("sun map: {what}")));
        if !(2..=16384).contains(&self.width) || self.width % 2 != 0 {
            return bad(format!("width {} must be even, 2 to 16384", self.width));
        }
        if !(self.elevation_deg.is_finite() && self.elevation_deg.abs() <= 90.0) {
            return bad(format!("elevation {}° must be -90 to 90", self.elevation_deg));
        }
        if !self.azimuth_deg.is_finite() {
            return bad(format!("azimuth {}° must be finite", self.azimuth_deg));
        }
        if !(self.radius_deg > 0.0 && self.radius_deg <= 45.0) {
            return bad(format!("radius {}° must be above 0 and at most 45", self.radius_deg));
        }
        for (name, rgb) in [("radiance", self.radiance), ("sky", self.sky), ("ground", self.ground)] {
            if rgb.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
                return bad(format!("{name} {rgb:?} must be finite and >= 0"));
            }
        }
        let (w, h) = (self.width, self.width / 2);
        let sun = self.direction();
        let cos_radius = self.radius_deg.to_radians().cos();
        let mut covered = 0usize;
        let pixels = (0..w * h)
            .map(|t| {
                let (x, y) = (t % w, t / w);
                let d = crate::equirect::equirect_direction(
                    (x as f64 + 0.5) / w as f64,
                    (y as f64 + 0.5) / h as f64,
                );
                if d.dot(sun) >= cos_radius {
                    covered += 1;
                    self.radiance
                } else if d.y > 0.0 {
                    self.sky
                } else {
                    self.ground
                }
            })
            .collect();
        if covered == 0 {
            return bad(format!(
                "a sun of {}° radius covers no texel centre of a {w}x{h} map: widen it or the map",
                self.radius_deg
            ));
        }
        EnvMap::from_pixels(w, h, pixels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::equirect::equirect_texel_solid_angle;

    /// The disk's texels add up to its solid angle 2π(1 − cos r) within the texels along its rim.
    #[test]
    fn the_sun_covers_its_solid_angle_where_the_convention_says() {
        let sun = SunMap { elevation_deg: 15.0, ..SunMap::DEFAULT };
        let map = sun.map().unwrap();
        let (w, h) = (map.width(), map.height());
        let mut omega = 0.0;
        let mut centroid = DVec3::ZERO;
        for (t, p) in map.pixels().iter().enumerate() {
            if p[0] > 0.0 {
                let (x, y) = (t as u32 % w, t as u32 / w);
                let d_omega = equirect_texel_solid_angle(w, h, y);
                omega += d_omega;
                centroid += d_omega
                    * crate::equirect::equirect_direction(
                        (x as f64 + 0.5) / w as f64,
                        (y as f64 + 0.5) / h as f64,
                    );
            }
        }
        let exact = 2.0 * std::f64::consts::PI * (1.0 - 2f64.to_radians().cos());
        assert!((omega / exact - 1.0).abs() < 0.05, "{omega} sr against {exact}");
        // From +X, 15° up: the centroid says so.
        assert!(
            centroid.normalize().dot(DVec3::new(15f64.to_radians().cos(), 15f64.to_radians().sin(), 0.0))
                > 0.9999
        );
    }

    #[test]
    fn bad_parameters_are_named() {
        let err = |s: SunMap| s.map().unwrap_err().to_string();
        assert!(err(SunMap { radius_deg: 0.0, ..SunMap::DEFAULT }).contains("radius 0"));
        assert!(err(SunMap { elevation_deg: 91.0, ..SunMap::DEFAULT }).contains("elevation 91"));
        assert!(err(SunMap { width: 3, ..SunMap::DEFAULT }).contains("width 3"));
        assert!(err(SunMap { sky: [f32::NAN, 0.0, 0.0], ..SunMap::DEFAULT }).contains("sky"));
        assert!(err(SunMap { width: 16, radius_deg: 0.1, ..SunMap::DEFAULT }).contains("covers no texel"));
    }
}
