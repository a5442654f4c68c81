//! Writing a scene as a self-contained folder that [`Scene::load`] reads back identically:
//! `scene.json` and the environment as 32-bit float EXR, with the geometry as one OBJ per mesh
//! ([`SceneFormat::Json`]) or as `scene.glb` ([`SceneFormat::Gltf`]: groups, meshes, lights,
//! camera and motion; the JSON then holds what glTF has no place for).
use std::collections::HashSet;
use std::path::{Path, PathBuf};

use super::file::{
    CameraDesc, EnvironmentDesc, GroupDesc, KeyframeDesc, LightDesc, MeshDesc, PointDesc, ProbeDesc,
    SceneFile, SpotDesc,
};
use super::{obj, Camera, Light, Scene, SceneError};

pub const SCENE_FILE: &str = "scene.json";
pub const ENVIRONMENT_FILE: &str = "environment.exr";
pub const GLTF_FILE: &str = "scene.glb";

/// How an exported scene holds its geometry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SceneFormat {
    /// Groups, lights and camera in the scene file, one OBJ per mesh.
    #[default]
    Json,
    /// Groups, lights, camera and motion in a binary glTF file beside the scene file, which
    /// Blender, three.js and other glTF tools open.
    Gltf,
}

/// `dir/name`, unless a symbolic link is there: the export writes its own files, never through
/// a link to a file elsewhere.
fn output(dir: &Path, name: &str) -> Result<PathBuf, SceneError> {
    let path = dir.join(name);
    match std::fs::symlink_metadata(&path) {
        Ok(meta) if meta.file_type().is_symlink() => {
            Err(SceneError::in_file(&path, "is a symbolic link: the export does not write through it"))
        }
        _ => Ok(path),
    }
}

pub fn export(scene: &Scene, dir: &Path, format: SceneFormat) -> Result<(), SceneError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| SceneError::in_file(dir, format!("cannot create folder: {e}")))?;
    scene.environment.write_exr(&output(dir, ENVIRONMENT_FILE)?)?;
    let mut file = SceneFile {
        name: Some(scene.name.clone()),
        gltf: None,
        gltf_camera: None,
        gltf_groups: Vec::new(),
        camera: None,
        // Always written, the default sky too: the folder reads back as the same scene.
        environment: Some(EnvironmentDesc {
            image: Some(ENVIRONMENT_FILE.into()),
            constant: None,
            intensity: 1.0,
        }),
        groups: Vec::new(),
        lights: Vec::new(),
        walkthrough: scene.walkthrough.iter().map(camera).collect(),
        probes: scene
            .probes
            .iter()
            .map(|p| ProbeDesc { position: p.position.to_array(), role: p.role })
            .collect(),
        exposure: scene.exposure,
    };
    match format {
        SceneFormat::Json => {
            file.camera = Some(camera(&scene.camera));
            file.groups = groups(scene, dir)?;
            file.lights = scene.lights.iter().map(light).collect();
        }
        SceneFormat::Gltf => {
            let path = output(dir, GLTF_FILE)?;
            std::fs::write(&path, super::gltf::write_glb(scene))
                .map_err(|e| SceneError::in_file(&path, format!("cannot write: {e}")))?;
            file.gltf = Some(GLTF_FILE.into());
        }
    }
    let path = output(dir, SCENE_FILE)?;
    let json = serde_json::to_string_pretty(&file)
        .map_err(|e| SceneError::in_file(&path, format!("cannot encode scene: {e}")))?;
    std::fs::write(&path, json + "\n").map_err(|e| SceneError::in_file(&path, format!("cannot write: {e}")))
}

/// The groups as the scene file gives them, each mesh written as an OBJ in `dir`.
fn groups(scene: &Scene, dir: &Path) -> Result<Vec<GroupDesc>, SceneError> {
    let mut used_files = HashSet::new();
    let mut groups = Vec::with_capacity(scene.groups.len());
    for group in &scene.groups {
        let mut meshes = Vec::with_capacity(group.meshes.len());
        for mesh in &group.meshes {
            let file = unique_file_name(&mesh.name, &mut used_files);
            obj::write_obj(mesh, &output(dir, &file)?)?;
            meshes.push(MeshDesc {
                name: Some(mesh.name.clone()),
                obj: Some(file),
                plane: None,
                sphere: None,
                albedo: mesh.albedo,
            });
        }
        let t = &group.transform;
        groups.push(GroupDesc {
            name: group.name.clone(),
            translation: t.translation.to_array(),
            rotation_deg: None,
            // A quaternion, not Euler angles, so the rotation reads back bit for bit.
            rotation_quat: Some(t.rotation.to_array()),
            scale: t.scale,
            meshes,
            keyframes: group
                .motion
                .iter()
                .flat_map(|m| &m.keys)
                .map(|k| KeyframeDesc {
                    time: k.time,
                    translation: k.translation.to_array(),
                    rotation_deg: None,
                    rotation_quat: Some(k.rotation.to_array()),
                    scale: (k.scale != t.scale).then_some(k.scale),
                })
                .collect(),
            loop_seconds: group.motion.as_ref().and_then(|m| m.loop_seconds),
        });
    }
    Ok(groups)
}

pub(super) fn camera(c: &Camera) -> CameraDesc {
    CameraDesc {
        position: c.position.to_array(),
        target: c.target.to_array(),
        up: c.up.to_array(),
        fov_y_deg: c.fov_y_deg,
    }
}

pub(super) fn light(light: &Light) -> LightDesc {
    match *light {
        Light::Point { position, intensity } => {
            LightDesc::Point(PointDesc { position: position.to_array(), intensity })
        }
        Light::Spot { position, direction, fov_deg, intensity } => LightDesc::Spot(SpotDesc {
            position: position.to_array(),
            direction: direction.to_array(),
            fov_deg,
            intensity,
        }),
    }
}

/// A portable file name from a mesh name; meshes with the same name get numbered files.
fn unique_file_name(mesh_name: &str, used: &mut HashSet<String>) -> String {
    let stem: String = mesh_name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect();
    let stem = if stem.is_empty() { "mesh".to_string() } else { stem };
    let mut file = format!("{stem}.obj");
    let mut n = 2;
    while !used.insert(file.clone()) {
        file = format!("{stem}-{n}.obj");
        n += 1;
    }
    file
}
