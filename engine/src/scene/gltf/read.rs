//! Reading glTF 2.0 (`--scene FILE.gltf` or `FILE.glb`).
//!
//! What is read:
//! - the default scene (else the first). Its groups follow from what moves: each root node with
//!   meshes in its subtree is one rigid group (its transform, TRS or matrix with uniform scale,
//!   the group's; its descendants' transforms baked into their meshes' vertices, meshes without
//!   one read as stored), and so is every node an animation moves, wherever it sits, and every
//!   node a scene file's `gltf_groups` names: such a node is a group of its own with its subtree,
//!   placed in the world by its parents at every instant (a moving node inside a moving one
//!   composes both motions). Nodes without a name are named `node<index>` (`node3`), which
//!   `gltf_groups` takes too;
//! - triangle primitives: positions, normals (computed where absent), indices (0, 1, 2, … where
//!   absent); the material's baseColorFactor as albedo, and its baseColorTexture as the mesh's
//!   albedo map (`texture`: its coordinate set, sampler and KHR_texture_transform);
//! - the first perspective camera, or the one named (without one, a view of the whole scene,
//!   with a note);
//! - KHR_lights_punctual point and spot lights (colour × candela over 683 lm/W, Kage's radiant
//!   intensity; a spot's full cone is twice its outer cone angle);
//! - animations' translation, rotation and scale channels: each group's keyframes, its node's
//!   channels composed with its ancestors' (linear; step and cubic-spline sampled into linear
//!   keys, see `linear_track`; where an ancestor moves, 8 keys per interval, see [`motions`]),
//!   played once unless Kage's extras give a loop. The animation of a node that moves no mesh (a
//!   camera, a light, an empty node) is listed as unused.
//!
//! What is refused, by name: skins and morph targets (a rigid group cannot follow them: an error
//! naming the skin or primitive, not the rest pose), other primitive modes, orthographic
//! cameras, a group whose scale in the world is not uniform (at rest or at a key), data out of
//! its buffer.
//! What is not used (directional lights, morph weight channels, extensions, textures other than
//! the base colour, alpha) is listed in one note. glTF has no environment: the scene is lit by a constant
//! sky of radiance 1 (a note says so; `--env` or a scene file gives another).
use super::super::motion::{Key, Motion};
use super::super::{Camera, Group, Light, Mesh, SceneError, Transform};
use super::Extras;
use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};
use std::path::Path;

/// What a glTF file gives a scene: its groups, lights and camera (if it has one).
pub struct Parts {
    pub groups: Vec<Group>,
    pub lights: Vec<Light>,
    pub camera: Option<Camera>,
}

/// Reads the groups, lights and camera of the glTF file at `path`: the camera named `camera`
/// (a camera's or its node's name), else the first one; the nodes named in `groups` are groups
/// of their own (with their subtrees but for listed nodes in them), besides the roots.
pub fn parts(path: &Path, camera: Option<&str>, groups: &[String]) -> Result<Parts, SceneError> {
    // The gltf crate (1.4) panics on some malformed files inside its own checks (an index of
    // 2^32 - 1, a channel's unchecked target): contained here, such a file is an error like
    // any other (Rust's panic message is printed before it).
    std::panic::catch_unwind(|| read(path, camera, groups)).unwrap_or_else(|payload| {
        let text = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(SceneError::in_file(
            path,
            format!("a malformed glTF file, which the glTF reader failed on: {text}"),
        ))
    })
}

/// A node that is a group: its index and its ancestors, root first (none for a root).
struct GroupNode {
    node: usize,
    ancestors: Vec<usize>,
}

/// Whether any of the file's animations moves each node (a translation, rotation or scale
/// channel on it), read from the JSON so that a bad target is left for [`motions`] to name.
fn animated_nodes(document: &gltf::Document) -> Vec<bool> {
    use gltf::json::validation::Checked;
    let mut animated = vec![false; document.nodes().len()];
    for channel in document.as_json().animations.iter().flat_map(|a| &a.channels) {
        let moves = matches!(channel.target.path, Checked::Valid(p) if p != gltf::json::animation::Property::MorphTargetWeights);
        if let Some(node) = animated.get_mut(channel.target.node.value()).filter(|_| moves) {
            *node = true;
        }
    }
    animated
}

