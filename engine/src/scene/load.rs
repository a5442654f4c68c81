//! Turning a parsed scene file into a validated [`Scene`]. Errors name the scene file and where
//! in it the problem is; errors in a referenced file name that file too.
use super::motion::{Key, Motion};
use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use super::file::{CameraDesc, EnvironmentDesc, GroupDesc, LightDesc, MeshDesc, SceneFile};
use super::{obj, shapes, Camera, EnvMap, Group, Light, Mesh, Scene, SceneError, SceneProbe, Transform};
use crate::files;

/// The radiance of the constant sky that lights a scene whose file gives no environment (a glTF
/// file read alone, a scene file without `environment`): the one place this default is set.
pub const DEFAULT_SKY: f32 = 1.0;

/// A scene read from a file, and what the file left to the default. Only the caller knows
/// whether it replaces the default (the command line's `--env`), so the loader prints no note
/// about it: the caller tells the user, or documents it (the C ABI's `kage_scene_load`).
#[derive(Clone, Debug, PartialEq)]
pub struct Loaded {
    pub scene: Scene,
    /// The file gave no environment: the scene is lit by a constant sky of radiance
    /// [`DEFAULT_SKY`].
    pub default_environment: bool,
}

pub fn load(path: &Path) -> Result<Loaded, SceneError> {
    let bytes = files::read(path, files::JSON).map_err(|e| SceneError::in_file(path, e.to_string()))?;
    let json = files::without_bom(&bytes);
    let file: SceneFile = serde_json::from_slice(json)
        .map_err(|e| SceneError::in_file(path, format!("invalid scene JSON: {e}")))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    let name = file.name.clone().or(stem).unwrap_or_default();
    build(file, name, folder).map_err(|e| e.attributed_to(path))
}

/// A glTF file read alone: as a scene file that names it and gives nothing else (so it is lit by
/// the default sky).
pub fn gltf_alone(path: &Path) -> Result<Loaded, SceneError> {
    let file = SceneFile {
        name: None,
        gltf: Some(path.file_name().unwrap_or_default().to_string_lossy().into_owned()),
        gltf_camera: None,
        gltf_groups: Vec::new(),
        camera: None,
        environment: None,
        groups: Vec::new(),
        lights: Vec::new(),
        walkthrough: Vec::new(),
        probes: Vec::new(),
        exposure: 1.0,
    };
    let folder = path.parent().unwrap_or(Path::new(""));
    let name = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    build(file, name, folder).map_err(|e| e.attributed_to(path))
}

/// The albedo of an OBJ file read alone (given straight to [`super::Scene::read`]): OBJ materials are not read.
pub const LONE_OBJ_ALBEDO: [f32; 3] = [0.8; 3];

/// An OBJ file read alone: as a scene file holding one group of it at rest, albedo
/// [`LONE_OBJ_ALBEDO`], lit as a glTF file read alone ([`gltf_alone`]), viewed whole from the
/// front ([`super::gltf::overview`]); no ground, lights or probes are added. A note says so.
pub fn obj_alone(path: &Path) -> Result<Loaded, SceneError> {
    let file_name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
    let name = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let mesh =
        MeshDesc { name: None, obj: Some(file_name), plane: None, sphere: None, albedo: LONE_OBJ_ALBEDO };
    let group = GroupDesc {
        name: name.clone(),
        translation: [0.0; 3],
        rotation_deg: None,
        rotation_quat: None,
        scale: 1.0,
        meshes: vec![mesh],
        keyframes: Vec::new(),
        loop_seconds: None,
    };
    let file = SceneFile {
        name: None,
        gltf: None,
        gltf_camera: None,
        gltf_groups: Vec::new(),
        camera: None,
        environment: None,
        groups: vec![group],
        lights: Vec::new(),
        walkthrough: Vec::new(),
        probes: Vec::new(),
        exposure: 1.0,
    };
    let folder = path.parent().unwrap_or(Path::new(""));
    let loaded = assemble(file, name, folder, true).map_err(|e| e.attributed_to(path))?;
    eprintln!(
        "kage: note: {} read alone: one group at rest, albedo {}, viewed whole from the front, no \
         ground (a scene file gives more)",
        path.display(),
        LONE_OBJ_ALBEDO[0]
    );
    Ok(loaded)
}

