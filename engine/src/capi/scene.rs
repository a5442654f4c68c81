//! `kage_scene`: a scene from a file, a built-in name, or the host's arrays.
use super::args;
use super::handles;
use super::result::{boundary, kage_result, Failure};
use crate::host_memory;
use crate::prt::TransferSet;
use crate::scene::{
    check_index_count, check_vertex_count, Camera, EnvMap, Group, Light, Mesh, Scene, SceneError, Transform,
};
use glam::{Quat, Vec3};
use std::ffi::c_char;
use std::sync::Arc;

/// A scene (geometry, environment light, camera) and what was precomputed for it.
pub struct kage_scene {
    pub(crate) scene: Scene,
    /// The PRT transfer from `kage_precompute`, shared with the renderers made from it.
    pub(crate) transfer: Option<Arc<TransferSet>>,
}

/// A group's rigid placement: uniform `scale`, then `rotation`, then `translation`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct kage_transform {
    pub translation: [f32; 3],
    /// A quaternion (x, y, z, w) of any finite, non-zero length: it is normalized, so only its
    /// direction (the rotation) counts; all zeros is refused.
    pub rotation: [f32; 4],
    /// Greater than 0.
    pub scale: f32,
}

impl kage_transform {
    pub(crate) fn validated(&self) -> Result<Transform, SceneError> {
        Transform {
            translation: Vec3::from(self.translation),
            rotation: Quat::from_array(self.rotation),
            scale: self.scale,
        }
        .validated()
    }
}

/// One triangle mesh of a group, in the group's object space.
#[repr(C)]
pub struct kage_mesh_desc {
    /// 3 floats (x, y, z) per vertex.
    pub positions: *const f32,
    /// 3 floats per vertex, or NULL: then area-weighted vertex normals are computed. A zero or
    /// non-finite normal is not refused: that vertex's normal is computed as if NULL (+Y where
    /// its triangles are all degenerate), with a note on stderr naming the mesh and the count.
    pub normals: *const f32,
    pub vertex_count: u32,
    /// 3 per triangle, counter-clockwise seen from the side the normals point to.
    pub indices: *const u32,
    pub index_count: u32,
    /// Diffuse reflectance per channel, in [0, 1].
    pub albedo: [f32; 3],
}

/// Meshes that move together (a rigid group); `kage_renderer_set_group_transform` moves it.
#[repr(C)]
pub struct kage_group_desc {
    /// A name for messages and debuggers, or NULL.
    pub name: *const c_char,
    pub transform: kage_transform,
    pub meshes: *const kage_mesh_desc,
    pub mesh_count: u32,
}

/// The environment light: an equirectangular map (width = 2 × height) of linear RGB radiance,
/// row 0 at the top (+Y); direction (x, y, z) is at u = atan2(x, -z) / 2π, v = acos(y) / π.
#[repr(C)]
pub struct kage_environment_desc {
    /// 3 floats (r, g, b) per pixel, row-major; finite (negative values are clamped to 0).
    pub pixels: *const f32,
    pub width: u32,
    pub height: u32,
}

/// A pinhole camera (right-handed, +Y up).
#[repr(C)]
pub struct kage_camera_desc {
    pub position: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
}

impl kage_camera_desc {
    pub(crate) fn camera(&self) -> Result<Camera, Failure> {
        Camera::from_arrays(self.position, self.target, self.up, self.fov_y_deg).map_err(refused)
    }
}

/// Kinds of `kage_light_desc`.
#[repr(u32)]
#[derive(Clone, Copy, strum::FromRepr)]
pub enum kage_light_kind {
    /// Radiant intensity in every direction.
    Point = 0,
    /// Radiant intensity inside a cone of full angle `fov_deg` about `direction`.
    Spot = 1,
}

/// A point or spot light, as a scene file's `lights` entry is (README, "Scene format").
#[repr(C)]
#[derive(Clone, Copy)]
pub struct kage_light_desc {
    /// A `kage_light_kind` value.
    pub kind: u32,
    pub position: [f32; 3],
    /// Spot lights: the cone's axis, any non-zero length (it is normalized). Point lights:
    /// unused.
    pub direction: [f32; 3],
    /// Spot lights: the cone's full angle in degrees, above 0 and at most 170. Point lights:
    /// unused.
    pub fov_deg: f32,
    /// Radiant intensity per channel (W/sr), at least 0.
    pub intensity: [f32; 3],
}