/// A node's name, or `node<index>` for a node without one (the name `gltf_groups` takes too).
fn node_name(node: &gltf::Node) -> String {
    node.name().map_or_else(|| format!("node{}", node.index()), str::to_string)
}

fn read(path: &Path, wanted_camera: Option<&str>, group_names: &[String]) -> Result<Parts, SceneError> {
    let fail = |problem: String| SceneError::in_file(path, problem);
    let super::import::Import { document, buffers, images } = super::import::import(path).map_err(fail)?;
    let mut unused: Vec<String> = document
        .extensions_used()
        .filter(|e| !["KHR_lights_punctual", "KHR_texture_transform"].contains(e))
        .map(|e| format!("extension {e}"))
        .collect();
    if let Some(skin) = document.skins().next() {
        return Err(fail(format!(
            "skin {} ({}): skinned meshes bend, and Kage moves rigid groups only",
            skin.index(),
            skin.name().unwrap_or("unnamed")
        )));
    }
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| fail("it holds no scene".into()))?;

    // The nodes that are groups besides the scene's roots: those that move, and those the
    // caller names.
    let mut listed = animated_nodes(&document);
    for name in group_names {
        let mut named = document.nodes().filter(|n| node_name(n) == *name);
        match (named.next(), named.next()) {
            (Some(node), None) => listed[node.index()] = true,
            (None, _) => return Err(fail(format!("gltf_groups: it has no node named \"{name}\""))),
            (Some(_), Some(_)) => {
                return Err(fail(format!("gltf_groups: several of its nodes are named \"{name}\"")))
            }
        }
    }

    let mut albedo_maps = super::texture::AlbedoMaps::new(&images);
    let mut groups = Vec::new();
    let mut camera = None;
    let mut camera_names = Vec::new();
    let mut lights = Vec::new();
    let mut group_nodes: Vec<GroupNode> = Vec::new();
    // glTF's nodes form trees: a node met twice (its own ancestor, or two parents) is refused.
    let mut seen = vec![false; document.nodes().len()];
    // Each node's parent on the walk: a group node's ancestors follow it up.
    let mut parent = vec![None; document.nodes().len()];
    // Group nodes to walk, with their parent's world matrix at rest: the scene's roots, then
    // each listed node met on the way.
    let mut queue: std::collections::VecDeque<_> = scene.nodes().map(|root| (root, Mat4::IDENTITY)).collect();
    while let Some((top, parent_world)) = queue.pop_front() {
        let top_matrix = parent_world * Mat4::from_cols_array_2d(&top.transform().matrix());
        let mut meshes = Vec::new();
        let mut stack = vec![(top.clone(), Mat4::IDENTITY)];
        while let Some((node, relative)) = stack.pop() {
            if std::mem::replace(&mut seen[node.index()], true) {
                return Err(fail(format!("node {} is met twice: nodes must form trees", node.index())));
            }
            let world = top_matrix * relative;
            if let Some(mesh) = node.mesh() {
                if mesh.primitives().len() == 0 {
                    // glTF requires one; dropping the node's geometry unsaid would hide it.
                    return Err(fail(format!(
                        "mesh {} (\"{}\"): it has no primitives",
                        mesh.index(),
                        crate::scene::clip(mesh.name().unwrap_or(""))
                    )));
                }
                for (p, primitive) in mesh.primitives().enumerate() {
                    let at = |problem: String| {
                        fail(format!(
                            "mesh {} (\"{}\") primitive {p}: {problem}",
                            mesh.index(),
                            crate::scene::clip(mesh.name().unwrap_or(""))
                        ))
                    };
                    meshes.push(
                        primitive_mesh(
                            &primitive,
                            &mesh,
                            p,
                            relative,
                            &buffers,
                            &mut albedo_maps,
                            &mut unused,
                        )
                        .map_err(at)?,
                    );
                }
            }
            if let Some(c) = node.camera() {
                let names = [c.name(), node.name()];
                camera_names.extend(names.iter().flatten().map(|n| format!("\"{n}\"")));
                let wanted = wanted_camera.is_none_or(|w| names.contains(&Some(w)));
                if camera.is_none() && wanted {
                    let read = camera_of(&c, &node, world)
                        .map_err(|e| fail(format!("camera {}: {e}", c.index())))?;
                    camera = Some(read);
                }
            }
            if let Some(light) = node.light() {
                match light_of(&light, &node, world) {
                    Some(l) => lights.push(l.map_err(|e| fail(format!("light {}: {e}", light.index())))?),
                    None => unused.push(format!("directional light {}", light.index())),
                }
            }
            // Pushed last to first: the meshes come in the file's order (depth first). A listed
            // child is a group of its own, walked after this one.
            let children: Vec<_> = node.children().collect();
            for child in children.into_iter().rev() {
                parent[child.index()] = Some(node.index());
                if listed[child.index()] {
                    queue.push_back((child, world));
                } else {
                    let local = Mat4::from_cols_array_2d(&child.transform().matrix());
                    stack.push((child, relative * local));
                }
            }
        }
        if meshes.is_empty() {
            continue;
        }
        let uniform = |scale: Vec3| {
            uniform_scale(scale).ok_or_else(|| {
                fail(format!("node {}: scale {scale} is not uniform (a group scales uniformly)", top.index()))
            })
        };
        // Read from the TRS as written where it is one (no round trip through a matrix).
        let (scale, rotation, translation) = rest_pose(&top);
        let transform = if parent_world == Mat4::IDENTITY {
            Transform { translation, rotation, scale: uniform(scale)? }
        } else {
            let (scale, rotation, translation) = top_matrix.to_scale_rotation_translation();
            Transform { translation, rotation, scale: uniform(scale)? }
        };
        groups.push(Group::new(node_name(&top), meshes, transform));
        let ancestors = std::iter::successors(parent[top.index()], |&a| parent[a]).collect::<Vec<_>>();
        group_nodes.push(GroupNode { node: top.index(), ancestors: ancestors.into_iter().rev().collect() });
    }
    if let Some(name) =
        group_names.iter().find(|name| document.nodes().any(|n| node_name(&n) == **name && !seen[n.index()]))
    {
        return Err(fail(format!("gltf_groups: node \"{name}\" is not in its scene")));
    }
    if groups.is_empty() {
        return Err(fail("its scene has no meshes".into()));
    }
    if let (Some(wanted), None) = (wanted_camera, &camera) {
        let names = if camera_names.is_empty() { "none".to_string() } else { camera_names.join(", ") };
        return Err(fail(format!(
            "it has no camera named \"{wanted}\" (its cameras and their nodes: {names})"
        )));
    }
    motions(&document, &buffers, &group_nodes, &mut groups, &mut unused).map_err(fail)?;
    if !unused.is_empty() {
        unused.sort();
        unused.dedup();
        eprintln!("kage: note: {}: not used by Kage: {}", path.display(), unused.join(", "));
    }
    Ok(Parts { groups, lights, camera })
}

