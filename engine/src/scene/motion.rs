//! A group's motion as data: keyframes of its translation, rotation and (uniform) scale over time
//! (seconds), which `kage render --animate` and `--time` play and the sweep's poses sample.
//! Between keys the translation and scale are interpolated linearly and the rotation along the
//! shorter arc (slerp); at a key's time the pose is the key's exactly. With a loop length the
//! motion repeats; without, it holds its first key before it and its last key after it.
use super::{Group, SceneError, Transform};
use glam::{Quat, Vec3};
use std::f32::consts::TAU;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    /// Seconds from the motion's start, 0 or more.
    pub time: f32,
    pub translation: Vec3,
    /// Unit length.
    pub rotation: Quat,
    /// Uniform, > 0.
    pub scale: f32,
}

impl Key {
    /// The key at `time` holding `pose`.
    pub fn posed(time: f32, pose: Transform) -> Key {
        Key { time, translation: pose.translation, rotation: pose.rotation, scale: pose.scale }
    }

    /// The pose it holds.
    pub fn transform(&self) -> Transform {
        Transform { translation: self.translation, rotation: self.rotation, scale: self.scale }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// At least one, in increasing time.
    pub keys: Vec<Key>,
    /// The period after which the motion starts again (at least the last key's time); `None`:
    /// it plays once.
    pub loop_seconds: Option<f32>,
}

impl Motion {
    /// The pose at `time` seconds.
    pub fn at(&self, time: f32) -> Transform {
        let (keys, period) = (&self.keys, self.loop_seconds);
        let time = period.filter(|p| *p > 0.0).map_or(time, |p| time.rem_euclid(p));
        let (first, last) = (&keys[0], &keys[keys.len() - 1]);
        // The keys around `time`, with their times; a looping motion runs from its last key
        // to its first one period later.
        let k = keys.partition_point(|key| key.time <= time);
        let (a, a_time, b, b_time) = match (k, period) {
            (0, Some(p)) => (last, last.time - p, first, first.time),
            (0, None) => return first.transform(),
            (k, Some(p)) if k == keys.len() => (last, last.time, first, first.time + p),
            (k, None) if k == keys.len() => return last.transform(),
            (k, _) => (&keys[k - 1], keys[k - 1].time, &keys[k], keys[k].time),
        };
        if time <= a_time || b_time <= a_time {
            return a.transform();
        }
        let s = ((time - a_time) / (b_time - a_time)).min(1.0);
        Transform {
            translation: a.translation.lerp(b.translation, s),
            rotation: a.rotation.slerp(b.rotation, s),
            scale: a.scale + (b.scale - a.scale) * s,
        }
    }

    /// How long one pass of the motion lasts: its loop length, else its last key's time.
    pub fn duration(&self) -> f32 {
        self.loop_seconds.unwrap_or_else(|| self.keys.last().map_or(0.0, |k| k.time))
    }

    /// Checks the keys: at least one, finite, times from 0 in strictly increasing order, unit
    /// rotations, positive scales, and a loop no shorter than the last key's time.
    pub fn validate(&self) -> Result<(), SceneError> {
        if self.keys.is_empty() {
            return Err(SceneError::invalid(
                "keyframes: none given (leave the field out for a group that stays)",
            ));
        }
        let mut previous = None;
        for (k, key) in self.keys.iter().enumerate() {
            let at = |problem: String| SceneError::invalid(format!("keyframe {k}: {problem}"));
            if !(key.time.is_finite() && key.time >= 0.0) {
                return Err(at(format!("time {} is not a number of seconds, 0 or more", key.time)));
            }
            if previous.is_some_and(|p| key.time <= p) {
                return Err(at(format!("time {} does not come after the previous key's", key.time)));
            }
            previous = Some(key.time);
            if !key.translation.is_finite() {
                return Err(at(format!("translation {} is not finite", key.translation)));
            }
            if !(key.rotation.is_finite() && (key.rotation.length() - 1.0).abs() < 1e-3) {
                return Err(at(format!("rotation {} is not a unit quaternion", key.rotation)));
            }
            if !(key.scale.is_finite() && key.scale > 0.0) {
                return Err(at(format!("scale {} is not a positive number", key.scale)));
            }
        }
        if let Some(period) = self.loop_seconds {
            let last = self.keys.last().map_or(0.0, |k| k.time);
            if !(period.is_finite() && period > 0.0 && period >= last) {
                return Err(SceneError::invalid(format!(
                    "loop_seconds {period}: a motion loops after a positive time no shorter than its last key's ({last})"
                )));
            }
        }
        Ok(())
    }
}

impl Group {
    /// Its transform at `time` seconds: its motion's; its transform when it has no motion.
    pub fn pose_at(&self, time: f32) -> Transform {
        self.motion.as_ref().map_or(self.transform, |motion| motion.at(time))
    }
}

/// How far the hop slides to each side and rises, in units of the group's height.
const SLIDE: f32 = 1.0;
const HOP: f32 = 0.4;
/// Keys per one-second cycle: every pose the sweep samples (0, 0.125, 0.6 s) is a key.
const HOP_KEYS: usize = 80;

/// The built-in scenes' motion for `group`: over a one-second loop it slides across the floor by
/// its height to each side and back, turns once about +Y and hops. At 0 and 0.5 s it rests in
/// its scene pose (for the teapot: standing on the floor, the contact case of the soft-shadow
/// method); in between it rises by up to 40 % of its height.
pub fn hop(group: &Group) -> Motion {
    let base = group.transform;
    let ys = group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| p[1]));
    let (lo, hi) = ys.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), y| (a.min(y), b.max(y)));
    let height = if lo <= hi { (hi - lo) * base.scale } else { 0.0 };
    let keys = (0..HOP_KEYS)
        .map(|k| {
            let time = k as f32 / HOP_KEYS as f32;
            let phase = TAU * time;
            let offset =
                Vec3::new(SLIDE * height * phase.sin(), HOP * height * (2.0 * phase).sin().abs(), 0.0);
            Key {
                time,
                translation: base.translation + offset,
                rotation: Quat::from_rotation_y(phase) * base.rotation,
                scale: base.scale,
            }
        })
        .collect();
    Motion { keys, loop_seconds: Some(1.0) }
}

