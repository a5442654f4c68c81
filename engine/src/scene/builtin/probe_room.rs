//! The built-in `probe-room` (Morishige 2014's Basic scene): a closed 4 × 2.5 × 4 room with a
//! red wall (−X), a green wall (+X), a blue wall (−Z) and grey floor, front wall and ceiling,
//! a 1.2 × 1.2 opening in the ceiling through which the sky shows, and the Stanford bunny
//! standing under the opening as group 0 (the group `--animate` moves).
use crate::scene::motion;
use glam::Vec3;

use crate::scene::{obj, shapes, Group, Mesh, SceneError, Transform};

/// The bunny's bounds in its OBJ: +Y up, standing on y = 0, 9.65 units tall.
const BUNNY_HEIGHT: f32 = 9.65;

/// Half the room's width and depth, and its height.
const HALF: f32 = 2.0;
const HEIGHT: f32 = 2.5;
/// Half the side of the square opening in the ceiling, centred above the origin.
const OPENING: f32 = 0.6;
/// Grid vertices per side of a panel: enough for the per-vertex techniques (Sloan, Tamura) to
/// show the room's gradients, few enough for lavapipe.
const PANEL_VERTICES: u32 = 9;

const GREY: [f32; 3] = [0.6; 3];
const RED: [f32; 3] = [0.7, 0.1, 0.1];
const GREEN: [f32; 3] = [0.1, 0.7, 0.1];
const BLUE: [f32; 3] = [0.1, 0.1, 0.7];

/// The bunny (group 0) and the room (group 1).
pub fn groups() -> Result<Vec<Group>, SceneError> {
    let bunny = obj::parse_obj(super::BUNNY_OBJ, "bunny", [0.75; 3])?;
    let bunny_transform = Transform { scale: 0.7 / BUNNY_HEIGHT, ..Transform::default() };
    let (h, o, top) = (HALF, OPENING, HEIGHT);
    let v = Vec3::new;
    let room = vec![
        panel("floor", v(-h, 0.0, -h), v(h, 0.0, h), Vec3::Y, GREY)?,
        panel("red_wall", v(-h, 0.0, -h), v(-h, top, h), Vec3::X, RED)?,
        panel("green_wall", v(h, 0.0, -h), v(h, top, h), Vec3::NEG_X, GREEN)?,
        panel("blue_wall", v(-h, 0.0, -h), v(h, top, -h), Vec3::Z, BLUE)?,
        panel("front_wall", v(-h, 0.0, h), v(h, top, h), Vec3::NEG_Z, GREY)?,
        // The ceiling in four pieces around the opening.
        panel("ceiling_back", v(-h, top, -h), v(h, top, -o), Vec3::NEG_Y, GREY)?,
        panel("ceiling_front", v(-h, top, o), v(h, top, h), Vec3::NEG_Y, GREY)?,
        panel("ceiling_left", v(-h, top, -o), v(-o, top, o), Vec3::NEG_Y, GREY)?,
        panel("ceiling_right", v(o, top, -o), v(h, top, o), Vec3::NEG_Y, GREY)?,
    ];
    Ok(vec![
        motion::hopping(Group::new("bunny", vec![bunny], bunny_transform)),
        Group::new("room", room, Transform::default()),
    ])
}

/// An axis-aligned rectangle from `lo` to `hi` (equal along the normal's axis) facing `normal`,
/// made from the floor grid of [`shapes::plane`] mapped X → one in-plane axis, Y → the normal,
/// Z → the other in-plane axis, the latter's sign chosen so the map keeps the counter-clockwise
/// winding.
pub(super) fn panel(
    name: &str,
    lo: Vec3,
    hi: Vec3,
    normal: Vec3,
    albedo: [f32; 3],
) -> Result<Mesh, SceneError> {
    let (centre, extent) = ((lo + hi) * 0.5, hi - lo);
    let mut in_plane = [Vec3::X, Vec3::Y, Vec3::Z].into_iter().filter(|a| a.dot(normal) == 0.0);
    let (Some(a), Some(b)) = (in_plane.next(), in_plane.next()) else {
        return Err(SceneError::invalid(format!("panel \"{name}\": normal {normal} is not along an axis")));
    };
    let u = a * extent.dot(a);
    let w = b * extent.dot(b);
    let w = if u.cross(normal).dot(w) < 0.0 { -w } else { w };
    let grid = shapes::plane(name, [1.0, 1.0], [PANEL_VERTICES; 2], albedo)?;
    let positions = grid.positions.iter().map(|p| (centre + u * p[0] + w * p[2]).to_array()).collect();
    let normals = vec![normal.to_array(); grid.positions.len()];
    Mesh::new(name, positions, Some(normals), grid.indices, albedo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panels_face_into_the_room_and_the_bunny_stands_on_the_floor() {
        let groups = groups().unwrap();
        let centre = Vec3::new(0.0, HEIGHT / 2.0, 0.0);
        for mesh in &groups[1].meshes {
            for tri in mesh.indices.chunks_exact(3) {
                let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[tri[k] as usize]));
                let face = (b - a).cross(c - a);
                assert!(
                    face.dot(Vec3::from(mesh.normals[tri[0] as usize])) > 0.0,
                    "{} winds clockwise",
                    mesh.name
                );
                assert!(face.dot(centre - a) > 0.0, "{} faces away from the room", mesh.name);
            }
        }
        let bunny = &groups[0];
        let ys = bunny.meshes[0].positions.iter().map(|p| p[1] * bunny.transform.scale);
        let (lo, hi) = ys.fold((f32::MAX, f32::MIN), |(l, h), y| (l.min(y), h.max(y)));
        assert!(lo.abs() < 0.01 && (hi - 0.7).abs() < 0.01, "bunny spans y {lo}..{hi}");
    }
}