/// One triangle primitive as a mesh, its vertices placed by `relative` (within its group).
fn primitive_mesh(
    primitive: &gltf::Primitive,
    mesh: &gltf::Mesh,
    p: usize,
    relative: Mat4,
    buffers: &[gltf::buffer::Data],
    albedo_maps: &mut super::texture::AlbedoMaps,
    unused: &mut Vec<String>,
) -> Result<Mesh, String> {
    if primitive.mode() != gltf::mesh::Mode::Triangles {
        return Err(format!("mode {:?}: Kage reads triangles", primitive.mode()));
    }
    if primitive.morph_targets().next().is_some() {
        return Err("morph targets: a rigid group cannot follow them".into());
    }
    if let Some(indices) = primitive.indices() {
        use gltf::accessor::DataType;
        if !matches!(indices.data_type(), DataType::U8 | DataType::U16 | DataType::U32) {
            return Err(format!(
                "indices of component type {:?}: they must be unsigned integers",
                indices.data_type()
            ));
        }
    }
    // The crate reads POSITION and NORMAL as float triples whatever the accessor declares.
    for semantic in [gltf::Semantic::Positions, gltf::Semantic::Normals] {
        use gltf::accessor::{DataType, Dimensions};
        if let Some(accessor) = primitive.get(&semantic) {
            if (accessor.data_type(), accessor.dimensions()) != (DataType::F32, Dimensions::Vec3) {
                return Err(format!(
                    "its {} accessor {} holds {:?} of component type {:?}: glTF's are VEC3 of FLOAT (5126)",
                    semantic.to_string(),
                    accessor.index(),
                    accessor.dimensions(),
                    accessor.data_type()
                ));
            }
        }
    }
    let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions = reader.read_positions().ok_or("positions missing, or beyond their buffer")?;
    let normals = reader.read_normals();
    // A mesh on a group's root node (or a child without a transform) is read as stored, bit for
    // bit; one further down has its place within the group baked in.
    let (positions, normals): (Vec<[f32; 3]>, Option<Vec<[f32; 3]>>) = if relative == Mat4::IDENTITY {
        (positions.collect(), normals.map(Iterator::collect))
    } else {
        let normal_matrix = glam::Mat3::from_mat4(relative).inverse().transpose();
        (
            positions.map(|p| relative.transform_point3(Vec3::from(p)).to_array()).collect(),
            normals
                .map(|n| n.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero().to_array()).collect()),
        )
    };
    let mut indices: Vec<u32> = match reader.read_indices() {
        Some(indices) => indices.into_u32().collect(),
        None if primitive.get(&gltf::Semantic::Positions).is_some_and(|a| a.count() == positions.len()) => {
            (0..positions.len() as u32).collect()
        }
        None => return Err("indices beyond their buffer".into()),
    };
    if primitive.indices().is_some_and(|a| a.count() != indices.len()) {
        return Err("indices beyond their buffer".into());
    }
    // A mirroring transform turns the triangles inside out: keep them counter-clockwise.
    if relative.determinant() < 0.0 {
        indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
    }
    let material = primitive.material();
    let [r, g, b, _] = material.pbr_metallic_roughness().base_color_factor();
    // Albedo outside [0, 1] is an error, as in a scene file: a surface reflects no more than
    // arrives, and clamping would hide a unit mistake.
    if ![r, g, b].iter().all(|c| (0.0..=1.0).contains(c)) {
        let material = match (material.index(), material.name()) {
            (Some(i), Some(name)) => format!("material {i} (\"{}\")", crate::scene::clip(name)),
            (Some(i), None) => format!("material {i}"),
            (None, _) => "the default material".into(),
        };
        return Err(format!("{material}: baseColorFactor {:?} is outside [0, 1]", [r, g, b]));
    }
    let albedo = [r, g, b];
    let texturing = albedo_maps.texturing(
        primitive,
        |set| reader.read_tex_coords(set).map(|c| c.into_f32().collect()),
        positions.len(),
    )?;
    if material.normal_texture().is_some()
        || material.occlusion_texture().is_some()
        || material.emissive_texture().is_some()
    {
        unused.push("normal, occlusion and emissive textures".into());
    }
    if material.alpha_mode() != gltf::material::AlphaMode::Opaque {
        unused.push("alpha (every surface is opaque)".into());
    }
    let mesh_name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
    let name = if mesh.primitives().len() == 1 { mesh_name } else { format!("{mesh_name}.{p}") };
    match texturing {
        Some(t) => Mesh::new_textured(name, positions, normals, indices, albedo, t),
        None => Mesh::new(name, positions, normals, indices, albedo),
    }
    .map_err(|e| e.to_string())
}

