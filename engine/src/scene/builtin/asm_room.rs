//! The built-in `asm` scene, modelled on the Adaptive Shadow Maps paper's (Fernando et al.
//! 2001: a room, a point light with a 122° field of view on the ceiling, the bunny and a finely
//! meshed sculpture): shadows with detail at several scales, for a hierarchy of shadow-map
//! tiles to refine and a conventional map to alias.
//!
//! - An 8 × 8 × 4 room (closed: no environment shows; the environment is black, so the spot
//!   light is all the light there is).
//! - The light: 5 cm below the ceiling's centre, pointing down, a 122° cone. It is a spot light
//!   because the scene format's point lights shine everywhere, and the paper's light has a field
//!   of view; the reference and the shadowmap technique treat its cone identically.
//! - The bunny on the floor (3,674 triangles).
//! - A grating hanging 2 m up: a frame, coarse bars 40 cm apart and fine bars 1.2 cm wide 8 cm
//!   apart; the light, 1.95 m above it, doubles them on the floor.
//! - A lattice cube (5 × 5 × 5 nodes, 2.5 cm bars) standing on the floor.
//! - Six thin vertical rods, 0.8 to 6 cm wide: shadows from sub-texel to several texels wide.
//!
//! The walkthrough (`--animate`) starts from the overview and visits close-ups of the grating's
//! shadow on the floor, the rods' shadows on the floor and wall, the lattice's shadow and the
//! bunny's, with the camera resting at each.
use glam::{Quat, Vec3};

use crate::scene::{obj, shapes, Camera, EnvMap, Group, Light, Scene, SceneError, Transform};

/// The bunny's height in its OBJ (+Y up, standing on y = 0).
const BUNNY_HEIGHT: f32 = 9.655;

type Bar = ([f32; 3], [f32; 3]);

/// A box from `lo` to `hi`.
fn bar(lo: Vec3, hi: Vec3) -> Bar {
    (lo.to_array(), hi.to_array())
}

/// The room's six slabs, 10 cm thick, around the inside x, z ∈ [−4, 4], y ∈ [0, 4].
fn room() -> Vec<Bar> {
    let (h, t) = (4.0, 0.1);
    vec![
        bar(Vec3::new(-h - t, -t, -h - t), Vec3::new(h + t, 0.0, h + t)),
        bar(Vec3::new(-h - t, h, -h - t), Vec3::new(h + t, h + t, h + t)),
        bar(Vec3::new(-h - t, 0.0, -h - t), Vec3::new(-h, h, h + t)),
        bar(Vec3::new(h, 0.0, -h - t), Vec3::new(h + t, h, h + t)),
        bar(Vec3::new(-h, 0.0, -h - t), Vec3::new(h, h, -h)),
        bar(Vec3::new(-h, 0.0, h), Vec3::new(h, h, h + t)),
    ]
}

/// The grating over x ∈ [−0.2, 1.4], z ∈ [−1.6, 0], hanging at y = 2.
fn grating() -> Vec<Bar> {
    let (x0, x1, z0, z1, y) = (-0.2f32, 1.4f32, -1.6f32, 0.0f32, 2.0f32);
    let (frame, coarse, fine) = (0.08, 0.05, 0.012);
    let mut bars = vec![
        bar(Vec3::new(x0, y, z0), Vec3::new(x1, y + frame, z0 + frame)),
        bar(Vec3::new(x0, y, z1 - frame), Vec3::new(x1, y + frame, z1)),
        bar(Vec3::new(x0, y, z0), Vec3::new(x0 + frame, y + frame, z1)),
        bar(Vec3::new(x1 - frame, y, z0), Vec3::new(x1, y + frame, z1)),
    ];
    // Coarse bars along X every 40 cm, fine bars along Z every 8 cm, just below them.
    for k in 1..4 {
        let z = z0 + 0.4 * k as f32;
        bars.push(bar(Vec3::new(x0, y + 0.01, z - 0.5 * coarse), Vec3::new(x1, y + 0.06, z + 0.5 * coarse)));
    }
    for k in 1..20 {
        let x = x0 + 0.08 * k as f32;
        bars.push(bar(Vec3::new(x - 0.5 * fine, y - 0.02, z0), Vec3::new(x + 0.5 * fine, y, z1)));
    }
    bars
}

/// A cube lattice of 5 × 5 × 5 nodes 18 cm apart, bars 2.5 cm thick, its corner at `origin`.
fn lattice(origin: Vec3) -> Vec<Bar> {
    let (n, step, w) = (5, 0.18f32, 0.025f32);
    let length = step * (n - 1) as f32 + w;
    let mut bars = Vec::new();
    for axis in 0..3 {
        let along = Vec3::AXES[axis];
        let (u, v) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
        for i in 0..n {
            for j in 0..n {
                let lo = origin + step * (i as f32 * u + j as f32 * v);
                bars.push(bar(lo, lo + w * (u + v) + length * along));
            }
        }
    }
    bars
}

