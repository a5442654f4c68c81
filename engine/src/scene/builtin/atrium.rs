//! The built-in `atrium`: a courtyard building (a cloister) for light probes, where indoor and
//! outdoor light meet, lit by the courtyard environment:
//!
//! - An open 6 × 6 courtyard (x, z ∈ [−3, 3]) with a fountain block in its middle.
//! - Around it a covered gallery 2 m deep under a flat roof 3 m up, closed by outer walls with a
//!   doorway in the south wall (+Z).
//! - The arcade between them: twelve 30 cm columns 2 m apart on the courtyard's edge, and round
//!   arches between them (springing at 2 m, 85 cm radius), each approximated by eight boxes
//!   hanging from the roof's edge beam down to the arch's curve.
//! - The bunny, 90 cm tall, as group 0 (the group `--animate` moves): it stands in the arch at
//!   x = 3, z = 0, and slides ±90 cm along X, from the sunlit courtyard into the gallery's shade
//!   and back. The scene has no walkthrough, so `--animate` moves the bunny.
//!
//! 1,440 triangles (120 boxes) besides the bunny's 3,674: light for lavapipe.
use crate::scene::motion;
use glam::Vec3;

use crate::scene::{obj, shapes, Camera, Group, Mesh, SceneError, Transform};

/// The bunny's height in its OBJ (+Y up, standing on y = 0).
pub(crate) const BUNNY_HEIGHT: f32 = 9.655;
const BUNNY_SIZE: f32 = 0.9;

/// Half the courtyard's side: the arcade's line.
pub const COURT: f32 = 3.0;
/// The gallery's depth from the arcade's line to the outer walls.
pub(crate) const GALLERY: f32 = 2.0;
/// The gallery roof's underside.
pub const ROOF: f32 = 3.0;
const SLAB: f32 = 0.2;
const WALL: f32 = 0.2;
pub(crate) const COLUMN: f32 = 0.3;
/// Columns along each side of the courtyard, 2 m apart (corners shared).
pub(crate) const COLUMN_SPACING: f32 = 2.0;
pub(crate) const SPRING: f32 = 2.0;
/// Boxes per arch.
const ARCH_SEGMENTS: u32 = 8;

type Bar = ([f32; 3], [f32; 3]);

fn bar(lo: Vec3, hi: Vec3) -> Bar {
    (lo.to_array(), hi.to_array())
}

/// The outer edge of the walls.
fn outer() -> f32 {
    COURT + GALLERY + WALL
}

/// A box along X from `x0` to `x1` at depth `z` (centre) and thickness `t`, or its mirror along
/// Z: the arcade's four sides are one side turned.
fn along(x0: f32, x1: f32, y0: f32, y1: f32, z: f32, t: f32, swap: bool) -> Bar {
    let (lo, hi) = (Vec3::new(x0, y0, z - 0.5 * t), Vec3::new(x1, y1, z + 0.5 * t));
    if swap {
        bar(Vec3::new(lo.z, lo.y, lo.x), Vec3::new(hi.z, hi.y, hi.x))
    } else {
        bar(lo, hi)
    }
}

/// Columns on the courtyard's edge, and the arches between neighbours.
fn arcade() -> (Vec<Bar>, Vec<Bar>) {
    let spans = (2.0 * COURT / COLUMN_SPACING).round() as u32;
    let position = |k: u32| -COURT + COLUMN_SPACING * k as f32;
    let mut columns = Vec::new();
    for i in 0..=spans {
        for j in 0..=spans {
            let on_edge = i == 0 || j == 0 || i == spans || j == spans;
            if on_edge {
                let (x, z) = (position(i), position(j));
                let c = Vec3::new(x, 0.0, z);
                columns.push(bar(
                    c - Vec3::new(0.5 * COLUMN, 0.0, 0.5 * COLUMN),
                    c + Vec3::new(0.5 * COLUMN, ROOF, 0.5 * COLUMN),
                ));
            }
        }
    }
    let radius = 0.5 * (COLUMN_SPACING - COLUMN);
    let mut arches = Vec::new();
    for side in [-COURT, COURT] {
        for swap in [false, true] {
            for k in 0..spans {
                let (start, centre) = (position(k) + 0.5 * COLUMN, position(k) + 0.5 * COLUMN_SPACING);
                let width = 2.0 * radius / ARCH_SEGMENTS as f32;
                for s in 0..ARCH_SEGMENTS {
                    let (x0, x1) = (start + width * s as f32, start + width * (s + 1) as f32);
                    // The curve's height at the segment's outer end: no gap shows at the springs.
                    let off = ((x0 - centre).abs()).max((x1 - centre).abs()).min(radius);
                    let y = SPRING + (radius * radius - off * off).sqrt();
                    arches.push(along(x0, x1, y, ROOF, side, COLUMN, swap));
                }
            }
        }
    }
    (columns, arches)
}