/// A perspective camera on `node` (placed by `world`); Kage's own look-at where its extras hold
/// one that agrees (a target and up vector glTF has no place for).
fn camera_of(camera: &gltf::Camera, node: &gltf::Node, world: Mat4) -> Result<Camera, String> {
    let gltf::camera::Projection::Perspective(perspective) = camera.projection() else {
        return Err("orthographic: Kage renders perspective views".into());
    };
    let position = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    let read = Camera::from_arrays(
        position.to_array(),
        (position + forward).to_array(),
        up.to_array(),
        perspective.yfov().to_degrees(),
    )
    .map_err(|e| e.to_string())?;
    let exact = Extras::of(node.extras()).camera.and_then(|c| super::super::load::camera(&c).ok());
    Ok(exact.filter(|exact| agrees(&camera_frame(exact), &camera_frame(&read))).unwrap_or(read))
}

/// A camera's position, viewing direction, up direction (square to it) and field of view.
fn camera_frame(camera: &Camera) -> [f32; 10] {
    let forward = (camera.target - camera.position).normalize();
    let up = forward.cross(camera.up).cross(forward).normalize();
    let [a, b, c] = camera.position.to_array();
    let ([d, e, f], [g, h, i]) = (forward.to_array(), up.to_array());
    [a, b, c, d, e, f, g, h, i, camera.fov_y_deg.to_radians()]
}