/// Assembles a scene from its description; `folder` anchors the relative paths in it. With a
/// glTF file, its groups come first and the listed ones after them.
fn build(file: SceneFile, name: String, folder: &Path) -> Result<Loaded, SceneError> {
    assemble(file, name, folder, false)
}

/// [`build`], and with `view_whole` a description without a camera (a model file read alone)
/// is viewed whole from the front instead of refused.
fn assemble(file: SceneFile, name: String, folder: &Path, view_whole: bool) -> Result<Loaded, SceneError> {
    let own_camera = file.camera.as_ref().map(camera).transpose()?;
    let walkthrough = file
        .walkthrough
        .iter()
        .enumerate()
        .map(|(at, c)| camera(c).map_err(|e| e.within(&format!("walkthrough camera {at}"))))
        .collect::<Result<Vec<_>, _>>()?;
    super::animation::check_walkthrough(&walkthrough)?;
    let environment = match &file.environment {
        Some(desc) => environment(desc, folder)?,
        None => EnvMap::constant([DEFAULT_SKY; 3]),
    };
    let gltf_options = file.gltf_camera.is_some() || !file.gltf_groups.is_empty();
    let (mut groups, mut lights, gltf_camera) = match (&file.gltf, gltf_options) {
        (Some(gltf), _) => {
            let parts =
                super::gltf::parts(&folder.join(gltf), file.gltf_camera.as_deref(), &file.gltf_groups)?;
            (parts.groups, parts.lights, parts.camera)
        }
        (None, true) => {
            return Err(SceneError::invalid("\"gltf_camera\" or \"gltf_groups\" without a \"gltf\" file"))
        }
        (None, false) if file.groups.is_empty() => return Err(SceneError::invalid("it has no groups")),
        (None, false) => (Vec::new(), Vec::new(), None),
    };
    let listed: Vec<Group> = file
        .groups
        .into_iter()
        .enumerate()
        .map(|(at, g)| {
            let place = format!("group {at} (\"{}\")", g.name);
            group(g, folder).map_err(|e| e.within(&place))
        })
        .collect::<Result<_, _>>()?;
    groups.extend(listed);
    let camera = match (own_camera, gltf_camera) {
        (Some(camera), _) | (None, Some(camera)) => camera,
        (None, None) if file.gltf.is_some() => {
            eprintln!("kage: note: the glTF file has no camera: viewing the whole scene from the front");
            super::gltf::overview(&groups)
        }
        (None, None) if view_whole => super::gltf::overview(&groups),
        (None, None) => return Err(SceneError::invalid("it has no \"camera\"")),
    };
    let listed: Vec<Light> = file
        .lights
        .into_iter()
        .enumerate()
        .map(|(at, l)| light(l).validated_as(at))
        .collect::<Result<_, _>>()?;
    lights.extend(listed);
    let probes = file
        .probes
        .iter()
        .enumerate()
        .map(|(at, p)| {
            let position = Vec3::from(p.position);
            if !position.is_finite() {
                return Err(SceneError::invalid(format!("probe {at}: position {position} is not finite")));
            }
            Ok(SceneProbe { position, role: p.role })
        })
        .collect::<Result<_, _>>()?;
    let scene =
        Scene { name, groups, environment, lights, camera, walkthrough, probes, exposure: file.exposure };
    // The rules every scene meets however it was made (its extent among them), checked here
    // too so that a file's fault is named with the file, not found when a renderer is made.
    scene.validate()?;
    Ok(Loaded { scene, default_environment: file.environment.is_none() })
}

fn environment(desc: &EnvironmentDesc, folder: &Path) -> Result<EnvMap, SceneError> {
    let map = match (&desc.image, desc.constant) {
        (Some(image), None) => EnvMap::load(&folder.join(image))?,
        (None, Some(rgb)) => {
            if rgb.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
                return Err(SceneError::invalid(format!(
                    "environment constant {rgb:?} must be finite and >= 0"
                )));
            }
            EnvMap::constant(rgb)
        }
        _ => return Err(SceneError::invalid("environment needs exactly one of \"image\" or \"constant\"")),
    };
    map.scaled(desc.intensity)
}

