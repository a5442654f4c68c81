//! The frames `kage bench asm` renders: the scene's walkthrough sampled at N frames (as `kage
//! render --animate --frames N` plays it), with the camera held still for R more frames at each
//! keyframe (where a progressive technique converges), and how far the view moves on screen from
//! one frame to the next (where it moves slowly, flickering shadows show).
use kage::scene::animation::camera_at;
use kage::scene::Camera;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Time in the walkthrough's cycle, 0 to 1.
    pub t: f32,
    pub camera: Camera,
    /// The keyframe the camera rests at, for the frames held there and the one arriving.
    pub rest: Option<usize>,
    /// A frame added to the walkthrough's samples: held at a keyframe, or leaving it slowly.
    pub extra: bool,
}

/// How far each frame leaving a keyframe slowly moves along the eased move to the next: a
/// fraction of the move. Smoothstep starts slowly, so these frames move by a tenth of a pixel at
/// first and by about two after four (256² images of the `asm` walkthrough: 0.09 to 2.1 px).
pub const SLOW_STEP: f32 = 0.01;

/// `samples` frames at t = i / samples, and at each keyframe k (t = k / keys): the frame
/// arriving there (a sample where k / keys falls on one, else an extra frame), the camera held
/// for `rest` more frames, then `slow` frames leaving it at [`SLOW_STEP`] of the move each.
pub fn plan(keys: &[Camera], samples: u32, rest: u32, slow: u32) -> Vec<Frame> {
    let (n, k) = (samples as usize, keys.len());
    // Positions on a common denominator n·k: sample i at i·k, keyframe j at j·n.
    let mut entries: Vec<(usize, Option<usize>)> = (0..n).map(|i| (i * k, None)).collect();
    if rest + slow > 0 {
        entries.retain(|&(at, _)| at % n != 0);
        entries.extend((0..k).map(|j| (j * n, Some(j))));
        entries.sort_by_key(|&(at, _)| at);
    }
    let mut frames = Vec::new();
    for (at, key) in entries {
        let t = at as f32 / (n * k) as f32;
        let Some(camera) = camera_at(keys, t) else { continue };
        let Some(j) = key else {
            frames.push(Frame { t, camera, rest: None, extra: false });
            continue;
        };
        let rest_at = (rest > 0).then_some(j);
        let sample = at % k == 0;
        frames.push(Frame { t, camera, rest: rest_at, extra: !sample });
        frames.extend((0..rest).map(|_| Frame { t, camera, rest: rest_at, extra: true }));
        for i in 1..=slow {
            let t = (j as f32 + i as f32 * SLOW_STEP) / k as f32;
            let camera = camera_at(keys, t).expect("keys are not empty");
            frames.push(Frame { t, camera, rest: None, extra: true });
        }
    }
    frames
}

