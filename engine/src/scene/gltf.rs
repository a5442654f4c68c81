//! glTF 2.0 scenes (`--scene FILE.gltf` or `FILE.glb`), read through the `gltf` crate.
//!
//! What is read:
//! - the default scene (else the first); each root node with meshes in its subtree becomes one
//!   rigid group: its transform (TRS or matrix, uniform scale) the group's, its descendants'
//!   transforms baked into their meshes' vertices;
//! - triangle primitives: positions, normals (computed where absent), indices (0, 1, 2, … where
//!   absent); the material's baseColorFactor as albedo, times the mean of its baseColorTexture
//!   (sRGB decoded) where it has one, with a note: Kage shades each mesh with one diffuse colour;
//! - the first perspective camera (without one, a view of the whole scene, with a note);
//! - KHR_lights_punctual point and spot lights (colour × intensity, read as Kage's radiant
//!   intensity; a spot's full cone is twice its outer cone angle);
//! - animations' translation and rotation channels on root nodes: the groups' keyframes (linear;
//!   step and cubic-spline sampled into linear keys, see `linear_track`).
//!
//! What is refused, by name: skins and morph targets (a rigid group cannot follow them), other
//! primitive modes, animation channels on nodes inside a group, orthographic cameras, non-uniform scale on a root node, data out of its buffer.
//! What is not used (directional lights, scale channels, extensions, textures other than the
//! base colour) is listed in one note. glTF has no environment: the scene is lit by a constant
//! sky of radiance 1 (a note says so; `--env` or a scene file gives another).
use super::motion::{Key, Motion};
use super::{Camera, EnvMap, Group, Light, Mesh, Scene, SceneError, Transform};
use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};
use std::path::Path;

