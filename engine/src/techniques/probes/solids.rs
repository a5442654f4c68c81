//! Which points lie inside the static geometry, on the CPU: candidate probes and test points
//! there see only the inside of a wall or column, and are dropped. Triangles are tested one by
//! one (Möller & Trumbore 1997): a few thousand triangles and a few hundred points take
//! milliseconds, and no GPU round trip.
use super::set::ProbeGroups;
use crate::scene::Scene;
use glam::Vec3;

/// The world triangles of a scene's static groups.
pub struct Solids {
    triangles: Vec<[Vec3; 3]>,
}

/// The surface a ray meets first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub distance: f32,
    /// Met from behind (the side its counter-clockwise winding faces away from).
    pub back: bool,
}

/// The six axes and the eight diagonals, unit length: a ray along an axis may slip along a
/// box's edge, a diagonal one does not.
pub(super) fn directions() -> [Vec3; 14] {
    let d = 1.0 / 3f32.sqrt();
    std::array::from_fn(|k| match k {
        0..=5 => Vec3::AXES[k % 3] * if k < 3 { 1.0 } else { -1.0 },
        _ => {
            let s = |bit: usize| if (k - 6) & bit == 0 { d } else { -d };
            Vec3::new(s(1), s(2), s(4))
        }
    })
}

impl Solids {
    /// The triangles of the static groups ([`ProbeGroups::is_static`]).
    pub fn of_static(scene: &Scene) -> Solids {
        let groups = ProbeGroups::of(scene);
        let triangles = scene
            .groups
            .iter()
            .enumerate()
            .filter(|(g, _)| groups.is_static(*g))
            .flat_map(|(_, group)| {
                let m = group.transform.matrix();
                group.meshes.iter().flat_map(move |mesh| {
                    mesh.indices.chunks_exact(3).map(move |t| {
                        [0, 1, 2].map(|k| m.transform_point3(mesh.positions[t[k] as usize].into()))
                    })
                })
            })
            .collect();
        Solids { triangles }
    }

