//! glTF 2.0 scenes: tests/assets/gltf/two-groups.gltf (made by tests/assets/gltf/make.py) read
//! against the values the script wrote, hostile variants of it refused with errors naming the
//! file and the element, a file written by another tool, scene files that take their geometry
//! from glTF, and Kage's own glTF export rendering the same pixels as the scene it came from.
use glam::{Quat, Vec3};
use kage::prt::{transfer, PrtParams};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{Light, Scene, SceneFormat, SCENE_FILE};
use kage::techniques::description::TechniqueDesc;
use kage_tests::{every_technique, scratch_dir, Validated};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::Arc;

fn asset() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/two-groups.gltf")
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn groups_transforms_albedo_camera_lights_and_animation_are_read() {
    let scene = Scene::from_arg(asset().to_str().unwrap()).unwrap();
    assert_eq!(scene.name, "two-groups");
    let names: Vec<&str> = scene.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["box", "floor"], "root nodes with meshes; camera and lamps are no groups");
    let (cube, floor) = (&scene.groups[0], &scene.groups[1]);
    assert!(
        close(cube.transform.translation, Vec3::new(0.0, 0.5, 0.0))
            && (cube.transform.scale - 0.5).abs() < 1e-6
    );
    // The child node's offset (0.2 along X) is baked into the cube's vertices.
    let xs = cube.meshes[0].positions.iter().map(|p| p[0]);
    let (lo, hi) = xs.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    assert!((lo + 0.3).abs() < 1e-6 && (hi - 0.7).abs() < 1e-6, "{lo} {hi}");
    assert_eq!(cube.meshes[0].triangle_count(), 12);
    assert_eq!(cube.meshes[0].albedo, [0.8, 0.2, 0.2]);
    assert_eq!(floor.meshes[0].albedo, [0.6, 0.6, 0.6]);
    assert!(floor.motion.is_none());
    // The camera: at (0, 2, 5), tilted 0.3 rad down, 0.7 rad vertical field of view.
    let camera = scene.camera;
    assert!(close(camera.position, Vec3::new(0.0, 2.0, 5.0)));
    let forward = (camera.target - camera.position).normalize();
    assert!((forward.y + 0.3f32.sin()).abs() < 1e-5, "{forward}");
    assert!((camera.fov_y_deg - 0.7f32.to_degrees()).abs() < 1e-4);
    // The file's 3415 and 6147 cd are 5 and 9 W/sr at 683 lm/W.
    match scene.lights[..] {
        [Light::Point { position, intensity }, Light::Spot { position: at, direction, fov_deg, intensity: spot }] =>
        {
            assert!(close(position, Vec3::new(0.0, 3.0, 0.0)) && intensity == [5.0; 3]);
            assert!(close(at, Vec3::new(2.0, 3.0, 0.0)) && close(direction.normalize(), Vec3::NEG_Y));
            assert!((fov_deg - 1.0f32.to_degrees()).abs() < 1e-4 && spot == [9.0, 4.5, 4.5]);
        }
        _ => panic!("lights {:?}", scene.lights),
    }
    // The box slides to x = 1 turning 90° about +Y at 1 s and back at 2 s; then holds.
    let motion = cube.motion.as_ref().unwrap();
    assert_eq!(motion.keys.iter().map(|k| k.time).collect::<Vec<_>>(), [0.0, 1.0, 2.0]);
    assert_eq!(scene.duration(), 2.0);
    let at_one = cube.pose_at(1.0);
    assert!(close(at_one.translation, Vec3::new(1.0, 0.5, 0.0)) && at_one.scale == 0.5);
    assert!(at_one.rotation.abs_diff_eq(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2), 1e-5));
    assert!(close(cube.pose_at(0.5).translation, Vec3::new(0.5, 0.5, 0.0)));
    assert_eq!(cube.pose_at(5.0), cube.pose_at(2.0));
}

/// Writes `two-groups.gltf` changed by `edit` and returns the error of reading it.
fn error_of(name: &str, edit: impl Fn(&mut Value)) -> String {
    let mut gltf: Value = serde_json::from_str(&std::fs::read_to_string(asset()).unwrap()).unwrap();
    edit(&mut gltf);
    let path = scratch_dir("gltf").join(format!("{name}.gltf"));
    std::fs::write(&path, gltf.to_string()).unwrap();
    let message = Scene::load(&path).unwrap_err().to_string();
    // Once: the file read alone is both the scene and the glTF file at fault.
    let named = message.matches(path.to_str().unwrap()).count();
    assert_eq!(named, 1, "{message}: names the file {named} times, not once");
    message
}