/// Whether Kage's values and the glTF ones read beside them are the same up to f32 rounding
/// in glTF's form (a quaternion, radians, colour × intensity): 1e-5 relative to their size.
fn agrees(exact: &[f32], read: &[f32]) -> bool {
    exact.iter().zip(read).all(|(a, b)| (a - b).abs() <= 1e-5 * a.abs().max(b.abs()).max(1.0))
}

/// A point or spot light on `node` (placed by `world`), Kage's own where its extras hold one
/// that agrees; `None` for a directional one.
fn light_of(
    light: &gltf::khr_lights_punctual::Light,
    node: &gltf::Node,
    world: Mat4,
) -> Option<Result<Light, String>> {
    let position = world.transform_point3(Vec3::ZERO);
    let watts_per_sr = light.intensity() / super::LUMENS_PER_WATT;
    let intensity = light.color().map(|c| c * watts_per_sr);
    let read = match light.kind() {
        gltf::khr_lights_punctual::Kind::Point => Light::Point { position, intensity },
        gltf::khr_lights_punctual::Kind::Spot { outer_cone_angle, .. } => Light::Spot {
            position,
            direction: world.transform_vector3(Vec3::NEG_Z),
            fov_deg: 2.0 * outer_cone_angle.to_degrees(),
            intensity,
        },
        gltf::khr_lights_punctual::Kind::Directional => return None,
    };
    let read = match read.validated() {
        Ok(read) => read,
        Err(e) => return Some(Err(e.to_string())),
    };
    let exact =
        Extras::of(node.extras()).light.and_then(|desc| super::super::load::light(desc).validated().ok());
    let numbers = |light: &Light| match *light {
        Light::Point { position, intensity } => [position.to_array(), intensity, [0.0; 3], [0.0; 3]].concat(),
        Light::Spot { position, direction, fov_deg, intensity } => {
            [position.to_array(), intensity, direction.to_array(), [fov_deg.to_radians(), 1.0, 1.0]].concat()
        }
    };
    let same_kind = |exact: &Light| std::mem::discriminant(exact) == std::mem::discriminant(&read);
    Some(Ok(exact
        .filter(|exact| same_kind(exact) && agrees(&numbers(exact), &numbers(&read)))
        .unwrap_or(read)))
}

/// A camera that sees every group wherever its motion takes it (its box at rest and at each of
/// its keys): from the front (+Z) and a little above, far enough that the sphere around their
/// box fits the vertical field of view (and the horizontal one of any picture at least as wide
/// as tall).
pub fn overview(groups: &[Group]) -> Camera {
    let (lo, hi) = groups
        .iter()
        .flat_map(|g| {
            let points = g.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
            let (lo, hi) =
                points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
            let corners = (0..8)
                .map(move |c| Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo));
            let keys = g.motion.iter().flat_map(|m| m.keys.iter().map(|k| k.transform()));
            let poses: Vec<Mat4> = std::iter::once(g.transform).chain(keys).map(|t| t.matrix()).collect();
            let corners: Vec<Vec3> = if lo.cmple(hi).all() { corners.collect() } else { Vec::new() };
            poses
                .into_iter()
                .flat_map(move |m| corners.clone().into_iter().map(move |c| m.transform_point3(c)))
        })
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let fov_y_deg: f32 = 40.0;
    let distance = radius / (0.5 * fov_y_deg.to_radians()).sin();
    Camera {
        position: centre + Vec3::new(0.0, 0.2, 1.0).normalize() * distance,
        target: centre,
        up: Vec3::Y,
        fov_y_deg,
    }
}

/// A channel's keys: their times and values.
type Track<T> = Option<(Vec<f32>, Vec<T>)>;

/// What the animations do to one node: its translation, rotation and scale channels (each
/// sampled into linear keys) and the loop Kage's extras give their animation.
#[derive(Clone, Default)]
struct NodeTracks {
    translation: Track<Vec3>,
    rotation: Track<Quat>,
    scale: Track<Vec3>,
    loop_seconds: Option<f32>,
}

impl NodeTracks {
    fn moves(&self) -> bool {
        self.translation.is_some() || self.rotation.is_some() || self.scale.is_some()
    }