/// Reads the glTF file at `path`; every error names the file, and the element at fault.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    // The gltf crate (1.4) panics on some malformed files inside its own checks (an index of
    // 2^32 - 1, a channel's unchecked target): contained here, such a file is an error like
    // any other (Rust's panic message is printed before it).
    std::panic::catch_unwind(|| read(path)).unwrap_or_else(|payload| {
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

fn read(path: &Path) -> Result<Scene, SceneError> {
    let fail = |problem: String| SceneError::in_file(path, problem);
    let (document, buffers, images) =
        gltf::import(path).map_err(|e| fail(format!("not a glTF 2.0 file Kage can read: {e}")))?;
    let mut unused: Vec<String> = document
        .extensions_used()
        .filter(|e| *e != "KHR_lights_punctual")
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

    let mut groups = Vec::new();
    let mut camera = None;
    let mut lights = Vec::new();
    let mut root_of_group = Vec::new();
    // glTF's nodes form trees: a node met twice (its own ancestor, or two parents) is refused.
    let mut seen = vec![false; document.nodes().len()];
    for root in scene.nodes() {
        let root_matrix = Mat4::from_cols_array_2d(&root.transform().matrix());
        let mut meshes = Vec::new();
        let mut stack = vec![(root.clone(), Mat4::IDENTITY)];
        while let Some((node, relative)) = stack.pop() {
            if std::mem::replace(&mut seen[node.index()], true) {
                return Err(fail(format!("node {} is met twice: nodes must form trees", node.index())));
            }
            let world = root_matrix * relative;
            if let Some(mesh) = node.mesh() {
                for (p, primitive) in mesh.primitives().enumerate() {
                    let at = |problem: String| {
                        fail(format!(
                            "mesh {} (\"{}\") primitive {p}: {problem}",
                            mesh.index(),
                            mesh.name().unwrap_or("")
                        ))
                    };
                    meshes.push(
                        primitive_mesh(&primitive, &mesh, p, relative, &buffers, &images, &mut unused)
                            .map_err(at)?,
                    );
                }
            }
            if let (None, Some(c)) = (&camera, node.camera()) {
                camera = Some(camera_of(&c, world).map_err(|e| fail(format!("camera {}: {e}", c.index())))?);
            }
            if let Some(light) = node.light() {
                match light_of(&light, world) {
                    Some(l) => lights.push(l),
                    None => unused.push(format!("directional light {}", light.index())),
                }
            }
            for child in node.children() {
                let local = Mat4::from_cols_array_2d(&child.transform().matrix());
                stack.push((child, relative * local));
            }
        }
        if meshes.is_empty() {
            continue;
        }
        let (scale, rotation, translation) = root_matrix.to_scale_rotation_translation();
        if (scale.max_element() - scale.min_element()).abs() > 1e-4 * scale.max_element().abs() {
            return Err(fail(format!(
                "node {}: scale {scale} is not uniform (a group scales uniformly)",
                root.index()
            )));
        }
        let name = root.name().map_or_else(|| format!("node {}", root.index()), str::to_string);
        let transform = Transform { translation, rotation, scale: scale.x };
        groups.push(Group { name, meshes, transform, motion: None });
        root_of_group.push(root.index());
    }
    if groups.is_empty() {
        return Err(fail("its scene has no meshes".into()));
    }
    motions(&document, &buffers, &root_of_group, &mut groups, &mut unused).map_err(fail)?;

    let name = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let file = path.display();
    let camera = match camera {
        Some(camera) => camera,
        None => {
            eprintln!("kage: note: {file} has no camera: viewing the whole scene from the front");
            overview(&groups)
        }
    };
    eprintln!("kage: note: {file} has no environment: lit by a constant sky of radiance 1 (give one with --env or a scene file)");
    if !unused.is_empty() {
        unused.sort();
        unused.dedup();
        eprintln!("kage: note: {file}: not used by Kage: {}", unused.join(", "));
    }
    let scene = Scene {
        name,
        groups,
        environment: EnvMap::constant([1.0; 3]),
        lights,
        camera,
        walkthrough: Vec::new(),
        probes: Vec::new(),
        exposure: 1.0,
    };
    scene.validate().map_err(|e| e.attributed_to(path))?;
    Ok(scene)
}

/// One triangle primitive as a mesh, its vertices placed by `relative` (within its group).
fn primitive_mesh(
    primitive: &gltf::Primitive,
    mesh: &gltf::Mesh,
    p: usize,
    relative: Mat4,
    buffers: &[gltf::buffer::Data],
    images: &[gltf::image::Data],
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
    let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let positions: Vec<[f32; 3]> = reader
        .read_positions()
        .ok_or("positions missing, or beyond their buffer")?
        .map(|p| relative.transform_point3(Vec3::from(p)).to_array())
        .collect();
    let normal_matrix = glam::Mat3::from_mat4(relative).inverse().transpose();
    let normals = reader
        .read_normals()
        .map(|n| n.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero().to_array()).collect());
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
    let pbr = primitive.material().pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let mut albedo = [r, g, b];
    if let Some(info) = pbr.base_color_texture() {
        let image = images.get(info.texture().source().index()).ok_or("its base colour image is missing")?;
        let mean = mean_colour(image).ok_or("its base colour image has a format Kage cannot average")?;
        albedo = [albedo[0] * mean[0], albedo[1] * mean[1], albedo[2] * mean[2]];
        eprintln!(
            "kage: note: mesh {} primitive {p}: its base colour texture is replaced by its mean colour (Kage shades a mesh with one albedo)",
            mesh.index()
        );
    }
    let material = primitive.material();
    if material.normal_texture().is_some()
        || material.occlusion_texture().is_some()
        || material.emissive_texture().is_some()
    {
        unused.push("normal, occlusion and emissive textures".into());
    }
    let name =
        format!("{}.{p}", mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string));
    Mesh::new(name, positions, normals, indices, albedo.map(|c| c.clamp(0.0, 1.0))).map_err(|e| e.to_string())
}

/// The mean linear colour of an 8-bit sRGB image (RGB or RGBA).
fn mean_colour(image: &gltf::image::Data) -> Option<[f32; 3]> {
    let channels = match image.format {
        gltf::image::Format::R8G8B8 => 3,
        gltf::image::Format::R8G8B8A8 => 4,
        _ => return None,
    };
    let linear = |c: u8| crate::imageio::srgb_eotf(c as f32 / 255.0);
    let texels = image.pixels.chunks_exact(channels);
    let count = texels.len().max(1) as f32;
    let sum =
        texels.fold([0.0f32; 3], |s, t| [s[0] + linear(t[0]), s[1] + linear(t[1]), s[2] + linear(t[2])]);
    Some(sum.map(|c| c / count))
}

fn camera_of(camera: &gltf::Camera, world: Mat4) -> Result<Camera, String> {
    let gltf::camera::Projection::Perspective(perspective) = camera.projection() else {
        return Err("orthographic: Kage renders perspective views".into());
    };
    let position = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    Camera::from_arrays(
        position.to_array(),
        (position + forward).to_array(),
        up.to_array(),
        perspective.yfov().to_degrees(),
    )
    .map_err(|e| e.to_string())
}

