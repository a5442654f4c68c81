//! The camera walkthrough of `kage render --animate` ([`super::Scene::walkthrough`]): the camera
//! moves through the keyframes ([`camera_at`]) over one cycle of the frames. The groups' own
//! motions are in [`super::motion`].
use super::{Camera, SceneError};
#[cfg(test)]
use glam::Vec3;

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
}