impl kage_light_desc {
    /// The light this desc describes, not yet validated (`Light::validated_as` does that, for
    /// every way a scene gets lights); `kind` names its field in the error.
    pub(crate) fn light(&self, kind: &str) -> Result<Light, Failure> {
        let (position, intensity) = (Vec3::from(self.position), self.intensity);
        Ok(match args::enumeration(self.kind, kind, kage_light_kind::from_repr)? {
            kage_light_kind::Point => Light::Point { position, intensity },
            kage_light_kind::Spot => {
                Light::Spot { position, direction: self.direction.into(), fov_deg: self.fov_deg, intensity }
            }
        })
    }
}

/// A whole scene from the host's memory, no files involved.
#[repr(C)]
pub struct kage_scene_desc {
    /// `sizeof(kage_scene_desc)` as the host's kage.h declares it: checked, so that a host built
    /// against another version of the header gets an error instead of a misread struct.
    pub size: u32,
    pub groups: *const kage_group_desc,
    pub group_count: u32,
    pub environment: kage_environment_desc,
    pub camera: kage_camera_desc,
    /// Point and spot lights (as `kage_renderer_set_light` takes them; NULL when `light_count`
    /// is 0), checked as a scene file's lights are. `KAGE_TECHNIQUE_SHADOW_MAP` and
    /// `KAGE_TECHNIQUE_ASM` light a scene by them, and need at least one.
    pub lights: *const kage_light_desc,
    pub light_count: u32,
}

/// Loads a scene: a path to a scene file (JSON, or glTF 2.0 .gltf/.glb or a Wavefront .obj read
/// alone; see the README), or the name of a built-in scene ("teapot", the default scene; an
/// unknown name's error lists the others). A path that exists or ends in ".json", ".gltf",
/// ".glb" or ".obj" (any case) is a file. A file that gives no environment (a .gltf/.glb or
/// .obj read alone, a scene file without "environment") is lit by a constant sky of radiance 1,
/// and nothing says so, so a host that takes such files tells its users (or gives the scene
/// file an environment). A model file read alone without a camera of its own is viewed whole
/// from the front; an OBJ is one group at rest with albedo 0.8 in each channel and no ground
/// added. Zero or non-finite normals in a file are recomputed from its triangles, with a note
/// on stderr.
///
/// On success `*scene` is a new handle that the host owns and frees with `kage_scene_destroy`;
/// on failure it is set to NULL, and a bad or missing file is `KAGE_RESULT_FILE`, with the file
/// and the problem in the message. Needs no context (no GPU work).
///
/// # Safety
/// `path` must be NULL or a NUL-terminated UTF-8 string; `scene` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_scene_load(path: *const c_char, scene: *mut *mut kage_scene) -> kage_result {
    boundary(|| {
        // SAFETY: the caller promises NULL or a writable pointer.
        let out = unsafe { args::handle_out(scene, "scene") }?;
        // SAFETY: the caller promises NULL or a NUL-terminated string.
        let path = unsafe { args::text(path, "path") }?;
        let scene = Scene::from_arg(path).map_err(crate::Error::from)?;
        *out = handles::register(kage_scene { scene, transfer: None });
        Ok(())
    })
}