/// Six rods 2.4 m tall in a row along X at z = −2, widths from 0.8 cm to 6 cm.
fn rods() -> Vec<Bar> {
    [0.008f32, 0.012, 0.018, 0.027, 0.04, 0.06]
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            let x = -3.0 + 0.3 * k as f32;
            bar(Vec3::new(x - 0.5 * w, 0.0, -2.0 - 0.5 * w), Vec3::new(x + 0.5 * w, 2.4, -2.0 + 0.5 * w))
        })
        .collect()
}

fn camera(position: [f32; 3], target: [f32; 3], fov_y_deg: f32) -> Camera {
    Camera { position: Vec3::from(position), target: Vec3::from(target), up: Vec3::Y, fov_y_deg }
}

pub fn asm_scene() -> Result<Scene, SceneError> {
    let context = |e: SceneError| e.within("built-in scene \"asm\"");
    let bunny = obj::parse_obj(super::BUNNY_OBJ, "bunny", [0.8; 3]).map_err(context)?;
    let boxes =
        |name: &str, bars: Vec<Bar>, albedo: f32| shapes::boxes(name, &bars, [albedo; 3]).map_err(context);
    let group = |name: &str, mesh, transform| Group::new(name, vec![mesh], transform);
    let bunny_transform = Transform {
        translation: Vec3::new(-1.2, 0.0, 0.6),
        rotation: Quat::from_rotation_y(30f32.to_radians()),
        scale: 1.25 / BUNNY_HEIGHT,
    };
    let overview = camera([3.2, 2.6, 3.4], [-0.2, 0.5, -0.4], 60.0);
    Ok(Scene {
        name: "asm".into(),
        groups: vec![
            group("bunny", bunny, bunny_transform),
            group("room", boxes("room", room(), 0.7)?, Transform::default()),
            group("grating", boxes("grating", grating(), 0.6)?, Transform::default()),
            group("lattice", boxes("lattice", lattice(Vec3::new(1.5, 0.0, 1.5)), 0.6)?, Transform::default()),
            group("rods", boxes("rods", rods(), 0.5)?, Transform::default()),
        ],
        environment: EnvMap::constant([0.0; 3]),
        lights: vec![Light::Spot {
            position: Vec3::new(0.0, 3.95, 0.0),
            direction: Vec3::NEG_Y,
            fov_deg: 122.0,
            intensity: [16.0; 3],
        }],
        camera: overview,
        walkthrough: vec![
            overview,
            // The grating's doubled bars on the floor, from close above.
            camera([1.0, 0.9, 0.4], [1.4, 0.0, -1.6], 40.0),
            // The rods' shadows running to the back wall.
            camera([-1.6, 0.8, -1.0], [-3.4, 0.2, -3.4], 35.0),
            // The lattice's shadow beside it.
            camera([1.2, 1.2, 3.6], [2.6, 0.0, 2.6], 40.0),
            // The bunny's ears' shadow.
            camera([0.4, 0.7, 2.4], [-1.6, 0.0, 1.2], 35.0),
        ],
        probes: Vec::new(),
        exposure: 1.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_asm_scene_is_modest_closed_and_lit_by_a_122_degree_light() {
        let scene = asm_scene().unwrap();
        assert!(
            scene.triangle_count() < 6000,
            "{} triangles: keep it light for lavapipe",
            scene.triangle_count()
        );
        assert!(matches!(scene.lights[..], [Light::Spot { fov_deg, .. }] if fov_deg == 122.0));
        // Every camera of the walkthrough is inside the room, so no environment ever shows.
        assert!(scene.walkthrough.len() >= 4 && scene.walkthrough[0] == scene.camera);
        for c in &scene.walkthrough {
            let p = c.position;
            assert!(p.x.abs() < 4.0 && p.z.abs() < 4.0 && p.y > 0.0 && p.y < 4.0, "{p}");
            assert!(c.validated().is_ok());
        }
        // Thin rods: the thinnest is under a centimetre, detail for any map to alias.
        let rods = &scene.groups.iter().find(|g| g.name == "rods").unwrap().meshes[0];
        let xs = rods.positions.iter().map(|p| p[0]).filter(|x| *x < -2.9);
        let (lo, hi) = xs.fold((f32::MAX, f32::MIN), |(a, b), x| (a.min(x), b.max(x)));
        assert!(hi - lo < 0.01);
    }
}