    fn times(&self) -> impl Iterator<Item = f32> + '_ {
        let times = [self.translation.as_ref().map(|t| &t.0), self.rotation.as_ref().map(|t| &t.0)];
        times.into_iter().chain([self.scale.as_ref().map(|t| &t.0)]).flatten().flatten().copied()
    }

    /// The node's scale, rotation and translation in its parent at `time`: its channels'
    /// values, its rest pose `rest` where it has none.
    fn at(&self, time: f32, rest: (Vec3, Quat, Vec3)) -> (Vec3, Quat, Vec3) {
        (
            self.scale.as_ref().map_or(rest.0, |(t, v)| sample(t, v, time, Vec3::lerp)),
            self.rotation.as_ref().map_or(rest.1, |(t, v)| sample(t, v, time, Quat::slerp)),
            self.translation.as_ref().map_or(rest.2, |(t, v)| sample(t, v, time, Vec3::lerp)),
        )
    }
}

/// The animations' channels as the groups' keyframes. A group's pose at every instant is its
/// node's animated TRS placed by its ancestors' at that instant (hierarchical animation
/// composed): keys at every key time of the node and of its ancestors, with `SPLINE_STEPS`
/// keys per interval where an ancestor moves (a parent's turn carries its child along an arc,
/// which linear keys follow only in steps).
fn motions(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    group_nodes: &[GroupNode],
    groups: &mut [Group],
    unused: &mut Vec<String>,
) -> Result<(), String> {
    let mut tracks = vec![NodeTracks::default(); document.nodes().len()];
    for animation in document.animations() {
        let loop_seconds = Extras::of(animation.extras()).loop_seconds;
        for (c, channel) in animation.channels().enumerate() {
            let at = |problem: String| format!("animation {} channel {c}: {problem}", animation.index());
            // The crate leaves a channel's target unchecked (and panics on reading a bad one).
            let raw = &document.as_json().animations[animation.index()].channels[c].target;
            if raw.path == gltf::json::validation::Checked::Invalid {
                return Err(at("its target path is none of translation, rotation, scale, weights".into()));
            }
            if raw.node.value() >= document.nodes().len() {
                return Err(at(format!("its target node {} does not exist", raw.node.value())));
            }
            if channel.target().property() == Property::MorphTargetWeights {
                unused.push("morph target weight channels".into());
                continue;
            }
            let node = &mut tracks[channel.target().node().index()];
            node.loop_seconds = node.loop_seconds.or(loop_seconds);
            let interpolation = channel.sampler().interpolation();
            let reader = channel.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let times: Vec<f32> =
                reader.read_inputs().ok_or_else(|| at("times beyond their buffer".into()))?.collect();
            match reader.read_outputs().ok_or_else(|| at("values beyond their buffer".into()))? {
                ReadOutputs::Translations(values) => {
                    let values: Vec<Vec3> = values.map(Vec3::from).collect();
                    node.translation = Some(linear_track(&times, &values, interpolation, |v| v).map_err(at)?);
                }
                ReadOutputs::Rotations(values) => {
                    let values: Vec<Vec4> = values.into_f32().map(Vec4::from_array).collect();
                    let track = linear_track(&times, &values, interpolation, Vec4::normalize).map_err(at)?;
                    node.rotation = Some((track.0, track.1.into_iter().map(Quat::from_vec4).collect()));
                }
                ReadOutputs::Scales(values) => {
                    let values: Vec<Vec3> = values.map(Vec3::from).collect();
                    node.scale = Some(linear_track(&times, &values, interpolation, |v| v).map_err(at)?);
                }
                ReadOutputs::MorphTargetWeights(_) => unreachable!("weights are skipped above"),
            }
        }
    }
    // Moving nodes that move no group (a camera, a light, an empty node): their motion is lost.
    let mut used = vec![false; tracks.len()];
    for group_node in group_nodes {
        used[group_node.node] = true;
        group_node.ancestors.iter().for_each(|&a| used[a] = true);
    }
    for (n, _) in tracks.iter().enumerate().filter(|(n, t)| t.moves() && !used[*n]) {
        unused.push(format!("the animation of node {n}, which moves no mesh"));
    }
    let rest: Vec<(Vec3, Quat, Vec3)> = document.nodes().map(|node| rest_pose(&node)).collect();
    let matrices: Vec<Mat4> =
        document.nodes().map(|n| Mat4::from_cols_array_2d(&n.transform().matrix())).collect();
    for (group, group_node) in groups.iter_mut().zip(group_nodes) {
        let chain = || group_node.ancestors.iter().chain([&group_node.node]).map(|&n| (n, &tracks[n]));
        if !chain().any(|(_, t)| t.moves()) {
            continue;
        }
        let mut times: Vec<f32> = chain().flat_map(|(_, t)| t.times()).collect();
        times.sort_by(f32::total_cmp);
        times.dedup();
        if group_node.ancestors.iter().any(|&a| tracks[a].moves()) {
            let steps = times.windows(2).flat_map(|w| {
                (1..SPLINE_STEPS).map(move |j| w[0] + (w[1] - w[0]) * j as f32 / SPLINE_STEPS as f32)
            });
            times = times.iter().copied().chain(steps.collect::<Vec<_>>()).collect();
            times.sort_by(f32::total_cmp);
        }
        let keys = times
            .iter()
            .map(|&time| {
                // Static ancestors by their matrices as written, moving ones at this instant.
                let parent_world = group_node.ancestors.iter().fold(Mat4::IDENTITY, |world, &a| {
                    let local = if tracks[a].moves() {
                        let (scale, rotation, translation) = tracks[a].at(time, rest[a]);
                        Mat4::from_scale_rotation_translation(scale, rotation, translation)
                    } else {
                        matrices[a]
                    };
                    world * local
                });
                let (scale, rotation, translation) = tracks[group_node.node].at(time, rest[group_node.node]);
                in_world(time, scale, rotation, translation, parent_world)
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| format!("group \"{}\": {e}", group.name))?;
        let loop_seconds = chain().rev().find_map(|(_, t)| t.loop_seconds);
        let mut keys = keys;
        // A looping motion's last key at its loop length, where it repeats the first key at 0
        // (as Kage writes it, for players that loop over the animation's length), is the first.
        let (first, last) = (keys[0], keys[keys.len() - 1]);
        let closing = |p: f32| {
            keys.len() > 1 && first.time == 0.0 && last.time == p && {
                let (a, b) = (Key { time: 0.0, ..last }, first);
                a == b
            }
        };
        if loop_seconds.is_some_and(closing) {
            keys.pop();
        }
        let motion = Motion { keys, loop_seconds };
        motion.validate().map_err(|e| format!("group \"{}\": {e}", group.name))?;
        group.motion = Some(motion);
    }
    Ok(())
}

/// A node's scale, rotation and translation at rest: its TRS as written, or its matrix's.
fn rest_pose(node: &gltf::Node) -> (Vec3, Quat, Vec3) {
    match node.transform() {
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            (Vec3::from(scale), Quat::from_array(rotation), Vec3::from(translation))
        }
        gltf::scene::Transform::Matrix { matrix } => {
            Mat4::from_cols_array_2d(&matrix).to_scale_rotation_translation()
        }
    }
}

