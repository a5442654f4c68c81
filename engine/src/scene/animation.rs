//! The scripted motion of `kage render --animate`, one of two kinds:
//! - a scene with a walkthrough ([`super::Scene::walkthrough`]) moves its camera through the
//!   keyframes ([`camera_at`]) and leaves its groups where they are;
//! - otherwise the scene's first group slides across the floor and back, spinning about +Y and
//!   hopping ([`pose`]). At t = 0 and t = 0.5 it rests in its scene pose (for the teapot:
//!   standing on the floor, the contact case of the soft-shadow method); in between it rises by
//!   up to 40% of its height.
use super::{Camera, Group, SceneError, Transform};
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

/// The camera at time `t` of one cycle through `keys` (`t` wraps): each keyframe gets an equal
/// share of the cycle, moving to the next (the last back to the first) with smoothstep easing,
/// so the camera slows to rest at every keyframe (the close-ups stay in view for a while).
/// Position, target, up and field of view are interpolated linearly; `None` without keys.
pub fn camera_at(keys: &[Camera], t: f32) -> Option<Camera> {
    let n = keys.len();
    let first = keys.first()?;
    let x = t.rem_euclid(1.0) * n as f32;
    let k = (x.floor() as usize).min(n - 1);
    let (a, b) = (&keys[k], &keys[(k + 1) % n]);
    let f = x - k as f32;
    let s = f * f * (3.0 - 2.0 * f);
    let up = a.up.lerp(b.up, s);
    Some(Camera {
        position: a.position.lerp(b.position, s),
        target: a.target.lerp(b.target, s),
        // Opposite up vectors would cancel half-way; keyframes never have them, but stay defined.
        up: if up.length_squared() > 1e-12 { up } else { first.up },
        fov_y_deg: a.fov_y_deg + (b.fov_y_deg - a.fov_y_deg) * s,
    })
}

/// Checks every camera the walkthrough passes through, not only its keyframes: between two
/// valid keyframes the position can run through the target, or the view line up with up. Each
/// step is checked at the position's closest approach to the target and at 64 points.
pub fn check_walkthrough(keys: &[Camera]) -> Result<(), SceneError> {
    let n = keys.len();
    for k in 0..n {
        let (a, b) = (&keys[k], &keys[(k + 1) % n]);
        let (from, to) = (a.position - a.target, b.position - b.target);
        let step = to - from;
        let closest = match step.length_squared() {
            0.0 => 0.0,
            l => (-from.dot(step) / l).clamp(0.0, 1.0),
        };
        let shares = (0..=64).map(|i| i as f32 / 64.0).chain([closest]);
        for s in shares {
            // The time at which `camera_at`'s easing has gone the share `s` of this step.
            let x = (k as f32 + inverse_smoothstep(s)) / n as f32;
            if let Some(camera) = camera_at(keys, x) {
                camera.validated().map_err(|e| {
                    e.within(&format!("the walkthrough between cameras {k} and {}", (k + 1) % n))
                })?;
            }
        }
    }
    Ok(())
}

/// The f in [0, 1] at which smoothstep reaches `s`.
fn inverse_smoothstep(s: f32) -> f32 {
    0.5 - ((1.0 - 2.0 * s).asin() / 3.0).sin()
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

    /// Two valid keyframes on opposite sides of the target: half-way the camera stands on it.
    #[test]
    fn a_walkthrough_through_its_target_is_refused_naming_the_step() {
        let at = |z: f32| Camera {
            position: Vec3::new(0.0, 1.0, z),
            target: Vec3::Y,
            up: Vec3::Y,
            fov_y_deg: 45.0,
        };
        let keys = [at(2.0), at(-2.0)];
        keys.iter().for_each(|k| assert!(k.validated().is_ok()));
        let error = check_walkthrough(&keys).unwrap_err().to_string();
        assert!(error.contains("between cameras 0 and 1") && error.contains("same point"), "{error}");
        let around = [at(2.0), Camera { position: Vec3::new(2.0, 1.0, 0.0), ..at(0.0) }];
        check_walkthrough(&around).unwrap();
    }

    #[test]
    fn the_walkthrough_rests_at_each_keyframe_and_wraps() {
        let key = |x: f32, fov| Camera {
            position: Vec3::new(x, 1.0, 5.0),
            target: Vec3::new(x, 0.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: fov,
        };
        let keys = [key(0.0, 40.0), key(2.0, 20.0), key(-2.0, 60.0)];
        assert_eq!(camera_at(&keys, 0.0), Some(keys[0]));
        assert_eq!(camera_at(&keys, 1.0 / 3.0), Some(keys[1]));
        assert_eq!(camera_at(&keys, 1.0), Some(keys[0]));
        // Half-way from the last key back to the first.
        let back = camera_at(&keys, 5.0 / 6.0).unwrap();
        assert!((back.position.x + 1.0).abs() < 1e-5 && (back.fov_y_deg - 50.0).abs() < 1e-4);
        // Eased: a little after a keyframe the camera has moved much less than linearly.
        let early = camera_at(&keys, 0.05).unwrap();
        assert!(early.position.x > 0.0 && early.position.x < 0.5 * 2.0 * 0.15);
        assert_eq!(camera_at(&[], 0.5), None);
    }

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
