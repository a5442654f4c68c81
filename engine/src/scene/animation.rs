//! The scripted motion of `kage render --animate`: the scene's first group slides across the
//! floor and back, spinning about +Y and hopping. At t = 0 and t = 0.5 it rests in its scene
//! pose (for the teapot: standing on the floor, the contact case of the soft-shadow method);
//! in between it rises by up to 40% of its height.
use super::{Group, Transform};
use glam::{Quat, Vec3};
use std::f32::consts::TAU;

/// How far the group slides to each side, in units of its own height.
const SLIDE: f32 = 1.0;
const HOP: f32 = 0.4;
/// Full turns about +Y over one cycle.
const TURNS: f32 = 1.0;

/// The pose of `group` (moving from its scene transform) at time `t` of one cycle (`t` wraps:
/// 1.0 is 0.0 again).
pub fn pose(group: &Group, t: f32) -> Transform {
    motion(&group.transform, height(group), t)
}

/// The group's height in world units (its object-space extent along Y times its scale): the
/// motion scales with it.
fn height(group: &Group) -> f32 {
    let ys = group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| p[1]));
    let (lo, hi) = ys.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    if lo <= hi {
        (hi - lo) * group.transform.scale
    } else {
        0.0
    }
}

fn motion(base: &Transform, height: f32, t: f32) -> Transform {
    let t = t.rem_euclid(1.0);
    let phase = TAU * t;
    let offset = Vec3::new(SLIDE * height * phase.sin(), HOP * height * (2.0 * phase).sin().abs(), 0.0);
    let spin = Quat::from_rotation_y(TURNS * phase);
    Transform { translation: base.translation + offset, rotation: spin * base.rotation, scale: base.scale }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rests_at_the_start_and_half_way_and_is_periodic() {
        let base = Transform { translation: Vec3::new(0.0, 0.5, 0.0), ..Transform::default() };
        let at = |t| motion(&base, 1.0, t).matrix();
        assert!(at(0.0).abs_diff_eq(base.matrix(), 1e-6));
        assert!((at(0.5).w_axis.y - 0.5).abs() < 1e-5, "touching the floor again at t = 0.5");
        assert!(at(0.3).abs_diff_eq(at(1.3), 1e-5));
        assert!(at(0.125).w_axis.y > 0.8, "in the air between");
    }
}