    /// The nearest surface along the ray from `origin` in direction `dir`.
    pub fn first_hit(&self, origin: Vec3, dir: Vec3) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for [a, b, c] in &self.triangles {
            let (e1, e2) = (*b - *a, *c - *a);
            let q = dir.cross(e2);
            let det = e1.dot(q);
            if det.abs() < 1e-12 {
                continue;
            }
            let s = origin - *a;
            let u = s.dot(q) / det;
            let r = s.cross(e1);
            let v = dir.dot(r) / det;
            let t = e2.dot(r) / det;
            if u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 0.0 || best.is_some_and(|h| h.distance <= t) {
                continue;
            }
            // det = −(e1 × e2) · dir: negative when the ray runs along the face's normal.
            best = Some(Hit { distance: t, back: det < 0.0 });
        }
        best
    }

    /// Whether `p` is inside a solid: along most of 14 directions the first surface is met from
    /// behind. A point in a room open to the sky meets front faces or nothing.
    pub fn contains(&self, p: Vec3) -> bool {
        let behind = directions().iter().filter(|&&d| self.first_hit(p, d).is_some_and(|h| h.back)).count();
        2 * behind > directions().len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::motion::Key;
    use crate::scene::{shapes, Camera, EnvMap, Group, Motion, Transform};

    /// A column and, after it in the scene, a box that moves (a motion holding its rest pose).
    fn scene() -> Scene {
        let column = shapes::boxes("column", &[([0.0, 0.0, 0.0], [1.0, 3.0, 1.0])], [0.5; 3]).unwrap();
        let moving = shapes::boxes("mover", &[([5.0, 0.0, 5.0], [6.0, 1.0, 6.0])], [0.5; 3]).unwrap();
        let group = |name: &str, mesh, motion| Group {
            name: name.into(),
            meshes: vec![mesh],
            transform: Transform::default(),
            motion,
        };
        let held = Motion { keys: vec![Key::posed(0.0, Transform::default())], loop_seconds: None };
        Scene::new(
            "column",
            vec![group("column", column, None), group("mover", moving, Some(held))],
            EnvMap::constant([1.0; 3]),
            Camera { position: Vec3::Z * 9.0, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 },
        )
    }

    #[test]
    fn inside_a_box_is_solid_and_beside_it_is_not() {
        let solids = Solids::of_static(&scene());
        assert!(solids.contains(Vec3::new(0.5, 1.5, 0.5)));
        assert!(!solids.contains(Vec3::new(1.5, 1.5, 0.5)));
        // The moving group (the second: the one with a motion) is no solid.
        assert!(!solids.contains(Vec3::new(5.5, 0.5, 5.5)));
        let hit = solids.first_hit(Vec3::new(-1.0, 1.0, 0.5), Vec3::X).unwrap();
        assert!((hit.distance - 1.0).abs() < 1e-6 && !hit.back, "{hit:?}");
        assert!(solids.first_hit(Vec3::new(0.5, 1.0, 0.5), Vec3::X).unwrap().back);
    }

    /// The built-in atrium as the probes see it (its dimensions from the scene's module).
    mod atrium {
        use super::super::Solids;
        use crate::scene::builtin::atrium::{BUNNY_HEIGHT, COLUMN, COLUMN_SPACING, COURT, GALLERY, SPRING};
        use crate::scene::Scene;
        use glam::Vec3;

        #[test]
        fn the_camera_sees_the_sky() {
            let scene = Scene::builtin("atrium").unwrap();
            let solids = Solids::of_static(&scene);
            let c = scene.camera.position;
            assert!(!solids.contains(c) && solids.first_hit(c, Vec3::Y).is_none(), "the camera sees the sky");
        }

        #[test]
        fn the_bunny_moves_from_the_sun_into_the_shade_through_the_open_arch() {
            let scene = Scene::builtin("atrium").unwrap();
            let solids = Solids::of_static(&scene);
            let bunny = &scene.groups[0];
            let above = |t: f32| {
                let top = bunny.pose_at(t).matrix().transform_point3(Vec3::new(0.0, BUNNY_HEIGHT, 0.0));
                solids.first_hit(top, Vec3::Y)
            };
            // At a quarter cycle it is 90 cm into the gallery (+X), under the roof; at three
            // quarters 90 cm into the courtyard, under the sky.
            assert!(above(0.25).is_some_and(|h| !h.back), "in the gallery, the roof above");
            assert!(above(0.75).is_none(), "in the courtyard, nothing above");
            // Along the whole path its middle is in free space and not in a column: the arch's
            // opening is wider than the bunny.
            for s in 0..32 {
                let t = s as f32 / 32.0;
                let middle =
                    bunny.pose_at(t).matrix().transform_point3(Vec3::new(0.0, 0.5 * BUNNY_HEIGHT, 0.0));
                assert!(!solids.contains(middle), "t = {t}: {middle}");
                assert!(middle.z.abs() < 0.5 * (COLUMN_SPACING - COLUMN), "{middle}");
            }
        }

        #[test]
        fn arches_close_the_arcade_above_the_springs_and_leave_it_open_below() {
            let scene = Scene::builtin("atrium").unwrap();
            let solids = Solids::of_static(&scene);
            // Across the arch at z = 0 (mid-span): open under the crown, closed above it.
            let crown = SPRING + 0.5 * (COLUMN_SPACING - COLUMN);
            let from_court = |y: f32| solids.first_hit(Vec3::new(0.0, y, 0.0), Vec3::X).map(|h| h.distance);
            assert!(from_court(crown - 0.05).unwrap() > GALLERY, "under the crown the gallery's wall is met");
            assert!((from_court(crown + 0.05).unwrap() - (COURT - 0.5 * COLUMN)).abs() < 1e-4);
            // Inside a column is solid.
            assert!(solids.contains(Vec3::new(COURT, 1.0, 1.0)));
        }
    }
}