/// A point or spot light; `None` for a directional one.
fn light_of(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Option<Light> {
    let position = world.transform_point3(Vec3::ZERO);
    let intensity = light.color().map(|c| c * light.intensity());
    match light.kind() {
        gltf::khr_lights_punctual::Kind::Point => Some(Light::Point { position, intensity }),
        gltf::khr_lights_punctual::Kind::Spot { outer_cone_angle, .. } => Some(Light::Spot {
            position,
            direction: world.transform_vector3(Vec3::NEG_Z),
            fov_deg: 2.0 * outer_cone_angle.to_degrees(),
            intensity,
        }),
        gltf::khr_lights_punctual::Kind::Directional => None,
    }
}

/// A camera that sees every group: from the front (+Z), above their box's centre.
fn overview(groups: &[Group]) -> Camera {
    let (lo, hi) = groups
        .iter()
        .flat_map(|g| {
            let m = g.transform.matrix();
            g.meshes
                .iter()
                .flat_map(move |mesh| mesh.positions.iter().map(move |p| m.transform_point3(Vec3::from(*p))))
        })
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    Camera {
        position: centre + Vec3::new(0.0, 0.5, 2.5) * radius,
        target: centre,
        up: Vec3::Y,
        fov_y_deg: 40.0,
    }
}

/// The animations' channels on the groups' root nodes as the groups' keyframes.
fn motions(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    root_of_group: &[usize],
    groups: &mut [Group],
    unused: &mut Vec<String>,
) -> Result<(), String> {
    // Per group: the times and values of its translation and rotation channels.
    type Track<T> = Option<(Vec<f32>, Vec<T>)>;
    let mut tracks: Vec<(Track<Vec3>, Track<Quat>)> = vec![(None, None); groups.len()];
    for animation in document.animations() {
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
            let node = channel.target().node();
            let property = channel.target().property();
            if property == Property::Scale || property == Property::MorphTargetWeights {
                unused.push(format!("{property:?} channels"));
                continue;
            }
            let Some(g) = root_of_group.iter().position(|&r| r == node.index()) else {
                return Err(at(format!(
                    "it moves node {} inside a group: Kage moves whole groups (root nodes)",
                    node.index()
                )));
            };
            let interpolation = channel.sampler().interpolation();
            let reader = channel.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let times: Vec<f32> =
                reader.read_inputs().ok_or_else(|| at("times beyond their buffer".into()))?.collect();
            match reader.read_outputs().ok_or_else(|| at("values beyond their buffer".into()))? {
                ReadOutputs::Translations(values) => {
                    let values: Vec<Vec3> = values.map(Vec3::from).collect();
                    tracks[g].0 = Some(linear_track(&times, &values, interpolation, |v| v).map_err(at)?);
                }
                ReadOutputs::Rotations(values) => {
                    let values: Vec<Vec4> = values.into_f32().map(Vec4::from_array).collect();
                    let track = linear_track(&times, &values, interpolation, Vec4::normalize).map_err(at)?;
                    tracks[g].1 = Some((track.0, track.1.into_iter().map(Quat::from_vec4).collect()));
                }
                _ => unreachable!("scale and weights are skipped above"),
            }
        }
    }
    for (group, (translations, rotations)) in groups.iter_mut().zip(tracks) {
        if translations.is_none() && rotations.is_none() {
            continue;
        }
        let mut times: Vec<f32> = [&translations.as_ref().map(|t| &t.0), &rotations.as_ref().map(|t| &t.0)]
            .into_iter()
            .flatten()
            .flat_map(|t| t.iter().copied())
            .collect();
        times.sort_by(f32::total_cmp);
        times.dedup();
        let keys = times
            .iter()
            .map(|&time| Key {
                time,
                translation: translations
                    .as_ref()
                    .map_or(group.transform.translation, |(t, v)| sample(t, v, time, Vec3::lerp)),
                rotation: rotations
                    .as_ref()
                    .map_or(group.transform.rotation, |(t, v)| sample(t, v, time, Quat::slerp)),
            })
            .collect();
        let motion = Motion { keys, loop_seconds: None };
        motion.validate().map_err(|e| format!("group \"{}\": {e}", group.name))?;
        group.motion = Some(motion);
    }
    Ok(())
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

/// A channel's value at `time`: interpolated between its keys, held beyond them.
fn sample<T: Copy>(times: &[f32], values: &[T], time: f32, mix: impl Fn(T, T, f32) -> T) -> T {
    let k = times.partition_point(|&t| t <= time);
    match k {
        0 => values[0],
        k if k == times.len() => values[k - 1],
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