#[test]
fn hostile_gltf_is_refused_naming_the_file_and_the_element() {
    type Edit<'a> = &'a dyn Fn(&mut Value);
    let cases: [(&str, Edit, &str); 13] = [
        (
            "missing-buffer",
            &|g| g["buffers"][0]["uri"] = "missing.bin".into(),
            "buffer 0's file \"missing.bin\" (",
        ),
        ("cycle", &|g| g["nodes"][0]["children"] = serde_json::json!([0]), "node 0 is met twice"),
        (
            "lines",
            &|g| g["meshes"][0]["primitives"][0]["mode"] = 1.into(),
            "mesh 0 (\"cube\") primitive 0: mode Lines",
        ),
        (
            "short-buffer",
            &|g| g["buffers"][0]["byteLength"] = 100000.into(),
            "fewer than its byteLength 100000",
        ),
        (
            "garbage-uri",
            &|g| g["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@".into(),
            "its base64 data does not decode",
        ),
        (
            "huge-count",
            &|g| g["accessors"][0]["count"] = 1_000_000_000u64.into(),
            "mesh 0 (\"cube\") primitive 0: positions missing, or beyond their buffer",
        ),
        (
            "short-spline",
            &|g| g["animations"][0]["samplers"][0]["interpolation"] = "CUBICSPLINE".into(),
            "animation 0 channel 0: 3 values for 3 times (CubicSpline sampling)",
        ),
        // Silently accepted before: bytes read as floats, a mesh dropped, an albedo clamped.
        (
            "byte-positions",
            &|g| g["accessors"][0]["componentType"] = 5121.into(),
            "mesh 0 (\"cube\") primitive 0: its POSITION accessor 0 holds Vec3 of component type U8",
        ),
        (
            "no-primitives",
            &|g| g["meshes"][0]["primitives"] = serde_json::json!([]),
            "mesh 0 (\"cube\"): it has no primitives",
        ),
        (
            "bright",
            &|g| {
                g["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] =
                    serde_json::json!([5, -1, 0.5, 1])
            },
            "material 0 (\"red\"): baseColorFactor [5.0, -1.0, 0.5] is outside [0, 1]",
        ),
        ("skin", &|g| g["skins"] = serde_json::json!([{"joints": [1]}]), "skin 0"),
        ("stretched", &|g| g["nodes"][0]["scale"] = serde_json::json!([1, 2, 1]), "node 0: scale"),
        (
            "stretching",
            &|g| {
                // The translations (x from 0 to 1, y 0.5) as scales: not uniform.
                let samplers = g["animations"][0]["samplers"].as_array_mut().unwrap();
                samplers.push(serde_json::json!({"input": 5, "output": 6}));
                let channel = serde_json::json!({"sampler": samplers.len() - 1, "target": {"node": 0, "path": "scale"}});
                g["animations"][0]["channels"].as_array_mut().unwrap().push(channel);
            },
            "group \"box\": at 0 s its scale in the world, [0, 0.5, 0], is not uniform",
        ),
    ];
    for (name, edit, expected) in cases {
        let message = error_of(name, edit);
        assert!(message.contains(expected), "{name}: {message:?} does not say {expected:?}");
    }
    // A child offset beyond f32 turns the baked vertices infinite.
    let infinite = error_of("infinite", |g| g["nodes"][1]["translation"] = serde_json::json!([1e39, 0, 0]));
    assert!(
        infinite.contains("mesh 0 (\"cube\") primitive 0") && infinite.contains("NaN or infinite"),
        "{infinite}"
    );
}

/// A binary glTF whose JSON chunk claims more bytes than the file holds.
#[test]
fn a_glb_with_a_wrong_chunk_length_is_an_error() {
    let json = std::fs::read(asset()).unwrap();
    let padded = json.len().div_ceil(4) * 4;
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + padded) as u32).to_le_bytes());
    glb.extend(((padded + 64) as u32).to_le_bytes()); // the lie
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.resize(12 + 8 + padded, b' ');
    let path = scratch_dir("gltf").join("lying.glb");
    std::fs::write(&path, glb).unwrap();
    let message = Scene::from_arg(path.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        message.contains("lying.glb") && message.contains("not a glTF 2.0 file Kage can read"),
        "{message}"
    );
}

/// A file written by another tool (COLLADA2GLTF: the Khronos sample Box, CC BY 4.0, see
/// tests/assets/gltf/khronos-box/README.md): its root node's matrix turns the box -90° about X,
/// its child's identity matrix leaves the cube's 24 vertices where they are.
#[test]
fn the_khronos_sample_box_is_read() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/khronos-box/Box.gltf");
    let scene = Scene::load(&path).unwrap();
    assert_eq!(scene.groups.len(), 1);
    let group = &scene.groups[0];
    assert_eq!(group.name, "node0", "an unnamed node is named by its index");
    let turned = |v: Vec3| group.transform.rotation * v;
    assert!(
        close(turned(Vec3::Y), Vec3::NEG_Z)
            && close(turned(Vec3::Z), Vec3::Y)
            && close(turned(Vec3::X), Vec3::X)
    );
    assert!(close(group.transform.translation, Vec3::ZERO) && group.transform.scale == 1.0);
    let mesh = &group.meshes[0];
    assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (24, 12));
    assert!(mesh.positions.iter().flatten().all(|c| c.abs() == 0.5));
    assert_eq!(mesh.albedo, [0.8, 0.0, 0.0]);
    assert!(scene.lights.is_empty() && group.motion.is_none());
}

