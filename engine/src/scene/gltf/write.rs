//! Writing a scene's groups, lights, camera and motion as binary glTF (.glb), in the mapping
//! the module documents; [`super::parts`] reads them back identical.
use super::super::albedo_map::{AlbedoMap, Wrap};
use super::super::camera::{FAR, NEAR};
use super::super::motion::{Key, Motion};
use super::super::{Camera, Group, Light, Mesh, Scene};
use super::{Extras, KageExtras};
use glam::{Mat3, Quat, Vec3};
use serde_json::{json, Value};

/// glTF's buffer view targets (from the specification).
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The 4-byte numbers the buffer holds, with glTF's code for their component type.
trait Component: Copy + Into<f64> {
    const TYPE: u32;
    fn bytes(self) -> [u8; 4];
}

impl Component for f32 {
    const TYPE: u32 = 5126;
    fn bytes(self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

impl Component for u32 {
    const TYPE: u32 = 5125;
    fn bytes(self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

/// The binary buffer and the JSON arrays that describe it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    /// Each albedo map written (one image, sampler and texture each), by address.
    maps: Vec<*const AlbedoMap>,
    images: Vec<Value>,
    samplers: Vec<Value>,
    textures: Vec<Value>,
}

impl Builder {
    /// Appends `values` (`width` per element of glTF type `kind`) as one buffer view and
    /// accessor; returns the accessor's index. Positions and animation times carry their
    /// bounds, as glTF requires.
    fn accessor<T: Component>(
        &mut self,
        values: &[T],
        width: usize,
        kind: &str,
        target: Option<u32>,
        bounds: bool,
    ) -> usize {
        let offset = self.bin.len();
        self.bin.extend(values.iter().flat_map(|v| v.bytes()));
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": self.bin.len() - offset});
        if let Some(target) = target {
            view["target"] = target.into();
        }
        self.views.push(view);
        let mut accessor = json!({
            "bufferView": self.views.len() - 1,
            "componentType": T::TYPE,
            "count": values.len() / width,
            "type": kind,
        });
        if bounds {
            let (mut lo, mut hi) = (vec![f64::INFINITY; width], vec![f64::NEG_INFINITY; width]);
            for element in values.chunks_exact(width) {
                for (c, v) in element.iter().enumerate() {
                    let v: f64 = (*v).into();
                    (lo[c], hi[c]) = (lo[c].min(v), hi[c].max(v));
                }
            }
            (accessor["min"], accessor["max"]) = (lo.into(), hi.into());
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// The texture of `map`, written as a PNG image in the buffer with its sampler the first
    /// time.
    fn texture(&mut self, map: &std::sync::Arc<AlbedoMap>) -> usize {
        if let Some(at) = self.maps.iter().position(|m| *m == std::sync::Arc::as_ptr(map)) {
            return at;
        }
        let offset = self.bin.len();
        self.bin.extend(map.png());
        self.views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": self.bin.len() - offset}));
        // Each view starts 4-byte aligned, as accessors after it need.
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let index = self.maps.len();
        self.images
            .push(json!({"name": map.name, "mimeType": "image/png", "bufferView": self.views.len() - 1}));
        let wrap = |w| match w {
            Wrap::Repeat => 10497,
            Wrap::MirroredRepeat => 33648,
            Wrap::ClampToEdge => 33071,
        };
        let f = map.filter;
        let min = match (f.minify_linear, f.mipmaps) {
            (false, None) => 9728,
            (true, None) => 9729,
            (false, Some(false)) => 9984,
            (true, Some(false)) => 9985,
            (false, Some(true)) => 9986,
            (true, Some(true)) => 9987,
        };
        self.samplers.push(json!({
            "magFilter": if f.magnify_linear { 9729 } else { 9728 },
            "minFilter": min,
            "wrapS": wrap(map.wrap[0]),
            "wrapT": wrap(map.wrap[1]),
        }));
        self.textures.push(json!({"source": index, "sampler": index}));
        self.maps.push(std::sync::Arc::as_ptr(map));
        index
    }
}

/// The scene's groups, lights, camera and motion as a .glb file's bytes.
pub fn write_glb(scene: &Scene) -> Vec<u8> {
    let mut b = Builder::default();
    let (mut nodes, mut meshes, mut materials, mut animations) = (vec![], vec![], vec![], vec![]);
    let mut roots = Vec::new();
    for group in &scene.groups {
        let mesh_indices: Vec<usize> = group
            .meshes
            .iter()
            .map(|mesh| {
                meshes.push(mesh_json(&mut b, mesh, materials.len()));
                let mut material = json!({
                    "name": mesh.name,
                    "pbrMetallicRoughness": {
                        "baseColorFactor": [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 1.0],
                        "metallicFactor": 0.0,
                        "roughnessFactor": 1.0,
                    },
                });
                if let Some(texturing) = &mesh.texturing {
                    let texture = b.texture(&texturing.map);
                    material["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": texture});
                }
                materials.push(material);
                meshes.len() - 1
            })
            .collect();
        let t = &group.transform;
        let mut root = json!({
            "name": group.name,
            "translation": t.translation.to_array(),
            "rotation": t.rotation.to_array(),
            "scale": vec![t.scale; 3],
        });
        // One mesh sits on the group's node; several on children of it without a transform (a
        // group without meshes, which scenes made in code may hold, is a bare node).
        if let [mesh] = mesh_indices[..] {
            root["mesh"] = mesh.into();
        } else if !mesh_indices.is_empty() {
            let children: Vec<usize> = group
                .meshes
                .iter()
                .zip(&mesh_indices)
                .map(|(mesh, &index)| {
                    nodes.push(json!({"name": mesh.name, "mesh": index}));
                    nodes.len() - 1
                })
                .collect();
            root["children"] = children.into();
        }
        nodes.push(root);
        roots.push(nodes.len() - 1);
        if let Some(motion) = &group.motion {
            animations.push(animation_json(&mut b, group, motion, nodes.len() - 1));
        }
    }

    nodes.push(camera_node(&scene.camera));
    roots.push(nodes.len() - 1);
    let mut lights = Vec::new();
    for light in &scene.lights {
        let (node, light) = light_json(light, lights.len());
        lights.push(light);
        nodes.push(node);
        roots.push(nodes.len() - 1);
    }

    let mut document = json!({
        "asset": {"version": "2.0", "generator": "Kage"},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": roots}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{
            "type": "perspective",
            "perspective": {"yfov": scene.camera.fov_y_deg.to_radians(), "znear": NEAR, "zfar": FAR},
        }],
        "buffers": [{"byteLength": b.bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    if !animations.is_empty() {
        document["animations"] = animations.into();
    }
    if !b.images.is_empty() {
        document["images"] = b.images.into();
        document["samplers"] = b.samplers.into();
        document["textures"] = b.textures.into();
    }
    if !lights.is_empty() {
        document["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        document["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
    }
    let json = serde_json::to_vec(&document).expect("a JSON value always encodes");
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: json.into(),
        bin: Some(b.bin.into()),
    };
    glb.to_vec().expect("writing to memory does not fail")
}

fn mesh_json(b: &mut Builder, mesh: &Mesh, material: usize) -> Value {
    let positions = b.accessor(mesh.positions.as_flattened(), 3, "VEC3", Some(ARRAY_BUFFER), true);
    let normals = b.accessor(mesh.normals.as_flattened(), 3, "VEC3", Some(ARRAY_BUFFER), false);
    let indices = b.accessor(&mesh.indices, 1, "SCALAR", Some(ELEMENT_ARRAY_BUFFER), false);
    let mut attributes = json!({"POSITION": positions, "NORMAL": normals});
    if let Some(texturing) = &mesh.texturing {
        let uvs = b.accessor(texturing.uvs.as_flattened(), 2, "VEC2", Some(ARRAY_BUFFER), false);
        attributes["TEXCOORD_0"] = uvs.into();
    }
    json!({
        "name": mesh.name,
        "primitives": [{"attributes": attributes, "indices": indices, "material": material}],
    })
}

/// The group's keys as linear translation, rotation and scale channels on `node`. A looping
/// motion gets a closing key at its loop length (its pose there, the first key's at 0), so that
/// players that loop over the animation's length play it as Kage does; its loop length goes in
/// the extras.
fn animation_json(b: &mut Builder, group: &Group, motion: &Motion, node: usize) -> Value {
    let mut keys: Vec<Key> = motion.keys.clone();
    if let Some(period) = motion.loop_seconds {
        if keys[0].time > 0.0 {
            keys.insert(0, Key::posed(0.0, motion.at(0.0)));
        }
        if keys[keys.len() - 1].time < period {
            keys.push(Key::posed(period, motion.at(period)));
        }
    }
    let times: Vec<f32> = keys.iter().map(|k| k.time).collect();
    let input = b.accessor(&times, 1, "SCALAR", None, true);
    let translations: Vec<f32> = keys.iter().flat_map(|k| k.translation.to_array()).collect();
    let rotations: Vec<f32> = keys.iter().flat_map(|k| k.rotation.to_array()).collect();
    let scales: Vec<f32> = keys.iter().flat_map(|k| [k.scale; 3]).collect();
    let outputs = [
        ("translation", b.accessor(&translations, 3, "VEC3", None, false)),
        ("rotation", b.accessor(&rotations, 4, "VEC4", None, false)),
        ("scale", b.accessor(&scales, 3, "VEC3", None, false)),
    ];
    let mut animation = json!({
        "name": group.name,
        "samplers": outputs.iter().map(|(_, output)| json!({"input": input, "output": output, "interpolation": "LINEAR"})).collect::<Vec<_>>(),
        "channels": outputs.iter().enumerate().map(|(s, (path, _))| json!({"sampler": s, "target": {"node": node, "path": path}})).collect::<Vec<_>>(),
    });
    if let Some(loop_seconds) = motion.loop_seconds {
        animation["extras"] = extras(KageExtras { loop_seconds: Some(loop_seconds), ..Default::default() });
    }
    animation
}

/// The camera's node: its position and orientation (glTF cameras look down their node's −Z
/// with +Y up), and Kage's look-at in the extras.
fn camera_node(camera: &Camera) -> Value {
    let view = Mat3::from_mat4(camera.view());
    let rotation = Quat::from_mat3(&view.transpose()).normalize();
    let desc = super::super::export::camera(camera);
    json!({
        "name": "camera",
        "camera": 0,
        "translation": camera.position.to_array(),
        "rotation": rotation.to_array(),
        "extras": extras(KageExtras { camera: Some(desc), ..Default::default() }),
    })
}

/// A light's node and its KHR_lights_punctual entry (index `index`): colour the intensity over
/// its largest channel, intensity that channel in candela; a spot turned from −Z to its direction with a
/// hard edge (inner cone just inside the outer one).
fn light_json(light: &Light, index: usize) -> (Value, Value) {
    let (position, intensity) = match *light {
        Light::Point { position, intensity } | Light::Spot { position, intensity, .. } => {
            (position, intensity)
        }
    };
    let peak = intensity.iter().copied().fold(0.0, f32::max);
    let colour = if peak > 0.0 { intensity.map(|c| c / peak) } else { [1.0; 3] };
    let mut node = json!({
        "name": format!("light {index}"),
        "translation": position.to_array(),
        "extensions": {"KHR_lights_punctual": {"light": index}},
        "extras": extras(KageExtras { light: Some(super::super::export::light(light)), ..Default::default() }),
    });
    let mut entry = json!({"name": format!("light {index}"), "color": colour, "intensity": peak * super::LUMENS_PER_WATT});
    match *light {
        Light::Point { .. } => entry["type"] = "point".into(),
        Light::Spot { direction, fov_deg, .. } => {
            node["rotation"] = Quat::from_rotation_arc(Vec3::NEG_Z, direction.normalize()).to_array().into();
            let outer = (0.5 * fov_deg).to_radians();
            entry["type"] = "spot".into();
            // The next float below the outer angle (positive, so one below in its bits).
            let inner = f32::from_bits(outer.to_bits() - 1);
            entry["spot"] = json!({"innerConeAngle": inner, "outerConeAngle": outer});
        }
    }
    (node, entry)
}

fn extras(kage: KageExtras) -> Value {
    serde_json::to_value(Extras { kage }).expect("plain numbers always encode")
}
