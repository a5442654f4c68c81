//! What a scene holds and how it is read and written.
//!
//! A [`Scene`] is rigid [`Group`]s of triangle [`Mesh`]es (one diffuse albedo each, times an
//! optional [`AlbedoMap`] per pixel), one environment light ([`EnvMap`]), optional local
//! [`Light`]s and a [`Camera`]. Nothing more until a technique needs it.
//!
//! Conventions:
//! - Right-handed, +Y up. Group transforms scale uniformly, then rotate, then translate; Euler
//!   angles in scene files are degrees with R = Rz · Ry · Rx (X applied first).
//! - Triangles wind counter-clockwise seen from the side their normals point to.
//! - Equirectangular environment maps: direction (x, y, z) ↔ u = atan2(x, −z) / 2π wrapped into
//!   [0, 1), v = acos(y) / π; row 0 is the top (+Y); pixel centres at ((i + ½) / width,
//!   (j + ½) / height). See [`envmap`] for the details and [`direction_to_uv`] for the code.
//! - The camera's projection targets Vulkan clip space (depth 0..1) with +Y world up in the image.
//!
//! Scenes come from JSON files ([`file`](mod@file) documents the schema), from a glTF 2.0 or
//! OBJ file read alone ([`Scene::load`]: a constant sky of radiance 1, the whole model in view,
//! an OBJ at albedo [`LONE_OBJ_ALBEDO`] with no ground added), from the built-in set
//! ([`BUILTIN`]), or from code. Every loading error is a [`SceneError`] naming the file and the
//! problem.
use glam::Vec3;
use std::path::Path;

pub mod albedo_map;
pub mod animation;
pub(crate) mod builtin;
mod camera;
pub mod clusters;
pub mod envmap;
mod error;
mod export;
pub mod file;
pub mod gltf;
mod light;
mod load;
mod mesh;
pub mod motion;
mod obj;
mod probe;
pub mod shapes;
mod sun_map;
mod transform;

pub use albedo_map::{AlbedoMap, Texturing};
pub use builtin::BUILTIN;
pub use camera::{Camera, FAR, NEAR};
pub use envmap::{direction_to_uv, uv_to_direction, EnvMap};
pub use error::{clip, clip_message, SceneError, CLIP_CHARS};
pub use export::{SceneFormat, ENVIRONMENT_FILE, GLTF_FILE, SCENE_FILE};
pub use light::{Light, MAX_SPOT_FOV_DEG};
pub use load::LONE_OBJ_ALBEDO;
pub use load::{Loaded, DEFAULT_SKY};
pub use mesh::{check_index_count, check_vertex_count, Mesh, MAX_MESH_VERTICES, MAX_TRIANGLES};
pub use motion::Motion;
pub use obj::{load_obj, parse_obj, write_obj};
pub use probe::{ProbeRole, SceneProbe};
pub use sun_map::SunMap;

/// How far from the origin, in world units along any axis, a scene's geometry may reach. The
/// shadow maps of the local-light and parallel-light techniques fit the whole scene, and with
/// f32 depth a scene spanning far more than this (one small sphere at 1e20) shadows everything;
/// at 1e6 a 4096² map's texel is still finer than the scene's extent over 1e3.
pub const MAX_EXTENT: f32 = 1e6;
pub use transform::Transform;

/// What a `--scene` argument ending in one of these (any case) names: a scene file, even
/// where there is none to read (the error names the file, not a missing built-in scene).
const SCENE_EXTENSIONS: [&str; 4] = [".json", ".gltf", ".glb", ".obj"];

#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub name: String,
    pub groups: Vec<Group>,
    pub environment: EnvMap,
    pub lights: Vec<Light>,
    pub camera: Camera,
    /// Camera keyframes of the scripted walkthrough (`kage render --animate`), visited in order
    /// and back to the first; empty for a scene without one (see [`animation::camera_at`]).
    pub walkthrough: Vec<Camera>,
    /// Light probes placed by hand (`probes` in a scene file); empty for most scenes.
    pub probes: Vec<SceneProbe>,
    /// What a PNG of the scene is multiplied by before tonemapping when the user names no
    /// exposure (`exposure` in a scene file, default 1): a dim room reads at 4.
    pub exposure: f32,
}

