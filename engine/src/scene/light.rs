//! Local lights, in world space.
use glam::Vec3;

use super::SceneError;

/// The widest spot cone a light may have: shadow-map techniques render a spot light's view with a
/// perspective projection, which degenerates as the cone approaches 180°.
pub const MAX_SPOT_FOV_DEG: f32 = 170.0;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Radiant intensity (W/sr per channel) in every direction.
    Point { position: Vec3, intensity: [f32; 3] },
    /// Radiant intensity inside a cone of full angle `fov_deg` about the unit `direction`.
    Spot { position: Vec3, direction: Vec3, fov_deg: f32, intensity: [f32; 3] },
}

impl Light {
    /// Checks finiteness and ranges; a spot light's direction comes back normalized.
    pub fn validated(self) -> Result<Light, SceneError> {
        let (position, intensity) = match self {
            Light::Point { position, intensity } | Light::Spot { position, intensity, .. } => {
                (position, intensity)
            }
        };
        if !position.is_finite() {
            return Err(SceneError::invalid(format!("light position {position} is not finite")));
        }
        if intensity.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(SceneError::invalid(format!(
                "light intensity {intensity:?} must be finite and >= 0"
            )));
        }
        match self {
            Light::Point { .. } => Ok(self),
            Light::Spot { direction, fov_deg, .. } => {
                if !direction.is_finite() || direction.length_squared() == 0.0 {
                    return Err(SceneError::invalid(format!(
                        "spot light direction {direction} is not a direction"
                    )));
                }
                if !(fov_deg > 0.0 && fov_deg <= MAX_SPOT_FOV_DEG) {
                    return Err(SceneError::invalid(format!(
                        "spot light fov_deg must be in (0, {MAX_SPOT_FOV_DEG}] degrees, got {fov_deg}"
                    )));
                }
                // Leave unit directions untouched so that a written and re-read scene is bit-identical.
                let direction = if direction.is_normalized() { direction } else { direction.normalize() };
                Ok(Light::Spot { position, direction, fov_deg, intensity })
            }
        }
    }

    /// [`Light::validated`] for light `index` of a scene, its error naming the light as every
    /// way of giving a scene lights does (a scene file, the C ABI, a renderer's light changed).
    pub fn validated_as(self, index: usize) -> Result<Light, SceneError> {
        self.validated().map_err(|e| e.within(&format!("light {index}")))
    }
}
