//! The built-in `two-rooms`, where light probes leak: two 4 × 2.5 × 4 rooms side by side along
//! X, parted by a solid wall 10 cm thick at x = 0 without an opening. The west room (x < 0) is
//! lit through a wide 2.4 × 2.4 opening in its ceiling, the east room (x > 0) through a
//! 0.8 × 0.8 one near its far corner, so it is dim. The Stanford bunny (group 0, 0.5 tall)
//! slides along the wall inside the east room, 0.35 from it, from z = −1.5 to 1.5 and back
//! every 2 s: probes interpolated across the wall light it with the west room's sky.
use super::probe_room::panel;
use crate::scene::motion::{Key, Motion};
use crate::scene::{obj, Group, Mesh, SceneError, Transform};
use glam::{Quat, Vec3};

/// The bunny's bounds in its OBJ: +Y up, standing on y = 0, 9.65 units tall.
const BUNNY_HEIGHT: f32 = 9.65;
/// Each room's width along X and depth along Z, and the height.
const ROOM: f32 = 4.0;
const HEIGHT: f32 = 2.5;
/// Half the wall's thickness.
const WALL: f32 = 0.05;
/// The bunny's distance from the wall and the ends of its path along Z.
const PATH_X: f32 = 0.35;
const PATH_Z: f32 = 1.5;
/// The openings: centre (x, z) and half side.
const SUNLIT_OPENING: ([f32; 2], f32) = ([-2.0, 0.0], 1.2);
const DIM_OPENING: ([f32; 2], f32) = ([3.0, -1.2], 0.4);

const GREY: [f32; 3] = [0.6; 3];
const WARM: [f32; 3] = [0.7, 0.5, 0.3];

/// The bunny (group 0) and the rooms (group 1).
pub fn groups() -> Result<Vec<Group>, SceneError> {
    let bunny = obj::parse_obj(super::BUNNY_OBJ, "bunny", [0.75; 3])?;
    let scale = 0.5 / BUNNY_HEIGHT;
    let at = |z: f32| Transform {
        translation: Vec3::new(PATH_X, 0.0, z),
        rotation: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        scale,
    };
    let keys = [(0.0, -PATH_Z), (1.0, PATH_Z), (2.0, -PATH_Z)].map(|(t, z)| Key::posed(t, at(z))).to_vec();
    let bunny = Group {
        motion: Some(Motion { keys, loop_seconds: Some(2.0) }),
        ..Group::new("bunny", vec![bunny], at(-PATH_Z))
    };
    let (w, d, top) = (ROOM, ROOM / 2.0, HEIGHT);
    let v = Vec3::new;
    let mut rooms = vec![
        panel("floor", v(-w, 0.0, -d), v(w, 0.0, d), Vec3::Y, GREY)?,
        panel("west_wall", v(-w, 0.0, -d), v(-w, top, d), Vec3::X, WARM)?,
        panel("east_wall", v(w, 0.0, -d), v(w, top, d), Vec3::NEG_X, GREY)?,
        panel("back_wall", v(-w, 0.0, -d), v(w, top, -d), Vec3::Z, GREY)?,
        panel("front_wall", v(-w, 0.0, d), v(w, top, d), Vec3::NEG_Z, GREY)?,
        // The parting wall, a face into each room; the ceiling closes it above.
        panel("wall_west_face", v(-WALL, 0.0, -d), v(-WALL, top, d), Vec3::NEG_X, GREY)?,
        panel("wall_east_face", v(WALL, 0.0, -d), v(WALL, top, d), Vec3::X, GREY)?,
    ];
    rooms.extend(ceiling("west", -w, 0.0, SUNLIT_OPENING)?);
    rooms.extend(ceiling("east", 0.0, w, DIM_OPENING)?);
    Ok(vec![bunny, Group::new("rooms", rooms, Transform::default())])
}

/// The ceiling over x in [`x0`, `x1`] in four pieces around a square opening.
fn ceiling(room: &str, x0: f32, x1: f32, ([cx, cz], half): ([f32; 2], f32)) -> Result<Vec<Mesh>, SceneError> {
    let (d, top) = (ROOM / 2.0, HEIGHT);
    let v = Vec3::new;
    let piece =
        |side: &str, lo: Vec3, hi: Vec3| panel(&format!("{room}_ceiling_{side}"), lo, hi, Vec3::NEG_Y, GREY);
    Ok(vec![
        piece("back", v(x0, top, -d), v(x1, top, cz - half))?,
        piece("front", v(x0, top, cz + half), v(x1, top, d))?,
        piece("left", v(x0, top, cz - half), v(cx - half, top, cz + half))?,
        piece("right", v(cx + half, top, cz - half), v(x1, top, cz + half))?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bunny_stays_in_the_dim_room_beside_the_wall() {
        let groups = groups().unwrap();
        let motion = groups[0].motion.as_ref().unwrap();
        for k in 0..=40 {
            let pose = motion.at(k as f32 / 20.0);
            let matrix = pose.matrix();
            let points = groups[0].meshes[0].positions.iter().map(|&p| matrix.transform_point3(p.into()));
            let nearest = points.map(|p| p.x).fold(f32::INFINITY, f32::min);
            assert!(nearest > WALL + 0.1, "at {pose:?} the bunny comes within {nearest} of the wall's axis");
            assert!(pose.translation.z.abs() <= PATH_Z + 1e-6);
        }
        // Every ceiling piece is non-empty: the openings lie inside their rooms.
        assert!(groups[1].meshes.iter().all(|m| !m.indices.is_empty()));
    }
}