/// Builds a scene from the host's arrays. Everything is copied during the call: the host may
/// free or reuse its arrays as soon as it returns.
///
/// Bad data is `KAGE_RESULT_INVALID_VALUE` naming the group and mesh: no groups or meshes,
/// NaN or infinite values (but a zero or non-finite normal is recomputed: see
/// `kage_mesh_desc`), indices out of range or not a multiple of 3, albedo outside [0, 1], a map
/// that is not 2:1, a degenerate camera or transform, a bad light (named `light N`, as in a
/// scene file). A NULL array with a non-zero count is `KAGE_RESULT_NULL_ARGUMENT`.
///
/// Counts beyond what Kage represents are `KAGE_RESULT_INVALID_VALUE` before anything is read
/// or allocated, the message naming the field, its value and the limit: a mesh's
/// `vertex_count` above 134217727 (32 bytes a vertex on the GPU, within 4 GiB), an
/// `index_count` (of a mesh, or of all meshes together) above 805306368 (268435456 triangles,
/// what the ray tracer numbers), a map beyond 16384x8192. Within them, memory the copies need
/// and the machine does not give is `KAGE_RESULT_OUT_OF_MEMORY`, never an abort.
///
/// On success `*scene` is a new handle that the host owns and frees with `kage_scene_destroy`;
/// on failure it is set to NULL.
///
/// # Safety
/// `desc` must be NULL or point to a `kage_scene_desc` whose arrays are NULL or hold the
/// counts it states; `scene` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_scene_create(
    desc: *const kage_scene_desc,
    scene: *mut *mut kage_scene,
) -> kage_result {
    boundary(|| {
        // SAFETY: the caller promises NULL or a writable pointer.
        let out = unsafe { args::handle_out(scene, "scene") }?;
        // SAFETY: the caller promises NULL or a valid desc with arrays as stated.
        let scene = unsafe { scene_from_desc(args::sized(desc, "desc")?) }?;
        *out = handles::register(kage_scene { scene, transfer: None });
        Ok(())
    })
}

/// # Safety
/// The arrays of `desc` must be NULL or hold the counts it states.
unsafe fn scene_from_desc(desc: &kage_scene_desc) -> Result<Scene, Failure> {
    // SAFETY: the caller promises `group_count` groups.
    let groups = unsafe { args::slice(desc.groups, desc.group_count as usize, "desc->groups") }?;
    if groups.is_empty() {
        return Err(Failure::invalid("the scene has no groups"));
    }
    // SAFETY: the caller promises valid mesh arrays in every group.
    unsafe { check_counts(groups) }?;
    let env = &desc.environment;
    EnvMap::check_size(env.width, env.height).map_err(|e| refused(e.within("desc->environment")))?;
    let mut built = host_memory::with_room(groups.len(), "desc->groups")?;
    for (at, g) in groups.iter().enumerate() {
        // SAFETY: the caller promises valid arrays in every group.
        built.push(unsafe { group(at, g) }?);
    }
    let texels = env.width as usize * env.height as usize;
    // SAFETY: the caller promises width × height RGB pixels.
    let pixels = unsafe { args::chunks::<3>(env.pixels, texels, "desc->environment.pixels") }?;
    let pixels = host_memory::collect(pixels.iter().copied(), "desc->environment.pixels")?;
    let environment = EnvMap::from_pixels(env.width, env.height, pixels).map_err(refused)?;
    let camera = desc.camera.camera()?;
    // SAFETY: the caller promises `light_count` lights.
    let descs = unsafe { args::slice(desc.lights, desc.light_count as usize, "desc->lights") }?;
    let mut lights = host_memory::with_room(descs.len(), "desc->lights")?;
    for (at, light) in descs.iter().enumerate() {
        lights.push(light.light(&format!("desc->lights[{at}].kind"))?.validated_as(at).map_err(refused)?);
    }
    let scene = Scene {
        name: "host".into(),
        groups: built,
        environment,
        lights,
        camera,
        walkthrough: Vec::new(),
        probes: Vec::new(),
        exposure: 1.0,
    };
    // The rules every scene meets (its extent among them): refused here, not when a renderer
    // is made from it.
    scene.validate().map_err(refused)?;
    Ok(scene)
}

/// Refuses vertex and index counts beyond the engine's limits, naming the field, before any
/// mesh is copied: the counts are the host's word, not arrays Kage has seen.
///
/// # Safety
/// The mesh arrays of `groups` must be NULL or hold the counts they state.
unsafe fn check_counts(groups: &[kage_group_desc]) -> Result<(), Failure> {
    let mut indices = 0;
    for (g, group) in groups.iter().enumerate() {
        // SAFETY: the caller promises `mesh_count` meshes.
        let meshes = unsafe { args::slice(group.meshes, group.mesh_count as usize, "group meshes") }?;
        for (m, mesh) in meshes.iter().enumerate() {
            let field = |name: &str| format!("desc->groups[{g}].meshes[{m}].{name}");
            check_vertex_count(mesh.vertex_count as usize)
                .map_err(|e| refused(e.within(&field("vertex_count"))))?;
            check_index_count(mesh.index_count as usize)
                .map_err(|e| refused(e.within(&field("index_count"))))?;
            indices += mesh.index_count as usize;
        }
    }
    check_index_count(indices).map_err(|e| refused(e.within("the index_count of all meshes together")))
}