/// `group` with the built-in hop ([`hop`]) as its motion.
pub fn hopping(group: Group) -> Group {
    Group { motion: Some(hop(&group)), ..group }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f32, x: f32, turn: f32) -> Key {
        Key { time, translation: Vec3::new(x, 0.0, 0.0), rotation: Quat::from_rotation_y(turn), scale: 1.0 }
    }

    #[test]
    fn keys_are_hit_exactly_and_interpolated_between_held_or_looped_beyond() {
        let once = Motion { keys: vec![key(1.0, 0.0, 0.0), key(3.0, 4.0, 1.0)], loop_seconds: None };
        assert_eq!(once.at(1.0), once.keys[0].transform());
        assert_eq!(once.at(0.0), once.at(1.0), "held before the first key");
        assert_eq!(once.at(9.0), once.keys[1].transform(), "held after the last");
        let half = once.at(2.0);
        assert!(
            (half.translation.x - 2.0).abs() < 1e-6
                && half.rotation.abs_diff_eq(Quat::from_rotation_y(0.5), 1e-6)
        );
        let growing = Motion {
            keys: vec![key(0.0, 0.0, 0.0), Key { scale: 3.0, ..key(2.0, 0.0, 0.0) }],
            loop_seconds: None,
        };
        assert_eq!(growing.at(0.5).scale, 1.5, "scale interpolated linearly");
        // Looping over 4 s: from the last key (3 s) back to the first one period later (5 s).
        let looped = Motion { loop_seconds: Some(4.0), ..once.clone() };
        assert_eq!(looped.at(5.0), looped.at(1.0));
        assert!(
            (looped.at(4.0).translation.x - 2.0).abs() < 1e-6,
            "half-way from the last key back to the first"
        );
        assert!((looped.at(3.5).translation.x - 3.0).abs() < 1e-6);
        assert_eq!(looped.duration(), 4.0);
        assert_eq!(once.duration(), 3.0);
    }

    #[test]
    fn bad_keyframes_are_refused_naming_the_key() {
        let bad =
            |keys: Vec<Key>, loop_seconds| Motion { keys, loop_seconds }.validate().unwrap_err().to_string();
        assert!(bad(vec![], None).contains("none given"));
        assert!(bad(vec![key(1.0, 0.0, 0.0), key(1.0, 1.0, 0.0)], None)
            .contains("keyframe 1: time 1 does not come after"));
        assert!(bad(vec![key(-1.0, 0.0, 0.0)], None).contains("keyframe 0: time -1"));
        assert!(bad(vec![key(f32::NAN, 0.0, 0.0)], None).contains("keyframe 0: time NaN"));
        assert!(bad(vec![key(0.0, f32::INFINITY, 0.0)], None).contains("translation"));
        let skewed = Key { rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 2.0), ..key(0.0, 0.0, 0.0) };
        assert!(bad(vec![skewed], None).contains("not a unit quaternion"));
        let flat = Key { scale: 0.0, ..key(0.0, 0.0, 0.0) };
        assert!(bad(vec![flat], None).contains("keyframe 0: scale 0"));
        assert!(bad(vec![key(0.0, 0.0, 0.0), key(2.0, 0.0, 0.0)], Some(1.0)).contains("loop_seconds 1"));
    }

    #[test]
    fn the_hop_rests_at_the_start_and_half_way_and_is_periodic() {
        let mesh = crate::scene::Mesh::new(
            "unit",
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            None,
            vec![0, 1, 2],
            [0.5; 3],
        )
        .unwrap();
        let base = Transform { translation: Vec3::new(0.0, 0.5, 0.0), ..Transform::default() };
        let group = Group::new("g", vec![mesh], base);
        let group = Group { motion: Some(hop(&group)), ..group };
        group.motion.as_ref().unwrap().validate().unwrap();
        let at = |t| group.pose_at(t).matrix();
        assert!(at(0.0).abs_diff_eq(base.matrix(), 1e-6));
        assert!((at(0.5).w_axis.y - 0.5).abs() < 1e-5, "touching the floor again at t = 0.5");
        assert!(at(0.3).abs_diff_eq(at(1.3), 1e-5));
        assert!(at(0.125).w_axis.y > 0.8, "in the air between");
    }
}
