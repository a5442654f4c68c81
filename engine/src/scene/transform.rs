//! Rigid placement of a group: uniform scale, then rotation, then translation.
use glam::{EulerRot, Mat4, Quat, Vec3, Vec4};

use super::SceneError;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    pub translation: Vec3,
    pub rotation: Quat,
    /// Uniform, so normals transform with the rotation alone.
    pub scale: f32,
}

impl Default for Transform {
    fn default() -> Self {
        Transform { translation: Vec3::ZERO, rotation: Quat::IDENTITY, scale: 1.0 }
    }
}

impl Transform {
    /// Object space to world space.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(Vec3::splat(self.scale), self.rotation, self.translation)
    }

    /// Euler angles in degrees as the scene file gives them: R = Rz · Ry · Rx, so X is applied
    /// first, then Y, then Z (all about the fixed world axes).
    pub fn rotation_from_euler_deg(degrees: [f32; 3]) -> Quat {
        let [x, y, z] = degrees.map(f32::to_radians);
        Quat::from_euler(EulerRot::ZYX, z, y, x)
    }

    /// Checks what the renderer relies on: finite values, a positive scale, a rotation that is a
    /// rotation. A quaternion that is only slightly off unit length is renormalized.
    pub fn validated(mut self) -> Result<Transform, SceneError> {
        if !self.translation.is_finite() {
            return Err(SceneError::invalid(format!("translation {} is not finite", self.translation)));
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(SceneError::invalid(format!(
                "scale must be finite and greater than zero, got {}",
                self.scale
            )));
        }
        // Any nonzero finite quaternion names a rotation. Unit ones are left untouched, so that a
        // written and re-read scene is bit-identical; others are divided by their largest
        // component before normalizing, so that a long one (1e20 along an axis, whose squared
        // length overflows) or a tiny one (whose squared length underflows) keeps its rotation.
        let q = Vec4::from(self.rotation);
        let largest = q.abs().max_element();
        if !q.is_finite() || largest == 0.0 {
            return Err(SceneError::invalid(format!("rotation {} is not a rotation", self.rotation)));
        }
        if !self.rotation.is_normalized() {
            self.rotation = Quat::from_vec4((q / largest).normalize());
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One rule for every quaternion: a nonzero finite one is its rotation, however long.
    #[test]
    fn long_and_tiny_quaternions_keep_their_rotation() {
        let with = |rotation: Quat| Transform { rotation, ..Transform::default() }.validated();
        for length in [1e20f32, 1e-30, 3.0] {
            let turned = with(Quat::from_xyzw(length, 0.0, 0.0, 0.0)).unwrap().rotation;
            assert_eq!(turned.to_array(), [1.0, 0.0, 0.0, 0.0], "x = {length}");
        }
        let half = with(Quat::from_xyzw(0.0, 1e20, 0.0, 1e20)).unwrap().rotation;
        assert!(half.abs_diff_eq(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2), 1e-6), "{half}");
        let zero = with(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)).unwrap_err().to_string();
        assert!(zero.contains("is not a rotation"), "{zero}");
        assert!(with(Quat::from_xyzw(f32::INFINITY, 0.0, 0.0, 1.0)).is_err());
    }

    #[test]
    fn euler_applies_x_then_y_then_z() {
        let q = Transform::rotation_from_euler_deg([90.0, 90.0, 0.0]);
        // X first takes +Y to +Z, then Y takes +Z to +X.
        assert!((q * Vec3::Y - Vec3::X).length() < 1e-6);
        let q = Transform::rotation_from_euler_deg([0.0, 90.0, 90.0]);
        // Y first takes +Z to +X, then Z takes +X to +Y.
        assert!((q * Vec3::Z - Vec3::Y).length() < 1e-6);
        let single = Transform::rotation_from_euler_deg([0.0, 30.0, 0.0]);
        assert!(single.abs_diff_eq(Quat::from_rotation_y(30f32.to_radians()), 1e-6));
    }

    #[test]
    fn matrix_scales_then_rotates_then_translates() {
        let t = Transform {
            translation: Vec3::new(1.0, 2.0, 3.0),
            rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            scale: 2.0,
        };
        let p = t.matrix().transform_point3(Vec3::Z);
        assert!((p - Vec3::new(3.0, 2.0, 3.0)).length() < 1e-5);
    }

    #[test]
    fn bad_transforms_are_rejected() {
        let ok = Transform::default();
        assert!(ok.validated().is_ok());
        for scale in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(Transform { scale, ..ok }.validated().unwrap_err().to_string().contains("scale"));
        }
        assert!(Transform { translation: Vec3::new(0.0, f32::NAN, 0.0), ..ok }.validated().is_err());
        assert!(Transform { rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), ..ok }.validated().is_err());
    }
}