/// Step sampling holds each key's value until the next key.
#[test]
fn step_sampling_holds_each_value_until_the_next_key() {
    let mut gltf: Value = serde_json::from_str(&std::fs::read_to_string(asset()).unwrap()).unwrap();
    gltf["animations"][0]["samplers"][0]["interpolation"] = "STEP".into();
    let path = scratch_dir("gltf").join("step.gltf");
    std::fs::write(&path, gltf.to_string()).unwrap();
    let scene = Scene::load(&path).unwrap();
    let cube = &scene.groups[0];
    assert!(close(cube.pose_at(0.9).translation, Vec3::new(0.0, 0.5, 0.0)), "held at the first key");
    assert!(close(cube.pose_at(1.0).translation, Vec3::new(1.0, 0.5, 0.0)));
    assert!(close(cube.pose_at(1.5).translation, Vec3::new(1.0, 0.5, 0.0)));
}

/// A scene file that takes its groups, lights and camera from a glTF file and adds what glTF has
/// no place for; its own camera replaces the glTF one, `gltf_camera` picks one by name, its
/// lights are added; naming a camera the file lacks is an error.
#[test]
fn a_scene_file_takes_its_geometry_from_gltf() {
    let dir = scratch_dir("gltf-scene-file");
    std::fs::copy(asset(), dir.join("two-groups.gltf")).unwrap();
    let write = |name: &str, extra: &str| {
        let path = dir.join(name);
        let json = format!(
            r#"{{"gltf": "two-groups.gltf", "environment": {{"constant": [0.5, 0.5, 0.5]}},
                "probes": [{{"position": [0, 1, 0]}}], "exposure": 2{extra}}}"#
        );
        std::fs::write(&path, json).unwrap();
        path
    };
    let scene = Scene::load(&write("plain.json", "")).unwrap();
    let from_gltf = Scene::load(&asset()).unwrap();
    assert_eq!((scene.name.as_str(), scene.exposure, scene.probes.len()), ("plain", 2.0, 1));
    assert!(scene.groups == from_gltf.groups && scene.lights == from_gltf.lights);
    assert_eq!(scene.camera, from_gltf.camera);
    assert_eq!(scene.environment.pixels()[0], [0.5; 3]);

    let camera = r#"{"position": [0, 1, 9], "target": [0, 0, 0], "fov_y_deg": 30}"#;
    let light = r#"{"point": {"position": [0, 4, 0], "intensity": [1, 1, 1]}}"#;
    let walk = format!(r#", "camera": {camera}, "lights": [{light}], "walkthrough": [{camera}, {camera}]"#);
    let own = Scene::load(&write("own.json", &walk)).unwrap();
    assert_eq!((own.camera.position, own.camera.fov_y_deg), (Vec3::new(0.0, 1.0, 9.0), 30.0));
    assert_eq!((own.lights.len(), own.walkthrough.len()), (3, 2));
    assert_eq!(own.lights[2], Light::Point { position: Vec3::new(0.0, 4.0, 0.0), intensity: [1.0; 3] });

    let named = Scene::load(&write("named.json", r#", "gltf_camera": "camera""#)).unwrap();
    assert_eq!(named.camera, from_gltf.camera, "the camera's node is named \"camera\"");
    let message =
        Scene::load(&write("missing.json", r#", "gltf_camera": "nobody""#)).unwrap_err().to_string();
    let expected = "no camera named \"nobody\" (its cameras and their nodes: \"camera\")";
    assert!(message.contains("missing.json") && message.contains(expected), "{message}");
    let lone = dir.join("lone.json");
    std::fs::write(&lone, r#"{"gltf_camera": "camera", "environment": {"constant": [1, 1, 1]}, "camera": {"position": [0, 0, 1], "target": [0, 0, 0], "fov_y_deg": 40}}"#).unwrap();
    let message = Scene::load(&lone).unwrap_err().to_string();
    assert!(message.contains("\"gltf_camera\" or \"gltf_groups\" without a \"gltf\" file"), "{message}");
}

/// The Khronos sample Box.
fn khronos_box() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/khronos-box/Box.gltf")
}

/// A scene file naming Box.gltf and adding `extra` (JSON fields after a comma).
fn box_scene_file(dir: &std::path::Path, name: &str, extra: &str) -> PathBuf {
    let path = dir.join(name);
    let gltf = serde_json::to_string(khronos_box().to_str().unwrap()).unwrap();
    std::fs::write(&path, format!(r#"{{"gltf": {gltf}{extra}}}"#)).unwrap();
    path
}

const FLOOR: &str = r#""groups": [{"name": "floor", "translation": [0, -0.5, 0],
    "meshes": [{"plane": {"size": [3, 3], "vertices": [9, 9]}, "albedo": [0.6, 0.6, 0.6]}]}]"#;

/// A scene file adds a floor (a plane group) under a glTF model and gives no environment: the
/// glTF's group first, then the floor; lit by the default sky, as the glTF file alone is. It
/// renders under validation, unshadowed and with Sloan's PRT of the whole scene, whose shadow
/// of the box on the floor (and of the floor on the box) only darkens: under a constant sky the
/// unoccluded transfer is the unshadowed one.
#[test]
fn a_scene_file_adds_a_floor_under_a_gltf_model_and_renders() {
    let dir = scratch_dir("gltf-floor");
    let camera = r#""camera": {"position": [0, 1.5, 3], "target": [0, -0.3, 0], "fov_y_deg": 45}"#;
    let file = box_scene_file(&dir, "box-on-floor.json", &format!(", {camera}, {FLOOR}"));
    let loaded = Scene::read(&file).unwrap();
    assert!(loaded.default_environment, "no environment given");
    let scene = loaded.scene;
    let alone = Scene::read(&khronos_box()).unwrap();
    assert!(alone.default_environment);
    let names: Vec<&str> = scene.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["node0", "floor"], "the glTF's group, then the listed one");
    assert_eq!(scene.groups[0], alone.scene.groups[0]);
    assert_eq!(scene.groups[1].meshes[0].vertex_count(), 81);
    assert_eq!(scene.groups[1].transform.translation, Vec3::new(0.0, -0.5, 0.0));
    assert_eq!(scene.environment, alone.scene.environment);
    assert!(scene.environment.pixels().iter().all(|p| *p == [kage::scene::DEFAULT_SKY; 3]));

    let ctx = Validated::new();
    let render = |technique: TechniqueDesc| {
        let transfer = technique.precomputation().map(|params| {
            Arc::new(transfer::precompute(&ctx, &scene, params, &mut kage::progress::silent).unwrap())
        });
        let options = RenderOptions { width: 32, height: 32, technique, transfer };
        let mut renderer = Renderer::new(&ctx, &scene, &options).unwrap();
        renderer.render().unwrap();
        renderer.image().unwrap().pixels
    };
    let unshadowed = render(TechniqueDesc::Unshadowed);
    let prt = PrtParams { bands: 3, rays: 16, ..PrtParams::DEFAULT };
    let shadowed = render(TechniqueDesc::SloanScene { prt });
    let luminance = |p: &[f32; 4]| p[0] + p[1] + p[2];
    assert!(unshadowed.iter().chain(&shadowed).all(|p| p.iter().all(|c| c.is_finite())));
    let lit = unshadowed.iter().filter(|p| luminance(p) > 0.0).count();
    assert!(lit > unshadowed.len() / 4, "the box and floor fill the view: {lit} lit pixels");
    let darker = unshadowed.iter().zip(&shadowed).filter(|(u, s)| luminance(s) < 0.9 * luminance(u)).count();
    let brighter =
        unshadowed.iter().zip(&shadowed).filter(|(u, s)| luminance(s) > 1.05 * luminance(u)).count();
    assert!(darker > 10 && brighter == 0, "{darker} pixels shadowed, {brighter} brighter");
}

/// A scene file that composes a glTF model with groups of its own still refuses bad values,
/// naming the scene file and the place; a glTF error names each file once.
#[test]
fn a_composed_scene_file_refuses_bad_values_by_name() {
    let dir = scratch_dir("gltf-floor-bad");
    let camera = r#""camera": {"position": [0, 1.5, 3], "target": [0, -0.3, 0], "fov_y_deg": 45}"#;
    let cases = [
        (
            "scale.json",
            format!(
                ", {camera}, {}",
                FLOOR.replace("\"name\": \"floor\"", "\"name\": \"floor\", \"scale\": 0")
            ),
            "group 0 (\"floor\"): scale must be finite and greater than zero",
        ),
        (
            "env.json",
            format!(
                ", {camera}, {FLOOR}, \"environment\": {{\"image\": \"sky.exr\", \"constant\": [1, 1, 1]}}"
            ),
            "environment needs exactly one of",
        ),
        (
            "negative.json",
            format!(", {FLOOR}, \"environment\": {{\"constant\": [1, -1, 1]}}"),
            "must be finite and >= 0",
        ),
        (
            "no-meshes.json",
            format!(", {camera}, \"groups\": [{{\"name\": \"floor\", \"meshes\": []}}]"),
            "group 0 (\"floor\"): it has no meshes",
        ),
    ];
    for (name, extra, expected) in cases {
        let path = box_scene_file(&dir, name, &extra);
        let message = Scene::load(&path).unwrap_err().to_string();
        assert!(message.contains(expected), "{name}: {message}");
        assert_eq!(message.matches(path.to_str().unwrap()).count(), 1, "{message}");
    }
    // A glTF file that is not there, behind a scene file: the scene file and the glTF file,
    // each named once.
    let missing = dir.join("missing.json");
    std::fs::write(&missing, format!(r#"{{"gltf": "nowhere.gltf", {camera}, {FLOOR}}}"#)).unwrap();
    let message = Scene::load(&missing).unwrap_err().to_string();
    let gltf = dir.join("nowhere.gltf");
    for file in [missing.to_str().unwrap(), gltf.to_str().unwrap()] {
        assert_eq!(message.matches(file).count(), 1, "{file} in {message}");
    }
}

/// Kage's own look-at in a camera node's extras is taken while it agrees with the node; once
/// another tool moved the node (leaving the extras as they were), the node is what is read.
#[test]
fn kage_extras_that_disagree_with_their_node_are_ignored() {
    let scene = Scene::builtin("teapot").unwrap();
    let dir = scratch_dir("gltf-extras");
    scene.export(&dir, SceneFormat::Gltf).unwrap();
    let glb_path = dir.join(kage::scene::GLTF_FILE);
    let bytes = std::fs::read(&glb_path).unwrap();
    let glb = gltf::binary::Glb::from_slice(&bytes).unwrap();
    let mut json: Value = serde_json::from_slice(&glb.json).unwrap();
    let camera_node =
        json["nodes"].as_array().unwrap().iter().position(|n| n.get("camera").is_some()).unwrap();
    json["nodes"][camera_node]["translation"] = serde_json::json!([0.0, 2.2, 6.0]);
    let json = serde_json::to_vec(&json).unwrap();
    let moved = gltf::binary::Glb { header: glb.header, json: json.into(), bin: glb.bin.clone() };
    let moved_path = dir.join("moved.glb");
    std::fs::write(&moved_path, moved.to_vec().unwrap()).unwrap();
    let exact = Scene::load(&glb_path).unwrap();
    let edited = Scene::load(&moved_path).unwrap();
    assert_eq!(exact.camera, scene.camera, "Kage's extras, bit for bit");
    assert_eq!(edited.camera.position, Vec3::new(0.0, 2.2, 6.0), "the node as the other tool left it");
    let (a, b) = (scene.camera.target - scene.camera.position, edited.camera.target - edited.camera.position);
    assert!(a.normalize().dot(b.normalize()) > 1.0 - 1e-6, "the same direction, from the node's rotation");
}

/// The default scene (with a spot light added for the local-light techniques) exported with its
/// geometry as OBJ and as glTF reads back as two scenes that render the same pixels, with every
/// technique, at an instant of the teapot's hop: the glTF path loses nothing the renderer uses.
#[test]
fn the_default_scene_as_gltf_renders_the_same_pixels_with_every_technique() {
    let ctx = Validated::new();
    let mut scene = Scene::builtin("teapot").unwrap();
    scene.lights.push(Light::Spot {
        position: Vec3::new(1.5, 3.0, 1.0),
        direction: Vec3::new(-1.5, -3.0, -1.0).normalize(),
        fov_deg: 60.0,
        intensity: [6.0, 5.0, 4.0],
    });
    let written = |format: SceneFormat| {
        let dir = scratch_dir("gltf-default");
        scene.export(&dir, format).unwrap();
        Scene::load(&dir.join(SCENE_FILE)).unwrap()
    };
    let (json, gltf) = (written(SceneFormat::Json), written(SceneFormat::Gltf));
    let render = |scene: &Scene, options: RenderOptions| {
        let options = RenderOptions { width: 48, height: 48, ..options };
        let mut renderer = Renderer::new(&ctx, scene, &options).unwrap();
        renderer.set_time(0.3).unwrap();
        renderer.render().unwrap();
        renderer.image().unwrap().pixels
    };
    let techniques = every_technique(&ctx, &json).into_iter().zip(every_technique(&ctx, &gltf));
    for ((kind, from_json), (_, from_gltf)) in techniques {
        let (a, b) = (render(&json, from_json), render(&gltf, from_gltf));
        let differing = a.iter().zip(&b).filter(|(p, q)| p != q).count();
        assert_eq!(differing, 0, "{kind:?}: {differing} of {} pixels differ", a.len());
        assert!(a.iter().any(|p| p[0] > 0.0), "{kind:?} rendered black");
    }
}

/// The default scene written by Blender (see tests/assets/gltf/blender-teapot/README.md) reads
/// as the built-in one: its groups' triangles and extent, its camera from the node alone (Blender
/// drops Kage's extras), and the hop as Blender resampled it at 24 frames per second, each key
/// the built-in motion's pose at that instant.
#[test]
fn the_default_scene_written_by_blender_reads_as_the_builtin_one() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/blender-teapot/teapot.glb");
    let (blender, builtin) = (Scene::load(&path).unwrap(), Scene::builtin("teapot").unwrap());
    let names: Vec<&str> = blender.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["teapot", "floor"]);
    let extent = |group: &kage::scene::Group| {
        let m = group.transform.matrix();
        let points = group
            .meshes
            .iter()
            .flat_map(|mesh| mesh.positions.iter().map(|p| m.transform_point3(Vec3::from(*p))));
        points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
    };
    for (a, b) in blender.groups.iter().zip(&builtin.groups) {
        assert_eq!(a.meshes[0].triangle_count(), b.meshes[0].triangle_count(), "{}", a.name);
        let ((a_lo, a_hi), (b_lo, b_hi)) = (extent(a), extent(b));
        assert!(close(a_lo, b_lo) && close(a_hi, b_hi), "{}: {a_lo} {a_hi} against {b_lo} {b_hi}", a.name);
    }
    let (camera, expected) = (blender.camera, builtin.camera);
    assert!(close(camera.position, expected.position));
    let direction = |c: &kage::scene::Camera| (c.target - c.position).normalize();
    assert!(direction(&camera).dot(direction(&expected)) > 1.0 - 1e-6);
    assert!((camera.fov_y_deg - expected.fov_y_deg).abs() < 1e-4);
    let motion = blender.groups[0].motion.as_ref().unwrap();
    assert_eq!((motion.keys.len(), motion.loop_seconds), (25, None));
    for key in &motion.keys {
        let hop = builtin.groups[0].pose_at(key.time);
        assert!(
            close(key.translation, hop.translation),
            "at {} s: {} against {}",
            key.time,
            key.translation,
            hop.translation
        );
        assert!(
            key.rotation.abs_diff_eq(hop.rotation, 1e-5) || key.rotation.abs_diff_eq(-hop.rotation, 1e-5)
        );
        assert!((key.scale - hop.scale).abs() < 1e-6);
    }
}

/// A node that moves is a group of its own wherever it sits, and so is one that `gltf_groups`
/// names: the box's child "cube" is then placed by its parents (its vertices as stored), and its
/// keys, written in its parent's frame, become world poses; inside a moving box, a named cube
/// follows the box's keys; naming a node the file lacks is an error.
#[test]
fn moving_and_named_nodes_inside_a_root_are_groups_of_their_own() {
    let dir = scratch_dir("gltf-groups");
    let mut gltf: Value = serde_json::from_str(&std::fs::read_to_string(asset()).unwrap()).unwrap();
    // The animation moves the child instead of the box.
    for channel in gltf["animations"][0]["channels"].as_array_mut().unwrap() {
        channel["target"]["node"] = 1.into();
    }
    std::fs::write(dir.join("child-moves.gltf"), gltf.to_string()).unwrap();
    std::fs::copy(asset(), dir.join("two-groups.gltf")).unwrap();
    let scene_file = |gltf: &str, groups: &str| {
        let path = dir.join(format!("{}-{}.json", gltf, groups.len()));
        let json = format!(
            r#"{{"gltf": "{gltf}.gltf", "gltf_groups": [{groups}], "environment": {{"constant": [1, 1, 1]}}}}"#
        );
        std::fs::write(&path, json).unwrap();
        Scene::load(&path)
    };
    for groups in ["", r#""cube""#] {
        let scene = scene_file("child-moves", groups).unwrap();
        let names: Vec<&str> = scene.groups.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(names, ["floor", "cube"], "the box holds no mesh of its own: no group");
        let cube = &scene.groups[1];
        // The box (at (0, 0.5, 0), scale 0.5) places the cube's (0.2, 0, 0) offset.
        assert!(
            close(cube.transform.translation, Vec3::new(0.1, 0.5, 0.0))
                && (cube.transform.scale - 0.5).abs() < 1e-6
        );
        assert!(cube.meshes[0].positions.iter().flatten().all(|c| c.abs() == 0.5), "vertices as stored");
        // The key (1, 0.5, 0) in the box's frame: (0, 0.5, 0) + 0.5 × (1, 0.5, 0).
        let at_one = cube.pose_at(1.0).translation;
        assert!(close(at_one, Vec3::new(0.5, 0.75, 0.0)), "{at_one}");
    }
    // The box moves (to x = 1 turning 90° about +Y at 1 s): the named cube, 0.2 along the box's
    // X at half its scale, is carried to (1, 0.5, 0) + 0.1 × (box's X turned = -Z).
    let scene = scene_file("two-groups", r#""cube""#).unwrap();
    let cube = scene.groups.iter().find(|g| g.name == "cube").unwrap();
    let at_one = cube.pose_at(1.0);
    assert!(close(at_one.translation, Vec3::new(1.0, 0.5, -0.1)), "{}", at_one.translation);
    assert!(at_one.rotation.abs_diff_eq(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2), 1e-5));
    let message = scene_file("two-groups", r#""nobody""#).unwrap_err().to_string();
    assert!(message.contains("gltf_groups: it has no node named \"nobody\""), "{message}");
}

fn box_animated() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/khronos-box-animated/BoxAnimated.gltf")
}

/// The Khronos sample BoxAnimated (CC BY 4.0, see its README): nodes without names, the inner
/// box (node 2) turned by its own channel and carried up by its grandparent (node 0, moved by
/// another animation), the outer box (node 3) still. The inner box becomes a moving group whose
/// keys compose both channels; the outer one a static group.
#[test]
fn box_animated_composes_its_hierarchical_animation() {
    let scene = Scene::load(&box_animated()).unwrap();
    let names: Vec<&str> = scene.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["node3", "node2"], "node 0 holds no mesh of its own");
    assert!(scene.groups[0].motion.is_none());
    let inner = &scene.groups[1];
    assert!((scene.duration() - 3.708_33).abs() < 1e-4, "{}", scene.duration());
    let up = Vec3::new(0.0, 2.52, 0.0);
    let half_turn = Quat::from_rotation_x(std::f32::consts::PI);
    let same_turn = |a: Quat, b: Quat| a.abs_diff_eq(b, 1e-4) || a.abs_diff_eq(-b, 1e-4);
    for (time, translation, rotation) in [
        (0.0, Vec3::ZERO, Quat::IDENTITY),
        (1.25, up, Quat::IDENTITY),
        (1.875, up, Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)),
        (2.5, up, half_turn),
        (3.708_33, Vec3::ZERO, half_turn),
    ] {
        let pose = inner.pose_at(time);
        assert!((pose.translation - translation).length() < 1e-4, "{time} s: {}", pose.translation);
        assert!(same_turn(pose.rotation, rotation), "{time} s: {}", pose.rotation);
    }
}

/// BoxAnimated plays with every technique: where the reference's pictures at 0 s and 1.25 s
/// differ beyond their noise (the inner box has left the outer one), each technique's differ
/// too, at all but the pixels along the moving silhouettes.
#[test]
fn box_animated_plays_with_every_technique_where_the_reference_moves() {
    use glam::DVec3;
    use kage::reference::{LightMode, ReferenceOptions, ReferenceRenderer};
    use kage::techniques::description::TechniqueDesc;
    use kage::techniques::probes::ProbePlacement;
    const SIZE: u32 = 32;
    let ctx = Validated::new();
    let mut scene = Scene::load(&box_animated()).unwrap();
    // A lamp above and in front, for the local-light techniques (shadowmap, asm).
    scene.lights.push(Light::Point { position: Vec3::new(1.0, 6.0, 4.0), intensity: [40.0; 3] });
    let (before, after) = (0.0, 1.25);
    let posed = |time: f32| {
        let mut posed = scene.clone();
        for group in &mut posed.groups {
            group.transform = group.pose_at(time);
            group.motion = None;
        }
        posed
    };
    let luminance = |p: &[f32]| (p[0] + p[1] + p[2]) / 3.0;
    // The pixels that move under `light`: the reference's means at the two instants differ by
    // more than 4 of their joint standard errors and by a tenth of the brighter.
    let moved = |light: LightMode| {
        let reference = |time: f32| {
            let options = ReferenceOptions { width: SIZE, height: SIZE, light, seed: 1 };
            let mut renderer = ReferenceRenderer::new(&ctx, &posed(time), &options).unwrap();
            renderer.run_batch(64).unwrap();
            renderer.statistics().unwrap()
        };
        let (r0, r1) = (reference(before), reference(after));
        let (e0, e1) = (r0.standard_error.as_ref().unwrap(), r1.standard_error.as_ref().unwrap());
        let moved: Vec<usize> = (0..r0.mean.len())
            .filter(|&i| {
                let (a, b) = (luminance(&r0.mean[i]), luminance(&r1.mean[i]));
                let noise = (luminance(&e0[i]).powi(2) + luminance(&e1[i]).powi(2)).sqrt();
                (a - b).abs() > (4.0 * noise).max(0.1 * a.max(b))
            })
            .collect();
        assert!(
            moved.len() > 20,
            "{light:?}: the reference sees the inner box move in {} pixels",
            moved.len()
        );
        moved
    };
    let (moved_environment, moved_local) = (moved(LightMode::Environment), moved(LightMode::Local));
    for (kind, mut options) in every_technique(&ctx, &scene) {
        // Probes go where the inner box travels: a grid over the outer box would put every
        // one inside it. The eight corners of a box around its path.
        if let TechniqueDesc::Probes { probes, .. } = &mut options.technique {
            let corners = (0..8)
                .map(|c| DVec3::new([-1.0, 1.0][c & 1], [-1.0, 3.6][(c >> 1) & 1], [-1.0, 1.0][c >> 2]));
            probes.placement = ProbePlacement::Positions(corners.collect());
        }
        let local = matches!(options.technique, TechniqueDesc::ShadowMap { .. } | TechniqueDesc::Asm(_));
        let moved = if local { &moved_local } else { &moved_environment };
        let mut renderer =
            Renderer::new(&ctx, &scene, &RenderOptions { width: SIZE, height: SIZE, ..options }).unwrap();
        let mut frame = |time: f32| {
            renderer.set_time(time).unwrap();
            renderer.render().unwrap();
            renderer.image().unwrap().pixels
        };
        let (f0, f1) = (frame(before), frame(after));
        let followed = moved
            .iter()
            .filter(|&&i| {
                let (a, b) = (luminance(&f0[i]), luminance(&f1[i]));
                (a - b).abs() > 0.05 * a.max(b)
            })
            .count();
        println!("{kind:?}: {followed} of the {} pixels the reference moves in move", moved.len());
        assert!(followed * 10 >= moved.len() * 9, "{kind:?}: only {followed} of {} pixels move", moved.len());
    }
}

/// A scene as a Blender user makes one (tests/assets/gltf/blender-suzanne/make.py, Blender
/// 3.4.1's exporter): objects in creation order, so the ground comes first and the animated
/// Suzanne last. Suzanne is the probe-lit group, wherever she goes; the ground and the textured
/// crate keep the static technique's lighting, pixel for pixel; the 1000 W spot, written as
/// 54,351 cd, reads back as the 1000 / 4π W/sr it radiates; the crate's colour grid is its
/// albedo map, with the sampler Blender wrote.
#[test]
fn a_blender_scene_with_the_animated_object_last_lights_it_from_the_probes() {
    use kage::scene::albedo_map::{Filter, Wrap};
    use kage::techniques::probes::{CaptureSettings, ProbeGroups, ProbePlacement, ProbeSettings};
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/blender-suzanne/scene.glb");
    let scene = Scene::load(&path).unwrap();
    let names: Vec<&str> = scene.groups.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["Ground", "Crate", "Suzanne"]);
    assert_eq!(ProbeGroups::of(&scene).moving(), [2], "Suzanne, the only group with keyframes");
    match scene.lights[..] {
        [Light::Spot { intensity, fov_deg, .. }] => {
            let expected = 1000.0 / (4.0 * std::f32::consts::PI);
            assert!(intensity.iter().all(|i| (i - expected).abs() < 1e-4 * expected), "{intensity:?}");
            assert!((fov_deg - 70.0).abs() < 1e-3, "{fov_deg}");
        }
        ref other => panic!("one spot light expected: {other:?}"),
    }
    let crate_map = &scene.groups[1].meshes[0].texturing.as_ref().expect("the crate's texture").map;
    assert_eq!((crate_map.name.as_str(), crate_map.width, crate_map.height), ("grid", 64, 64));
    assert_eq!((crate_map.wrap, crate_map.filter), ([Wrap::Repeat; 2], Filter::SMOOTH));

    let ctx = Validated::new();
    let probes = TechniqueDesc::Probes {
        probes: ProbeSettings {
            placement: ProbePlacement::Grid([3, 2, 3]),
            capture: CaptureSettings { cube_size: 8, samples: 16, ..Default::default() },
            ..Default::default()
        },
        prt: PrtParams::DEFAULT,
    };
    let render = |technique: TechniqueDesc, time: f32| {
        let options = RenderOptions { width: 96, height: 72, technique, transfer: None };
        let mut renderer = Renderer::new(&ctx, &scene, &options).unwrap();
        renderer.set_time(time).unwrap();
        renderer.render().unwrap();
        renderer.image().unwrap().pixels
    };
    // The pixels the probes light: those that differ from the unshadowed picture, whose static
    // groups the probes technique lights unshadowed too. Their mean column follows Suzanne.
    let probe_lit_column = |time: f32| {
        let (lit, plain) = (render(probes.clone(), time), render(TechniqueDesc::Unshadowed, time));
        let columns: Vec<usize> =
            lit.iter().zip(&plain).enumerate().filter(|(_, (a, b))| a != b).map(|(i, _)| i % 96).collect();
        assert!(columns.len() > 30, "at {time} s only {} pixels are lit by the probes", columns.len());
        assert!(columns.len() < 96 * 72 / 10, "at {time} s the probes light {} pixels", columns.len());
        columns.iter().sum::<usize>() as f32 / columns.len() as f32
    };
    // From x = −1.5 at 0 s to −0.25 at 1 s: about 20 columns to the right.
    let (start, end) = (probe_lit_column(0.0), probe_lit_column(1.0));
    assert!(end > start + 10.0, "Suzanne moves right across the picture: column {start} -> {end}");
}