/// # Safety
/// The arrays of `desc` must be NULL or hold the counts it states.
unsafe fn group(at: usize, desc: &kage_group_desc) -> Result<Group, Failure> {
    let name = match desc.name.is_null() {
        true => format!("group{at}"),
        // SAFETY: the caller promises a NUL-terminated string.
        false => unsafe { args::text(desc.name, "group name") }?.to_owned(),
    };
    let place = |e: SceneError| refused(e.within(&format!("group {at} (\"{name}\")")));
    let transform = desc.transform.validated().map_err(place)?;
    // SAFETY: the caller promises `mesh_count` meshes.
    let meshes = unsafe { args::slice(desc.meshes, desc.mesh_count as usize, "group meshes") }?;
    if meshes.is_empty() {
        return Err(place(SceneError::invalid("it has no meshes")));
    }
    let mut built = host_memory::with_room(meshes.len(), "group meshes")?;
    for (m, mesh) in meshes.iter().enumerate() {
        let vertices = mesh.vertex_count as usize;
        // SAFETY: the caller promises `vertex_count` positions (and normals, if any) and
        // `index_count` indices.
        let (positions, normals, indices) = unsafe {
            (
                args::chunks::<3>(mesh.positions, vertices, "mesh positions")?,
                match mesh.normals.is_null() {
                    true => None,
                    false => Some(args::chunks::<3>(mesh.normals, vertices, "mesh normals")?),
                },
                args::slice(mesh.indices, mesh.index_count as usize, "mesh indices")?,
            )
        };
        let copy = |field: &str| format!("desc->groups[{at}].meshes[{m}].{field}");
        let positions = host_memory::collect(positions.iter().copied(), &copy("positions"))?;
        let normals = match normals {
            Some(normals) => Some(host_memory::collect(normals.iter().copied(), &copy("normals"))?),
            None => None,
        };
        let indices = host_memory::collect(indices.iter().copied(), &copy("indices"))?;
        let made = Mesh::new(format!("mesh{m}"), positions, normals, indices, mesh.albedo);
        built.push(made.map_err(|e| place(e.within(&format!("mesh {m}"))))?);
    }
    Ok(Group::new(name, built, transform))
}

/// A scene error from data that came from no file: the host's values are at fault, or, where
/// the machine had no memory for them, `KAGE_RESULT_OUT_OF_MEMORY`.
fn refused(error: SceneError) -> Failure {
    crate::Error::from(error).into()
}

/// Destroys a scene handle. Renderers made from it keep what they need and stay usable. NULL is
/// allowed and does nothing. The handle must not be used after OK; on `KAGE_RESULT_BUSY` (a
/// call on another thread is using it) nothing was destroyed: call again once that call has
/// returned.
#[no_mangle]
pub extern "C" fn kage_scene_destroy(scene: *mut kage_scene) -> kage_result {
    boundary(|| handles::destroy(scene, "scene"))
}

/// The number of groups in the scene (the valid `group` indices of
/// `kage_renderer_set_group_transform` are 0 to count - 1).
///
/// # Safety
/// `scene` must be NULL or a handle; `count` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_scene_group_count(scene: *const kage_scene, count: *mut u32) -> kage_result {
    boundary(|| {
        let scene = handles::get(scene, "scene")?;
        // SAFETY: the caller promises NULL or writable.
        *unsafe { args::out(count, "count") }? = scene.scene.groups.len() as u32;
        Ok(())
    })
}

/// The number of point and spot lights in the scene (the valid `index` values of
/// `kage_renderer_set_light` are 0 to count - 1): `kage_scene_desc.light_count`, or a scene
/// file's lights.
///
/// # Safety
/// `scene` must be NULL or a handle; `count` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_scene_light_count(scene: *const kage_scene, count: *mut u32) -> kage_result {
    boundary(|| {
        let scene = handles::get(scene, "scene")?;
        // SAFETY: the caller promises NULL or writable.
        *unsafe { args::out(count, "count") }? = scene.scene.lights.len() as u32;
        Ok(())
    })
}