/// The floor under everything, the outer walls (a doorway in the south one), the gallery's
/// roof ring around the open courtyard.
fn shell() -> (Vec<Bar>, Vec<Bar>, Vec<Bar>) {
    let (o, inner) = (outer(), COURT + GALLERY);
    let top = ROOF + SLAB;
    let floor = vec![bar(Vec3::new(-o, -0.1, -o), Vec3::new(o, 0.0, o))];
    let door = 0.6;
    let walls = vec![
        bar(Vec3::new(-o, 0.0, -o), Vec3::new(o, top, -inner)),
        bar(Vec3::new(-o, 0.0, -inner), Vec3::new(-inner, top, inner)),
        bar(Vec3::new(inner, 0.0, -inner), Vec3::new(o, top, inner)),
        bar(Vec3::new(-o, 0.0, inner), Vec3::new(-door, top, o)),
        bar(Vec3::new(door, 0.0, inner), Vec3::new(o, top, o)),
        bar(Vec3::new(-door, 2.2, inner), Vec3::new(door, top, o)),
    ];
    // The roof reaches the arcade's courtyard face.
    let edge = COURT - 0.5 * COLUMN;
    let roof = vec![
        bar(Vec3::new(-inner, ROOF, -inner), Vec3::new(inner, top, -edge)),
        bar(Vec3::new(-inner, ROOF, edge), Vec3::new(inner, top, inner)),
        bar(Vec3::new(-inner, ROOF, -edge), Vec3::new(-edge, top, edge)),
        bar(Vec3::new(edge, ROOF, -edge), Vec3::new(inner, top, edge)),
    ];
    (floor, walls, roof)
}

/// Where the bunny stands at rest: in the east arch, its middle on the arcade's line.
pub fn bunny_rest() -> Vec3 {
    Vec3::new(COURT, 0.0, 0.0)
}

/// The bunny (group 0) and the building (group 1).
pub fn groups() -> Result<Vec<Group>, SceneError> {
    let bunny = obj::parse_obj(super::BUNNY_OBJ, "bunny", [0.8; 3])?;
    let (columns, arches) = arcade();
    let (floor, walls, roof) = shell();
    let stone = [0.75, 0.7, 0.6];
    let fountain = vec![bar(Vec3::new(-0.6, 0.0, -0.6), Vec3::new(0.6, 0.5, 0.6))];
    let meshes: Vec<Mesh> = vec![
        shapes::boxes("floor", &floor, [0.5; 3])?,
        shapes::boxes("walls", &walls, [0.7; 3])?,
        shapes::boxes("roof", &roof, [0.6, 0.35, 0.3])?,
        shapes::boxes("columns", &columns, stone)?,
        shapes::boxes("arches", &arches, stone)?,
        shapes::boxes("fountain", &fountain, [0.4, 0.5, 0.6])?,
    ];
    let bunny_transform =
        Transform { translation: bunny_rest(), scale: BUNNY_SIZE / BUNNY_HEIGHT, ..Transform::default() };
    Ok(vec![
        motion::hopping(Group::new("bunny", vec![bunny], bunny_transform)),
        Group::new("building", meshes, Transform::default()),
    ])
}

/// From the courtyard's north-west corner, looking at the bunny's arch across the fountain.
pub fn camera() -> Camera {
    Camera {
        position: Vec3::new(-2.4, 1.6, -2.4),
        target: Vec3::new(COURT, 0.8, 0.0),
        up: Vec3::Y,
        fov_y_deg: 60.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn the_atrium_is_modest_and_its_camera_is_in_the_open_courtyard() {
        let scene = Scene::builtin("atrium").unwrap();
        assert!(
            scene.triangle_count() < 6000,
            "{} triangles: keep it light for lavapipe",
            scene.triangle_count()
        );
        // No walkthrough: `--animate` moves the bunny.
        assert!(scene.walkthrough.is_empty());
        // Under the open courtyard (that nothing hides the sky from it: the probes' solids tests).
        let c = scene.camera.position;
        assert!(c.x.abs() < COURT && c.z.abs() < COURT && c.y > 0.0 && c.y < ROOF, "{c}");
        // The static bounds: the building, floor to roof.
        let (lo, hi) = scene.groups[1]
            .meshes
            .iter()
            .flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)))
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
        assert!(lo.abs_diff_eq(Vec3::new(-outer(), -0.1, -outer()), 1e-5), "{lo}");
        assert!(hi.abs_diff_eq(Vec3::new(outer(), ROOF + SLAB, outer()), 1e-5), "{hi}");
    }
}