impl Scene {
    /// A scene of `groups` under `environment` seen from `camera`, with no lights, walkthrough
    /// or hand-placed probes, at exposure 1 (change those fields with struct update syntax).
    pub fn new(name: impl Into<String>, groups: Vec<Group>, environment: EnvMap, camera: Camera) -> Scene {
        Scene {
            name: name.into(),
            groups,
            environment,
            lights: Vec::new(),
            camera,
            walkthrough: Vec::new(),
            probes: Vec::new(),
            exposure: 1.0,
        }
    }
}

/// Meshes that move together.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub name: String,
    pub meshes: Vec<Mesh>,
    /// Its pose at rest; with a motion, its motion gives its pose.
    pub transform: Transform,
    /// Its keyframes (`keyframes` in a scene file), which `--animate` and `--time` play.
    pub motion: Option<Motion>,
}

impl Group {
    /// A group at rest at `transform` (no keyframes).
    pub fn new(name: impl Into<String>, meshes: Vec<Mesh>, transform: Transform) -> Group {
        Group { name: name.into(), meshes, transform, motion: None }
    }

    /// The largest coordinate of its meshes along any axis, in object space.
    pub fn object_reach(&self) -> f32 {
        let coordinates = self.meshes.iter().flat_map(|m| m.positions.iter().flatten());
        coordinates.map(|c| c.abs()).fold(0.0, f32::max)
    }
}

/// Checks that a group of `object_reach` placed by `translation` and `scale` lies within
/// [`MAX_EXTENT`] (the one rule for scene files, scenes built in code and moved groups).
pub fn check_extent(translation: Vec3, scale: f32, object_reach: f32) -> Result<(), SceneError> {
    let reach = translation.abs().max_element() + scale * object_reach;
    if reach > MAX_EXTENT {
        return Err(SceneError::invalid(format!(
            "it reaches {reach:e} from the origin; scenes must lie within {MAX_EXTENT:e} of it (the \
             shadow maps fit the whole scene, and f32 depth loses every shadow beyond that)"
        )));
    }
    Ok(())
}

