//! Scenes compiled into the library, so that Kage renders something with no file on disk.
//! Their assets live in `engine/assets/` (licences in `engine/assets/LICENSES.md`): copies of
//! the shared reference assets, embedded so the library needs no file at run time.
use super::motion;
use glam::Vec3;

mod asm_room;
pub mod atrium;
mod probe_room;
mod two_rooms;

use super::{obj, shapes, Camera, EnvMap, Group, Scene, SceneError, Transform};

const TEAPOT_OBJ: &[u8] = include_bytes!("../../../assets/teapot.obj");
const COURTYARD_EXR: &[u8] = include_bytes!("../../../assets/courtyard.exr");
/// The Stanford bunny (3,674 triangles) that probe-room, the atrium and the asm scene place.
const BUNNY_OBJ: &[u8] = include_bytes!("../../../assets/bunny.obj");

/// The teapot's bounds in its OBJ: +Y up, centred on the origin, 15.75 units tall.
const TEAPOT_HEIGHT: f32 = 15.75;

/// Names accepted by [`Scene::builtin`]; the first is the default.
pub const BUILTIN: &[&str] = &["teapot", "teapot-hires-floor", "probe-room", "asm", "atrium", "two-rooms"];

pub fn builtin(name: &str) -> Result<Scene, SceneError> {
    if name == "probe-room" {
        let camera = Camera {
            position: Vec3::new(0.0, 1.4, 1.9),
            target: Vec3::new(0.0, 0.5, 0.0),
            up: Vec3::Y,
            fov_y_deg: 70.0,
        };
        // The room is lit through its open front only: it reads at four times the light.
        return courtyard_scene(name, probe_room::groups, camera, 4.0);
    }
    if name == "atrium" {
        return courtyard_scene(name, atrium::groups, atrium::camera(), 1.0);
    }
    if name == "two-rooms" {
        let camera = Camera {
            position: Vec3::new(3.6, 1.9, 1.8),
            target: Vec3::new(0.0, 0.5, -0.6),
            up: Vec3::Y,
            fov_y_deg: 70.0,
        };
        // Lit through two openings only, as probe-room is.
        return courtyard_scene(name, two_rooms::groups, camera, 4.0);
    }
    // Floor grid vertices per side: 31×31 is the paper's low-resolution receiver, 111×111 its
    // high-resolution one.
    let floor_vertices = match name {
        "teapot" => 31,
        "teapot-hires-floor" => 111,
        "asm" => return asm_room::asm_scene(),
        _ => {
            return Err(SceneError::invalid(format!(
                "no built-in scene \"{name}\"; the built-in scenes are: {}",
                BUILTIN.join(", ")
            )))
        }
    };
    let context = context(name);
    let teapot = obj::parse_obj(TEAPOT_OBJ, "teapot", [0.75; 3]).map_err(context)?;
    let floor = shapes::plane("floor", [6.0, 6.0], [floor_vertices; 2], [0.6; 3]).map_err(context)?;
    let environment = EnvMap::from_exr_bytes(COURTYARD_EXR).map_err(context)?;

    // One unit tall, standing on the floor.
    let teapot_transform = Transform {
        translation: Vec3::new(0.0, 0.5, 0.0),
        scale: 1.0 / TEAPOT_HEIGHT,
        ..Transform::default()
    };
    Ok(Scene {
        name: name.to_string(),
        groups: vec![
            motion::hopping(Group::new("teapot", vec![teapot], teapot_transform)),
            Group::new("floor", vec![floor], Transform::default()),
        ],
        environment,
        lights: Vec::new(),
        walkthrough: Vec::new(),
        probes: Vec::new(),
        exposure: 1.0,
        camera: Camera {
            position: Vec3::new(0.0, 2.2, 4.2),
            target: Vec3::new(0.0, 0.4, 0.0),
            up: Vec3::Y,
            fov_y_deg: 40.0,
        },
    })
}

/// The embedded assets are known good, but a failure still reports rather than panics.
fn context(name: &str) -> impl Fn(SceneError) -> SceneError + Copy + '_ {
    move |e: SceneError| e.within(&format!("built-in scene \"{name}\""))
}

/// A scene of `groups` under the courtyard sky, seen by `camera`, with no local light: the
/// probe scenes. See [`probe_room`] (the room lit through its opening, seen from inside near
/// the front wall) and [`atrium`] (the bunny passing from the courtyard's sun into the
/// gallery's shade).
fn courtyard_scene(
    name: &str,
    groups: fn() -> Result<Vec<Group>, SceneError>,
    camera: Camera,
    exposure: f32,
) -> Result<Scene, SceneError> {
    let context = context(name);
    Ok(Scene {
        name: name.to_string(),
        groups: groups().map_err(context)?,
        environment: EnvMap::from_exr_bytes(COURTYARD_EXR).map_err(context)?,
        lights: Vec::new(),
        walkthrough: Vec::new(),
        probes: Vec::new(),
        exposure,
        camera,
    })
}
