//! The scripted motion of `kage render --animate`: the scene's first group slides across the
//! floor and back, spinning about +Y and hopping. At t = 0 and t = 0.5 it rests in its scene
//! pose (for the teapot: standing on the floor, the contact case of the soft-shadow method);
//! in between it rises by up to 40% of its height.
use super::Transform;
use glam::{Mat4, Quat, Vec3};
use std::f32::consts::TAU;

/// How far the group slides to each side, in units of its own height.
const SLIDE: f32 = 1.0;
const HOP: f32 = 0.4;
/// Full turns about +Y over one cycle.
const TURNS: f32 = 1.0;

/// The pose of a group of height `height` whose scene transform is `base`, at time `t` of one
/// cycle (`t` wraps: 1.0 is 0.0 again).
pub fn pose(base: &Transform, height: f32, t: f32) -> Mat4 {
    let t = t.rem_euclid(1.0);
    let phase = TAU * t;
    let offset = Vec3::new(SLIDE * height * phase.sin(), HOP * height * (2.0 * phase).sin().abs(), 0.0);
    let spin = Quat::from_rotation_y(TURNS * phase);
    Transform { translation: base.translation + offset, rotation: spin * base.rotation, scale: base.scale }
        .matrix()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rests_at_the_start_and_half_way_and_is_periodic() {
        let base = Transform { translation: Vec3::new(0.0, 0.5, 0.0), ..Transform::default() };
        let rest = base.matrix();
        assert!(pose(&base, 1.0, 0.0).abs_diff_eq(rest, 1e-6));
        let half = pose(&base, 1.0, 0.5);
        assert!((half.w_axis.y - 0.5).abs() < 1e-5, "touching the floor again at t = 0.5");
        assert!(pose(&base, 1.0, 0.3).abs_diff_eq(pose(&base, 1.0, 1.3), 1e-5));
        assert!(pose(&base, 1.0, 0.125).w_axis.y > 0.8, "in the air between");
    }
}