impl Scene {
    /// Reads a scene file: JSON (relative paths inside it are relative to its folder), or by
    /// its extension (any case) glTF 2.0, .gltf or .glb ([`gltf`]), or a Wavefront .obj. A model
    /// file read alone is lit by a constant sky of radiance 1 and, without a camera of its own,
    /// viewed whole from the front; an OBJ is one group at rest of albedo
    /// [`LONE_OBJ_ALBEDO`], with no ground added. A note on stderr says so; [`Scene::read`] says whether the sky is the default.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Scene::read(path).map(|loaded| loaded.scene)
    }

    /// [`Scene::load`], saying whether the scene's environment is the default sky.
    pub fn read(path: &Path) -> Result<Loaded, SceneError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("gltf" | "glb") => load::gltf_alone(path),
            Some("obj") => load::obj_alone(path),
            _ => load::load(path),
        }
    }

    /// One of the scenes in [`BUILTIN`]; an unknown name is an error that lists them.
    pub fn builtin(name: &str) -> Result<Scene, SceneError> {
        builtin::builtin(name)
    }

    /// What a `--scene` argument means: an existing file or a name ending in `.json`, `.gltf`,
    /// `.glb` or `.obj` (any case) is a scene file ([`Scene::load`]), a folder holding [`SCENE_FILE`] (as [`Scene::export`] writes it) that file, then a
    /// built-in name is that scene (so a folder named like a built-in scene does not hide it),
    /// and any other existing path is a file that cannot be read (a folder without
    /// [`SCENE_FILE`], a device, a FIFO): an error naming it, not "no built-in scene".
    pub fn from_arg(arg: &str) -> Result<Scene, SceneError> {
        Scene::read_arg(arg).map(|loaded| loaded.scene)
    }

    /// [`Scene::from_arg`], saying whether the scene's environment is the default sky (a
    /// built-in scene's never is).
    pub fn read_arg(arg: &str) -> Result<Loaded, SceneError> {
        let builtin = |name| Scene::builtin(name).map(|scene| Loaded { scene, default_environment: false });
        let path = Path::new(arg);
        if path.join(SCENE_FILE).is_file() {
            Scene::read(&path.join(SCENE_FILE))
        } else if path.is_file() || SCENE_EXTENSIONS.iter().any(|e| arg.to_ascii_lowercase().ends_with(e)) {
            Scene::read(path)
        } else if BUILTIN.contains(&arg) {
            builtin(arg)
        } else if path.is_dir() {
            Err(SceneError::in_file(
                path,
                format!(
                    "a folder without {SCENE_FILE}; a scene is a scene file, a folder holding one, \
                     or a built-in name: {}",
                    BUILTIN.join(", ")
                ),
            ))
        } else if path.symlink_metadata().is_ok() {
            Scene::read(path)
        } else {
            builtin(arg)
        }
    }

    /// Writes `dir/`[`SCENE_FILE`] and the environment as 32-bit float EXR, with the geometry
    /// as one OBJ per mesh or as `dir/`[`GLTF_FILE`] ([`SceneFormat`]), such that
    /// [`Scene::load`] of the written scene file gives back this scene exactly (meshes made by
    /// [`Mesh::new`] keep their vertex order; see [`Mesh`]).
    pub fn export(&self, dir: &Path, format: SceneFormat) -> Result<(), SceneError> {
        export::export(self, dir, format)
    }

    /// Checks what loading guarantees, for a scene built or changed in code (its fields are
    /// public, so nothing else does): every mesh as [`Mesh::validate`], every group transform,
    /// light and camera as their `validated`. The error names the group and mesh at fault.
    /// Groups without meshes, and scenes without groups, are allowed here: they draw nothing
    /// and cast no shadow (scene files and the C ABI refuse them as likely mistakes).
    pub fn validate(&self) -> Result<(), SceneError> {
        for (g, group) in self.groups.iter().enumerate() {
            let place = format!("scene \"{}\": group {g} (\"{}\")", self.name, group.name);
            group.transform.validated().map_err(|e| e.within(&place))?;
            for (m, mesh) in group.meshes.iter().enumerate() {
                mesh.validate().map_err(|e| e.within(&format!("{place}: mesh {m}")))?;
            }
            let t = &group.transform;
            check_extent(t.translation, t.scale, group.object_reach()).map_err(|e| e.within(&place))?;
            if let Some(motion) = &group.motion {
                motion.validate().map_err(|e| e.within(&place))?;
                for key in &motion.keys {
                    check_extent(key.translation, key.scale, group.object_reach())
                        .map_err(|e| e.within(&place))?;
                }
            }
        }
        let indices = self.meshes().map(|(_, m)| m.indices.len()).sum();
        check_index_count(indices).map_err(|e| e.within(&format!("scene \"{}\"", self.name)))?;
        for (l, light) in self.lights.iter().enumerate() {
            light.validated_as(l).map_err(|e| e.within(&format!("scene \"{}\"", self.name)))?;
        }
        self.camera.validated().map_err(|e| e.within(&format!("scene \"{}\"", self.name)))?;
        animation::check_walkthrough(&self.walkthrough)
            .map_err(|e| e.within(&format!("scene \"{}\"", self.name)))?;
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Err(SceneError::invalid(format!(
                "scene \"{}\": exposure {} is not a positive number",
                self.name, self.exposure
            )));
        }
        Ok(())
    }

    /// How long one pass of its groups' motions lasts, seconds: the longest (0 without any).
    pub fn duration(&self) -> f32 {
        self.groups.iter().filter_map(|g| g.motion.as_ref()).map(Motion::duration).fold(0.0, f32::max)
    }

    /// Its groups' transforms at `time` seconds of their motions.
    pub fn poses_at(&self, time: f32) -> Vec<Transform> {
        self.groups.iter().map(|g| g.pose_at(time)).collect()
    }

    pub fn meshes(&self) -> impl Iterator<Item = (&Group, &Mesh)> {
        self.groups.iter().flat_map(|g| g.meshes.iter().map(move |m| (g, m)))
    }

    pub fn triangle_count(&self) -> usize {
        self.meshes().map(|(_, m)| m.triangle_count()).sum()
    }

    pub fn vertex_count(&self) -> usize {
        self.meshes().map(|(_, m)| m.vertex_count()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A finite but far-away group is refused with the group, the distance and the limit, not
    /// drawn with every surface shadowed.
    #[test]
    fn geometry_beyond_the_extent_is_refused() {
        let mut scene = Scene::builtin("teapot").unwrap();
        scene.validate().unwrap();
        scene.groups[0].transform.translation.x = 1e20;
        let error = scene.validate().unwrap_err().to_string();
        assert!(error.contains("group 0") && error.contains("1e20") && error.contains("1e6"), "{error}");
    }
}