/// A rotation given as Euler angles in degrees or as a quaternion, or neither (none).
fn rotation_of(degrees: Option<[f32; 3]>, quat: Option<[f32; 4]>) -> Result<Quat, SceneError> {
    match (degrees, quat) {
        (None, None) => Ok(Quat::IDENTITY),
        (Some(degrees), None) => Ok(Transform::rotation_from_euler_deg(degrees)),
        (None, Some(q)) => Ok(Quat::from_array(q)),
        (Some(_), Some(_)) => {
            Err(SceneError::invalid("give either \"rotation_deg\" or \"rotation_quat\", not both"))
        }
    }
}

fn group(desc: GroupDesc, folder: &Path) -> Result<Group, SceneError> {
    let rotation = rotation_of(desc.rotation_deg, desc.rotation_quat)?;
    let transform =
        Transform { translation: Vec3::from(desc.translation), rotation, scale: desc.scale }.validated()?;
    if desc.meshes.is_empty() {
        return Err(SceneError::invalid("it has no meshes"));
    }
    let meshes = desc
        .meshes
        .into_iter()
        .enumerate()
        .map(|(at, m)| meshes(m, folder).map_err(|e| e.within(&format!("mesh {at}"))))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
        .collect();
    let keys = desc
        .keyframes
        .iter()
        .enumerate()
        .map(|(k, key)| {
            let rotation = rotation_of(key.rotation_deg, key.rotation_quat)
                .map_err(|e| e.within(&format!("keyframe {k}")))?;
            Ok(Key {
                time: key.time,
                translation: Vec3::from(key.translation),
                rotation,
                scale: key.scale.unwrap_or(transform.scale),
            })
        })
        .collect::<Result<Vec<Key>, SceneError>>()?;
    let motion = match (keys.is_empty(), desc.loop_seconds) {
        (true, None) => None,
        (true, Some(_)) => return Err(SceneError::invalid("loop_seconds without keyframes")),
        (false, loop_seconds) => Some(Motion { keys, loop_seconds }),
    };
    Ok(Group { name: desc.name, meshes, transform, motion })
}

/// The meshes of one mesh entry: one, or one per albedo map of an OBJ whose faces use several
/// (named after the entry's `name`, with `.k` where there are several).
fn meshes(desc: MeshDesc, folder: &Path) -> Result<Vec<Mesh>, SceneError> {
    let mut meshes = match (desc.obj, desc.plane, desc.sphere) {
        (Some(obj), None, None) => {
            let path: PathBuf = folder.join(obj);
            obj::load_obj(&path, desc.albedo)?
        }
        (None, Some(p), None) => vec![shapes::plane("plane", p.size, p.vertices, desc.albedo)?],
        (None, None, Some(s)) => vec![shapes::sphere("sphere", s.radius, s.segments, desc.albedo)?],
        _ => return Err(SceneError::invalid("a mesh needs exactly one of \"obj\", \"plane\" or \"sphere\"")),
    };
    if let Some(name) = desc.name {
        let several = meshes.len() > 1;
        for (k, mesh) in meshes.iter_mut().enumerate() {
            mesh.name = if several { format!("{name}.{k}") } else { name.clone() };
        }
    }
    Ok(meshes)
}

pub(super) fn camera(desc: &CameraDesc) -> Result<Camera, SceneError> {
    Camera::from_arrays(desc.position, desc.target, desc.up, desc.fov_y_deg)
}

/// The light a scene file describes, before [`Light::validated_as`] checks it.
pub(super) fn light(desc: LightDesc) -> Light {
    match desc {
        LightDesc::Point(p) => Light::Point { position: Vec3::from(p.position), intensity: p.intensity },
        LightDesc::Spot(s) => Light::Spot {
            position: Vec3::from(s.position),
            direction: Vec3::from(s.direction),
            fov_deg: s.fov_deg,
            intensity: s.intensity,
        },
    }
}