/// A node's TRS in its parent at `time` as the group's key in the world: the TRS itself for a
/// root (read as written), else placed by its parent's world matrix; uniformly scaled either way.
fn in_world(
    time: f32,
    scale: Vec3,
    rotation: Quat,
    translation: Vec3,
    parent_world: Mat4,
) -> Result<Key, String> {
    let (scale, rotation, translation) = if parent_world == Mat4::IDENTITY {
        (scale, rotation, translation)
    } else {
        (parent_world * Mat4::from_scale_rotation_translation(scale, rotation, translation))
            .to_scale_rotation_translation()
    };
    let scale = uniform_scale(scale).ok_or_else(|| {
        format!("at {time} s its scale in the world, {scale}, is not uniform (a group scales uniformly)")
    })?;
    Ok(Key { time, translation, rotation, scale })
}

/// A scale's one factor where it is uniform (the same along every axis to 1e-4 of it): Kage's
/// groups scale uniformly.
fn uniform_scale(scale: Vec3) -> Option<f32> {
    let spread = (scale.max_element() - scale.min_element()).abs();
    (spread <= 1e-4 * scale.max_element().abs()).then_some(scale.x)
}

/// Sub-steps per key interval of a cubic-spline channel, sampled into linear keys: the spline's
/// deviation from its chords falls with their square (1/64 of one chord's).
const SPLINE_STEPS: usize = 8;

