//! The JSON scene file schema, shared by loading and exporting. Every struct rejects unknown
//! fields, so a misspelt key is an error rather than a silently ignored setting.
//!
//! ```json
//! {
//!   "camera": {"position": [0, 2, 6], "target": [0, 0.5, 0], "up": [0, 1, 0], "fov_y_deg": 40},
//!   "environment": {"image": "env.exr", "intensity": 1.0},
//!   "groups": [{"name": "teapot", "translation": [0, 0, 0], "rotation_deg": [0, 30, 0], "scale": 1.0,
//!               "meshes": [{"obj": "teapot.obj", "albedo": [0.8, 0.8, 0.8]},
//!                          {"plane": {"size": [10, 10], "vertices": [31, 31]}, "albedo": [0.6, 0.6, 0.6]},
//!                          {"sphere": {"radius": 1, "segments": 64}, "albedo": [0.5, 0.5, 0.5]}]}],
//!   "lights": [{"point": {"position": [0, 3, 0], "intensity": [5, 5, 5]}},
//!              {"spot": {"position": [2, 3, 0], "direction": [-1, -1, 0], "fov_deg": 60, "intensity": [9, 9, 9]}}]
//! }
//! ```
//!
//! - `environment` is exactly one of `image` (a path to .exr or .hdr), `constant` (an RGB
//!   radiance); `intensity` (default 1) scales it. Optional: without one the scene is lit by a
//!   constant sky of radiance [`super::DEFAULT_SKY`], as a glTF file read alone is
//!   ([`super::Loaded::default_environment`] says so).
//! - A group's rotation is `rotation_deg`, Euler angles in degrees with R = Rz · Ry · Rx (X
//!   applied first), or `rotation_quat` [x, y, z, w]; `translation`, rotation and `scale`
//!   (uniform, > 0) are optional.
//! - A mesh is exactly one of `obj`, `plane` (in XZ, normal +Y, `vertices` = grid vertex counts
//!   along X and Z) or `sphere`; `name` defaults to the OBJ's file stem or the shape's kind.
//! - `name` defaults to the scene file's stem; `camera.up` defaults to +Y; `lights` defaults to none.
//! - `walkthrough` (optional): cameras, in the form of `camera`, that `kage render --animate`
//!   visits in order.
//! - `probes` (optional): light probes placed by hand, `{"position": [x, y, z], "role": "sky"}`
//!   with `role` optional, one of `sky`, `bounce`, `bleed` ([`super::ProbeRole`]).
//! - `keyframes` (optional, per group): `{"time": seconds, "translation": [x, y, z],
//!   "rotation_deg" or "rotation_quat", "scale"}` in increasing time (`scale` optional, default
//!   the group's), with `loop_seconds` (optional) to repeat them: the group's motion
//!   (`super::motion`).
//! - `exposure` (optional, > 0, default 1): what a PNG of the scene is multiplied by before
//!   tonemapping when the command names no `--exposure`.
//! - `gltf` (optional): a glTF 2.0 file (.gltf or .glb) whose groups, lights and camera the
//!   scene takes ([`super::gltf`]); the file adds what glTF has no place for (the environment,
//!   probes, walkthrough, exposure) and may add geometry: its `groups` come after the glTF's
//!   (a floor under a model, say). Its `camera`, where given,
//!   replaces the glTF one; `gltf_camera` names the glTF camera to take (a camera's or its
//!   node's name) instead of the first; `gltf_groups` names nodes that are groups of their own
//!   (besides the root nodes); its `lights` are added to the glTF ones.
//! - `camera` is required unless a glTF file gives one.
//! - Relative paths are relative to the folder of the scene file.
use serde::{Deserialize, Serialize};

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gltf: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gltf_camera: Option<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub gltf_groups: Vec<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvironmentDesc>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupDesc>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<LightDesc>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub walkthrough: Vec<CameraDesc>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub probes: Vec<ProbeDesc>,
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub exposure: f32,
}

fn is_one(value: &f32) -> bool {
    *value == 1.0
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeDesc {
    pub position: [f32; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub role: Option<super::ProbeRole>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub position: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "up")]
    pub up: [f32; 3],
    pub fov_y_deg: f32,
}

fn up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constant: Option<[f32; 3]>,
    #[serde(default = "one")]
    pub intensity: f32,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupDesc {
    pub name: String,
    #[serde(default)]
    pub translation: [f32; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation_deg: Option<[f32; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation_quat: Option<[f32; 4]>,
    #[serde(default = "one")]
    pub scale: f32,
    pub meshes: Vec<MeshDesc>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub keyframes: Vec<KeyframeDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_seconds: Option<f32>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeDesc {
    pub time: f32,
    pub translation: [f32; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation_deg: Option<[f32; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation_quat: Option<[f32; 4]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f32>,
}

fn one() -> f32 {
    1.0
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obj: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<PlaneDesc>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sphere: Option<SphereDesc>,
    pub albedo: [f32; 3],
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneDesc {
    pub size: [f32; 2],
    pub vertices: [u32; 2],
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereDesc {
    pub radius: f32,
    pub segments: u32,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightDesc {
    Point(PointDesc),
    Spot(SpotDesc),
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointDesc {
    pub position: [f32; 3],
    pub intensity: [f32; 3],
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpotDesc {
    pub position: [f32; 3],
    pub direction: [f32; 3],
    pub fov_deg: f32,
    pub intensity: [f32; 3],
}