/// How far the view moves on screen from camera `a` to `b`, in pixels of an image `height`
/// pixels tall: the turn of the view direction, the move of the position seen from the target
/// (parallax at the distance the camera looks at) and the zoom at the image's edge, added. An
/// estimate of the motion of what the camera looks at, not of every pixel.
pub fn motion_px(a: &Camera, b: &Camera, height: u32) -> f32 {
    let pixel = a.fov_y_deg.to_radians() / height as f32;
    let forward = |c: &Camera| (c.target - c.position).normalize();
    // atan2 of the sine and cosine: acos loses small angles to rounding.
    let (u, v) = (forward(a), forward(b));
    let turn = u.cross(v).length().atan2(u.dot(v));
    let parallax = a.position.distance(b.position) / a.target.distance(a.position);
    let half_tan = |c: &Camera| (0.5 * c.fov_y_deg.to_radians()).tan();
    let zoom = (1.0 - half_tan(b) / half_tan(a)).abs() * 0.5 * height as f32;
    (turn + parallax) / pixel + zoom
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn key(x: f32) -> Camera {
        Camera {
            position: Vec3::new(x, 1.0, 5.0),
            target: Vec3::new(x, 0.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 40.0,
        }
    }

    #[test]
    fn samples_the_walkthrough_and_rests_at_every_keyframe() {
        let keys = [key(0.0), key(1.0)];
        // 5 samples over 2 keys: keyframe 0 falls on sample 0, keyframe 1 (t = ½) between
        // samples 2 and 3, so it is an extra frame.
        let frames = plan(&keys, 5, 2, 0);
        let ts: Vec<f32> = frames.iter().map(|f| f.t).collect();
        assert_eq!(ts, [0.0, 0.0, 0.0, 0.2, 0.4, 0.5, 0.5, 0.5, 0.6, 0.8]);
        let rests: Vec<Option<usize>> = frames.iter().map(|f| f.rest).collect();
        assert_eq!(&rests[..6], [Some(0), Some(0), Some(0), None, None, Some(1)]);
        let extra: Vec<bool> = frames.iter().map(|f| f.extra).collect();
        assert_eq!(extra, [false, true, true, false, false, true, true, true, false, false]);
        assert_eq!(frames[5].camera, keys[1]);
        // Without rests, exactly the samples of `kage render --animate`.
        let plain = plan(&keys, 4, 0, 0);
        assert_eq!(plain.iter().map(|f| f.t).collect::<Vec<_>>(), [0.0, 0.25, 0.5, 0.75]);
        assert!(plain.iter().all(|f| f.rest.is_none() && !f.extra));
        assert!(plan(&[], 4, 2, 1).is_empty());
    }

    #[test]
    fn leaves_each_keyframe_slowly_after_resting() {
        let keys = [key(0.0), key(1.0)];
        let frames = plan(&keys, 2, 1, 2);
        let expected = [0.0, 0.0, 0.005, 0.01, 0.5, 0.5, 0.505, 0.51];
        assert_eq!(frames.len(), expected.len());
        assert!(frames.iter().zip(expected).all(|(f, t)| (f.t - t).abs() < 1e-6), "{frames:?}");
        assert!(frames[2..4].iter().all(|f| f.extra && f.rest.is_none()));
        // Eased: held still, then each slow frame moves further than the one before.
        let moves: Vec<f32> =
            (0..3).map(|i| motion_px(&frames[i].camera, &frames[i + 1].camera, 256)).collect();
        assert!(moves[0] == 0.0 && moves[1] > 0.0 && moves[2] > moves[1], "{moves:?}");
    }

    #[test]
    fn motion_counts_turns_moves_and_zooms_in_pixels() {
        let a = key(0.0);
        assert_eq!(motion_px(&a, &a, 100), 0.0);
        let pixel = 40f32.to_radians() / 100.0;
        // Camera and target sideways by one pixel's angle at the target's distance: one pixel
        // of parallax, no turn.
        let distance = a.target.distance(a.position);
        let moved = Camera {
            position: a.position + Vec3::X * distance * pixel,
            target: a.target + Vec3::X * distance * pixel,
            ..a
        };
        assert!((motion_px(&a, &moved, 100) - 1.0).abs() < 1e-3);
        // Turning in place by three pixels' angle.
        let dir = (a.target - a.position).normalize();
        let turn = glam::Quat::from_axis_angle(dir.any_orthonormal_vector(), 3.0 * pixel);
        let turned = Camera { target: a.position + turn * dir, ..a };
        assert!((motion_px(&a, &turned, 100) - 3.0).abs() < 1e-2);
        // Zooming so that the edge moves by 2 of 50 half-height pixels.
        let fov = 2.0 * ((0.5 * 40f32.to_radians()).tan() * 48.0 / 50.0).atan();
        let zoomed = Camera { fov_y_deg: fov.to_degrees(), ..a };
        assert!((motion_px(&a, &zoomed, 100) - 2.0).abs() < 1e-3);
    }
}