/// A channel's keys as keys to interpolate linearly between: linear as they are; step as each
/// value held until a ten-thousandth of its interval before the next key; cubic spline (values
/// with in- and out-tangents, glTF's Hermite form) sampled `SPLINE_STEPS` times per interval.
/// `normalize` maps each sampled value (rotations back to unit length).
fn linear_track<T>(
    times: &[f32],
    values: &[T],
    interpolation: Interpolation,
    normalize: impl Fn(T) -> T,
) -> Result<(Vec<f32>, Vec<T>), String>
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Mul<f32, Output = T>,
{
    let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
    if times.is_empty() || values.len() != per_key * times.len() {
        return Err(format!(
            "{} values for {} times ({interpolation:?} sampling)",
            values.len(),
            times.len()
        ));
    }
    if !times.iter().all(|t| t.is_finite()) || times.windows(2).any(|w| w[0] >= w[1]) {
        return Err("its times are not finite and increasing".into());
    }
    let (mut out_times, mut out_values) = (Vec::new(), Vec::new());
    let n = times.len();
    match interpolation {
        Interpolation::Linear => return Ok((times.to_vec(), values.to_vec())),
        Interpolation::Step => {
            for k in 0..n {
                out_times.push(times[k]);
                out_values.push(values[k]);
                if k + 1 < n {
                    out_times.push(times[k + 1] - 1e-4 * (times[k + 1] - times[k]));
                    out_values.push(values[k]);
                }
            }
        }
        Interpolation::CubicSpline => {
            // values: [in-tangent, value, out-tangent] per key.
            let (value, out_tangent, in_tangent) =
                (|k: usize| values[3 * k + 1], |k: usize| values[3 * k + 2], |k: usize| values[3 * k]);
            for k in 0..n {
                out_times.push(times[k]);
                out_values.push(normalize(value(k)));
                if k + 1 == n {
                    break;
                }
                let span = times[k + 1] - times[k];
                for j in 1..SPLINE_STEPS {
                    let s = j as f32 / SPLINE_STEPS as f32;
                    let (s2, s3) = (s * s, s * s * s);
                    let point = value(k) * (2.0 * s3 - 3.0 * s2 + 1.0)
                        + out_tangent(k) * (span * (s3 - 2.0 * s2 + s))
                        + value(k + 1) * (-2.0 * s3 + 3.0 * s2)
                        + in_tangent(k + 1) * (span * (s3 - s2));
                    out_times.push(times[k] + s * span);
                    out_values.push(normalize(point));
                }
            }
        }
    }
    Ok((out_times, out_values))
}

/// A channel's value at `time`: its key's exactly at a key's time, interpolated between keys,
/// held beyond them.
fn sample<T: Copy>(times: &[f32], values: &[T], time: f32, mix: impl Fn(T, T, f32) -> T) -> T {
    let k = times.partition_point(|&t| t <= time);
    match k {
        0 => values[0],
        k if k == times.len() || times[k - 1] == time => values[k - 1],
        k => {
            let s = (time - times[k - 1]) / (times[k] - times[k - 1]);
            mix(values[k - 1], values[k], s)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_and_cubic_spline_channels_become_linear_keys() {
        let times = [0.0, 1.0];
        let (t, v) = linear_track(&times, &[0.0f32, 4.0], Interpolation::Step, |v| v).unwrap();
        assert_eq!((t, v), (vec![0.0, 0.9999, 1.0], vec![0.0, 0.0, 4.0]));
        // Zero tangents: the Hermite curve is a smoothstep, 3s² - 2s³ of the way.
        let spline = [9.0f32, 0.0, 0.0, 0.0, 4.0, 9.0];
        let (t, v) = linear_track(&times, &spline, Interpolation::CubicSpline, |v| v).unwrap();
        assert_eq!(t.len(), SPLINE_STEPS + 1);
        assert_eq!((t[2], v[2]), (0.25, 4.0 * 0.15625));
        assert_eq!((t[4], v[4]), (0.5, 2.0));
        assert_eq!(v[SPLINE_STEPS], 4.0);
        let short = linear_track(&times, &[1.0f32, 2.0], Interpolation::CubicSpline, |v| v).unwrap_err();
        assert!(short.contains("2 values for 2 times"), "{short}");
        let backwards = linear_track(&[1.0, 0.0], &[1.0f32, 2.0], Interpolation::Linear, |v| v).unwrap_err();
        assert!(backwards.contains("increasing"), "{backwards}");
    }
}
