//! Scene input: every kind of bad file gives an error naming the file and the problem (never a
//! panic), and an exported scene reads back identical. No GPU needed.
use std::path::{Path, PathBuf};

use glam::Vec3;
use kage::scene::{Light, ProbeRole, Scene, SceneFormat, BUILTIN};

/// A fresh, empty folder under the system temp dir, unique to this process and test.
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kage-scene-input-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const CAMERA: &str = r#""camera": {"position": [0, 2, 6], "target": [0, 0.5, 0], "fov_y_deg": 40}"#;
const ENVIRONMENT: &str = r#""environment": {"constant": [1, 1, 1]}"#;
const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// A scene file with one group holding `meshes`, plus any extra top-level entries.
fn scene_json(group_extra: &str, meshes: &str, top_extra: &str) -> String {
    format!(
        r#"{{{CAMERA}, {ENVIRONMENT}{top_extra},
            "groups": [{{"name": "g"{group_extra}, "meshes": [{meshes}]}}]}}"#
    )
}

fn write(dir: &Path, name: &str, contents: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

fn write_exr(dir: &Path, name: &str, width: usize, height: usize, value: [f32; 3]) -> PathBuf {
    let path = dir.join(name);
    exr::prelude::write_rgb_file(&path, width, height, |x, y| {
        if (x, y) == (1, 1) {
            (value[0], value[1], value[2])
        } else {
            (1.0f32, 1.0f32, 1.0f32)
        }
    })
    .unwrap();
    path
}

/// Loads `scene` and checks that the error names `blamed` (a file name) and says `problem`.
#[track_caller]
fn assert_rejected(scene: &Path, blamed: &str, problem: &str) {
    match Scene::load(scene) {
        Ok(_) => panic!("{} loaded, but should fail with {problem:?}", scene.display()),
        Err(e) => {
            let message = e.to_string();
            assert!(message.contains(blamed), "{message:?} does not name {blamed:?}");
            assert!(message.contains(problem), "{message:?} does not say {problem:?}");
        }
    }
}

#[test]
fn missing_files_are_named() {
    let dir = temp_dir("missing");
    assert_rejected(&dir.join("nowhere.json"), "nowhere.json", "cannot read");
    let scene =
        write(&dir, "scene.json", &scene_json("", r#"{"obj": "absent.obj", "albedo": [0.5, 0.5, 0.5]}"#, ""));
    assert_rejected(&scene, "absent.obj", "cannot read");
    let scene = write(
        &dir,
        "env.json",
        &scene_json("", r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#, "")
            .replace(r#"{"constant": [1, 1, 1]}"#, r#"{"image": "absent.exr"}"#),
    );
    assert_rejected(&scene, "absent.exr", "cannot read");
}

#[test]
fn bad_obj_files_are_rejected() {
    let dir = temp_dir("obj");
    let cases = [
        ("malformed.obj", "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n", "malformed"),
        ("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "NaN"),
        ("infinite.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n", "infinite"),
        ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "out of"),
        ("empty.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles"),
    ];
    for (file, contents, problem) in cases {
        write(&dir, file, contents);
        let mesh = format!(r#"{{"obj": "{file}", "albedo": [0.5, 0.5, 0.5]}}"#);
        let scene = write(&dir, &format!("{file}.json"), &scene_json("", &mesh, ""));
        assert_rejected(&scene, file, problem);
        // The scene file that referred to the OBJ is named too.
        assert_rejected(&scene, &format!("{file}.json"), problem);
    }
}

#[test]
fn bad_environment_images_are_rejected() {
    let dir = temp_dir("env");
    write_exr(&dir, "square.exr", 4, 4, [1.0; 3]);
    write_exr(&dir, "nan.exr", 4, 2, [1.0, f32::NAN, 1.0]);
    write_exr(&dir, "inf.exr", 4, 2, [f32::INFINITY, 1.0, 1.0]);
    write(&dir, "env.png", "not an image");
    write(&dir, "garbage.exr", "not an image");
    let cases = [
        ("square.exr", "2:1"),
        ("nan.exr", "NaN"),
        ("inf.exr", "infinite"),
        ("env.png", "unsupported"),
        ("garbage.exr", "OpenEXR"),
    ];
    for (file, problem) in cases {
        let json =
            scene_json("", r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#, "")
                .replace(r#"{"constant": [1, 1, 1]}"#, &format!(r#"{{"image": "{file}"}}"#));
        let scene = write(&dir, &format!("{file}.json"), &json);
        assert_rejected(&scene, file, problem);
    }
}

#[test]
fn negative_pixels_are_clamped_and_counted() {
    let dir = temp_dir("negative");
    let path = write_exr(&dir, "negative.exr", 4, 2, [-1.0, 0.5, -2.0]);
    let map = kage::scene::EnvMap::load(&path).unwrap();
    assert_eq!(map.pixels()[4 + 1], [0.0, 0.5, 0.0]);
    assert_eq!(map.clamped_negative(), 2);
}

#[test]
fn radiance_hdr_files_load_and_are_checked() {
    let dir = temp_dir("hdr");
    // Uncompressed RGBE (rows narrower than 8 pixels are never run-length encoded);
    // (128, 128, 128, 129) encodes 1.0 in each channel.
    let hdr = |width: usize, height: usize| {
        let mut bytes =
            format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n").into_bytes();
        for _ in 0..width * height {
            bytes.extend([128, 128, 128, 129]);
        }
        bytes
    };
    std::fs::write(dir.join("good.hdr"), hdr(4, 2)).unwrap();
    std::fs::write(dir.join("square.hdr"), hdr(4, 4)).unwrap();
    let map = kage::scene::EnvMap::load(&dir.join("good.hdr")).unwrap();
    assert_eq!((map.width(), map.height()), (4, 2));
    assert!(map.pixels().iter().all(|p| *p == [1.0; 3]), "{:?}", map.pixels()[0]);
    let message = kage::scene::EnvMap::load(&dir.join("square.hdr")).unwrap_err().to_string();
    assert!(message.contains("square.hdr") && message.contains("2:1"), "{message}");
}

#[test]
fn bad_scene_values_are_rejected() {
    let dir = temp_dir("values");
    let sphere = r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#;
    let cases = [
        ("syntax", "{\"camera\": ".to_string(), "line"),
        ("unknown-top", scene_json("", sphere, r#", "fog": 1"#), "unknown field `fog`"),
        ("unknown-group", scene_json(r#", "colour": 1"#, sphere, ""), "unknown field `colour`"),
        (
            "unknown-mesh",
            scene_json(
                "",
                r#"{"sphere": {"radius": 1, "segments": 8, "rings": 3}, "albedo": [1, 1, 1]}"#,
                "",
            ),
            "unknown field `rings`",
        ),
        ("zero-scale", scene_json(r#", "scale": 0"#, sphere, ""), "scale"),
        (
            "zero-exposure",
            scene_json("", sphere, r#", "exposure": 0"#),
            "exposure 0 is not a positive number",
        ),
        (
            "negative-exposure",
            scene_json("", sphere, r#", "exposure": -1"#),
            "exposure -1 is not a positive number",
        ),
        ("negative-scale", scene_json(r#", "scale": -2"#, sphere, ""), "scale"),
        ("infinite-translation", scene_json(r#", "translation": [0, 1e39, 0]"#, sphere, ""), "translation"),
        ("infinite-rotation", scene_json(r#", "rotation_deg": [1e39, 0, 0]"#, sphere, ""), "rotation"),
        (
            "albedo",
            scene_json("", r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 1.5, 0.5]}"#, ""),
            "albedo",
        ),
        (
            "two-shapes",
            scene_json(
                "",
                r#"{"sphere": {"radius": 1, "segments": 8}, "obj": "a.obj", "albedo": [1, 1, 1]}"#,
                "",
            ),
            "exactly one",
        ),
        ("no-meshes", scene_json("", "", ""), "no meshes"),
        (
            "plane",
            scene_json("", r#"{"plane": {"size": [1, 1], "vertices": [1, 5]}, "albedo": [1, 1, 1]}"#, ""),
            "plane vertices",
        ),
        (
            "spot-fov",
            scene_json(
                "",
                sphere,
                r#", "lights": [{"spot": {"position": [0, 3, 0], "direction": [0, -1, 0], "fov_deg": 171, "intensity": [1, 1, 1]}}]"#,
            ),
            "fov_deg",
        ),
        (
            "spot-direction",
            scene_json(
                "",
                sphere,
                r#", "lights": [{"spot": {"position": [0, 3, 0], "direction": [0, 0, 0], "fov_deg": 60, "intensity": [1, 1, 1]}}]"#,
            ),
            "direction",
        ),
        ("light-kind", scene_json("", sphere, r#", "lights": [{"area": {}}]"#), "unknown variant `area`"),
        (
            "env-intensity",
            scene_json("", sphere, "")
                .replace(r#""constant": [1, 1, 1]"#, r#""constant": [1, 1, 1], "intensity": -1"#),
            "intensity",
        ),
    ];
    for (name, json, problem) in cases {
        let file = format!("{name}.json");
        assert_rejected(&write(&dir, &file, &json), &file, problem);
    }
}

#[test]
fn bad_cameras_are_rejected() {
    let dir = temp_dir("camera");
    let sphere = r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#;
    let cases = [
        ("same-point", r#""position": [1, 2, 3], "target": [1, 2, 3], "fov_y_deg": 40"#, "same point"),
        ("zero-up", r#""position": [0, 2, 6], "target": [0, 0, 0], "up": [0, 0, 0], "fov_y_deg": 40"#, "up"),
        ("fov-zero", r#""position": [0, 2, 6], "target": [0, 0, 0], "fov_y_deg": 0"#, "fov_y_deg"),
        ("fov-180", r#""position": [0, 2, 6], "target": [0, 0, 0], "fov_y_deg": 180"#, "fov_y_deg"),
        ("infinite", r#""position": [0, 1e39, 6], "target": [0, 0, 0], "fov_y_deg": 40"#, "not finite"),
    ];
    for (name, camera, problem) in cases {
        let json = scene_json("", sphere, "").replace(
            r#""camera": {"position": [0, 2, 6], "target": [0, 0.5, 0], "fov_y_deg": 40}"#,
            &format!(r#""camera": {{{camera}}}"#),
        );
        let file = format!("{name}.json");
        assert_rejected(&write(&dir, &file, &json), &file, problem);
    }
}

#[test]
fn a_full_scene_file_loads() {
    let dir = temp_dir("full");
    write(&dir, "tri.obj", TRIANGLE_OBJ);
    let meshes = r#"{"obj": "tri.obj", "albedo": [0.8, 0.8, 0.8]},
                    {"plane": {"size": [10, 10], "vertices": [3, 4]}, "albedo": [0.6, 0.6, 0.6]},
                    {"name": "ball", "sphere": {"radius": 1, "segments": 16}, "albedo": [0.5, 0.5, 0.5]}"#;
    let lights = r#", "lights": [{"point": {"position": [0, 3, 0], "intensity": [5, 5, 5]}},
        {"spot": {"position": [2, 3, 0], "direction": [0, -2, 0], "fov_deg": 170, "intensity": [9, 9, 9]}}]"#;
    let path =
        write(&dir, "full.json", &scene_json(r#", "rotation_deg": [0, 90, 0], "scale": 2"#, meshes, lights));
    let scene = Scene::from_arg(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.name, "full");
    let group = &scene.groups[0];
    let names: Vec<_> = group.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["tri", "plane", "ball"]);
    assert_eq!(group.meshes[1].vertex_count(), 12);
    let turned = group.transform.matrix().transform_vector3(glam::Vec3::Z);
    assert!((turned - glam::Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5);
    assert_eq!(scene.lights.len(), 2);
    if let kage::scene::Light::Spot { direction, .. } = scene.lights[1] {
        assert_eq!(direction, glam::Vec3::NEG_Y);
    }
}

#[test]
fn built_in_scenes_are_listed_and_unknown_names_rejected() {
    assert_eq!(BUILTIN[0], "teapot");
    let message = Scene::from_arg("no-such-scene").unwrap_err().to_string();
    assert!(BUILTIN.iter().all(|name| message.contains(name)), "{message}");
    // A folder without a scene file is the folder's fault: the answer names it and lists the
    // built-ins, never "is a directory".
    let empty = temp_dir("no-scene-file");
    let error = Scene::from_arg(empty.to_str().unwrap()).unwrap_err();
    assert_eq!(error.file(), Some(empty.as_path()));
    let message = error.to_string();
    assert!(BUILTIN.iter().all(|name| message.contains(name)), "{message}");
    assert!(!message.contains("directory"), "{message}");
    let hires = Scene::builtin("teapot-hires-floor").unwrap();
    let floor = hires.groups.iter().find(|g| g.name == "floor").unwrap();
    assert_eq!(floor.meshes[0].vertex_count(), 111 * 111);
}

#[test]
fn exported_builtins_read_back_identical() {
    let teapot = Scene::builtin("teapot").unwrap();
    let floor = teapot.groups.iter().find(|g| g.name == "floor").unwrap();
    assert_eq!(floor.meshes[0].vertex_count(), 31 * 31);
    // The asm scene adds box meshes, a spot light and a camera walkthrough; probe-room its
    // exposure.
    let room = Scene::builtin("probe-room").unwrap();
    assert_eq!((teapot.exposure, room.exposure), (1.0, 4.0));
    // The same three written with their geometry as glTF; one more with several meshes in a
    // group, coloured lights and a motion that grows and does not start at 0.
    let mut atrium = Scene::builtin("atrium").unwrap();
    atrium.lights = vec![
        Light::Point { position: Vec3::new(0.3, 2.0, -0.7), intensity: [3.0, 1.7, 0.1] },
        Light::Spot {
            position: Vec3::new(1.0, 3.0, 0.5),
            direction: Vec3::new(-0.3, -1.0, 0.2).normalize(),
            fov_deg: 47.3,
            intensity: [0.2, 0.9, 5.0],
        },
    ];
    let motion = atrium.groups.iter_mut().find_map(|g| g.motion.as_mut()).unwrap();
    motion.keys.remove(0);
    motion.keys[3].scale *= 1.5;
    assert!(atrium.groups.iter().any(|g| g.meshes.len() > 1));
    let formats = [SceneFormat::Json, SceneFormat::Gltf];
    let cases = [teapot, Scene::builtin("asm").unwrap(), room];
    let cases = formats.iter().flat_map(|f| cases.iter().map(move |s| (*f, s.clone())));
    for (format, scene) in cases.chain([(SceneFormat::Gltf, atrium)]) {
        let dir = temp_dir(&format!("export-{}-{format:?}", scene.name));
        scene.export(&dir, format).unwrap();
        let back = Scene::load(&dir.join(kage::scene::SCENE_FILE)).unwrap();
        // The folder as a --scene argument is its scene file.
        assert!(Scene::from_arg(dir.to_str().unwrap()).unwrap() == back);
        // Field by field first, so a failure says what differs; then everything at once.
        assert_eq!(back.name, scene.name);
        assert_eq!(back.camera, scene.camera);
        assert_eq!(back.lights, scene.lights);
        assert_eq!(back.walkthrough, scene.walkthrough);
        assert_eq!(back.exposure, scene.exposure);
        for (a, b) in back.groups.iter().zip(&scene.groups) {
            assert_eq!((&a.name, a.transform), (&b.name, b.transform));
            for (m, n) in a.meshes.iter().zip(&b.meshes) {
                assert_eq!(m.name, n.name);
                assert_eq!(m.albedo, n.albedo);
                assert!(m.positions == n.positions, "positions of {} differ", m.name);
                assert!(m.normals == n.normals, "normals of {} differ", m.name);
                assert!(m.indices == n.indices, "indices of {} differ", m.name);
            }
        }
        assert!(back.environment == scene.environment, "environment pixels differ");
        if scene.name == "atrium" {
            // The motion that starts after 0 comes back with a key at 0 (its pose there).
            let motion_of = |s: &Scene| s.groups.iter().find_map(|g| g.motion.clone()).unwrap();
            let (a, b) = (motion_of(&back), motion_of(&scene));
            assert_eq!(a.keys[1..], b.keys[..]);
            assert_eq!((a.keys[0].time, a.loop_seconds), (0.0, b.loop_seconds));
            continue;
        }
        for (a, b) in back.groups.iter().zip(&scene.groups) {
            assert_eq!(a.motion, b.motion, "motion of {}", a.name);
        }
        assert!(back == scene, "{format:?}");
    }
}

/// Probes placed in a scene file, with and without a role, read in and export back identical;
/// an unknown role, an unknown field and a non-finite position are errors that say so.
#[test]
fn scene_file_probes_round_trip_and_bad_ones_are_named() {
    let dir = temp_dir("probes");
    write(&dir, "tri.obj", TRIANGLE_OBJ);
    let probes = r#", "probes": [{"position": [0, 1, 0], "role": "sky"}, {"position": [1, 0.5, -1]},
        {"position": [-1, 0.5, 1], "role": "bounce"}, {"position": [0, 0.2, 0], "role": "bleed"}]"#;
    let path = write(
        &dir,
        "scene.json",
        &scene_json("", r#"{"obj": "tri.obj", "albedo": [0.5, 0.5, 0.5]}"#, probes),
    );
    let scene = Scene::load(&path).unwrap();
    let roles: Vec<_> = scene.probes.iter().map(|p| p.role).collect();
    assert_eq!(roles, [Some(ProbeRole::Sky), None, Some(ProbeRole::Bounce), Some(ProbeRole::Bleed)]);
    assert_eq!(scene.probes[1].position, glam::Vec3::new(1.0, 0.5, -1.0));
    let out = dir.join("export");
    scene.export(&out, SceneFormat::Json).unwrap();
    let back = Scene::load(&out.join(kage::scene::SCENE_FILE)).unwrap();
    assert_eq!(back.probes, scene.probes);

    for (extra, expected) in [
        (r#", "probes": [{"position": [0, 1, 0], "role": "fill"}]"#, "unknown variant `fill`"),
        (r#", "probes": [{"position": [0, 1, 0], "radius": 2}]"#, "unknown field `radius`"),
        (r#", "probes": [{"position": [0, 1e39, 0]}]"#, "probe 0"),
    ] {
        let path = write(
            &dir,
            "bad.json",
            &scene_json("", r#"{"obj": "tri.obj", "albedo": [0.5, 0.5, 0.5]}"#, extra),
        );
        let error = Scene::load(&path).unwrap_err().to_string();
        assert!(error.contains(expected), "{extra}: {error}");
    }
}

/// A group's keyframes in a scene file: read, sampled (exact at keys, linear and slerped
/// between, looped), written back by export identical; bad ones named with the file, the group
/// and the key.
#[test]
fn keyframes_in_a_scene_file_move_their_group_and_bad_ones_are_named() {
    let dir = temp_dir("keyframes");
    let sphere = r#"{"sphere": {"radius": 0.5, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#;
    let keys = r#", "keyframes": [
        {"time": 0, "translation": [0, 1, 0]},
        {"time": 2, "translation": [4, 1, 0], "rotation_deg": [0, 90, 0]}], "loop_seconds": 4"#;
    let path = write(&dir, "moving.json", &scene_json(keys, sphere, ""));
    let scene = Scene::load(&path).unwrap();
    let group = &scene.groups[0];
    assert_eq!(scene.duration(), 4.0);
    assert_eq!(group.pose_at(2.0).translation, Vec3::new(4.0, 1.0, 0.0));
    let half = group.pose_at(1.0);
    assert!((half.translation - Vec3::new(2.0, 1.0, 0.0)).length() < 1e-6);
    assert!(half.rotation.abs_diff_eq(glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_4), 1e-5));
    // Looped: from the last key back to the first over the remaining two seconds.
    assert!((group.pose_at(3.0).translation.x - 2.0).abs() < 1e-6);
    assert_eq!(group.pose_at(4.0), group.pose_at(0.0));
    // Export writes the keyframes back.
    let out = temp_dir("keyframes-export");
    scene.export(&out, SceneFormat::Json).unwrap();
    let back = Scene::load(&out.join(kage::scene::SCENE_FILE)).unwrap();
    assert_eq!(back.groups[0].motion, scene.groups[0].motion);
    let cases = [
        (
            r#", "keyframes": [{"time": 1, "translation": [0, 0, 0]}, {"time": 1, "translation": [1, 0, 0]}]"#,
            "keyframe 1: time 1 does not come after",
        ),
        (
            r#", "keyframes": [{"time": 0, "translation": [0, 0, 0], "rotation_deg": [0, 0, 0], "rotation_quat": [0, 0, 0, 1]}]"#,
            "keyframe 0: give either",
        ),
        (
            r#", "keyframes": [{"time": 0, "translation": [0, 0, 0], "rotation_quat": [0, 0, 0, 3]}]"#,
            "not a unit quaternion",
        ),
        (
            r#", "keyframes": [{"time": 0, "translation": [0, 0, 0]}, {"time": 3, "translation": [0, 0, 0]}], "loop_seconds": 2"#,
            "loop_seconds 2",
        ),
        (r#", "loop_seconds": 2"#, "loop_seconds without keyframes"),
        (r#", "keyframes": [{"time": 0, "translation": [0, 0, 0], "scale": 0}]"#, "keyframe 0: scale 0"),
        (r#", "keyframes": [{"time": 0, "translation": [0, 0, 0], "size": 2}]"#, "unknown field `size`"),
    ];
    for (k, (extra, problem)) in cases.iter().enumerate() {
        let file = format!("bad{k}.json");
        let path = write(&dir, &file, &scene_json(extra, sphere, ""));
        assert_rejected(&path, &file, problem);
        let message = Scene::load(&path).unwrap_err().to_string();
        assert!(message.contains("group 0") || message.contains("unknown field"), "{message}");
    }
}

/// `environment` is optional: a scene file without one is lit by the default sky (the same as a
/// glTF file alone gets) and says so; one with it, a built-in scene and an export (which always
/// writes the environment) do not, and the export reads back as the same scene.
#[test]
fn a_scene_file_without_environment_is_lit_by_the_default_sky() {
    let dir = temp_dir("no-environment");
    let sphere = r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#;
    let bare = write(
        &dir,
        "bare.json",
        &format!(r#"{{{CAMERA}, "groups": [{{"name": "g", "meshes": [{sphere}]}}]}}"#),
    );
    let loaded = Scene::read(&bare).unwrap();
    assert!(loaded.default_environment);
    let sky = kage::scene::EnvMap::constant([kage::scene::DEFAULT_SKY; 3]);
    assert_eq!(loaded.scene.environment, sky);
    let given = write(&dir, "given.json", &scene_json("", sphere, ""));
    let given = Scene::read_arg(given.to_str().unwrap()).unwrap();
    assert!(!given.default_environment && given.scene.environment == sky, "given, if equal");
    assert!(!Scene::read_arg("teapot").unwrap().default_environment);
    let out = dir.join("exported");
    loaded.scene.export(&out, kage::scene::SceneFormat::Json).unwrap();
    let back = Scene::read(&out.join(kage::scene::SCENE_FILE)).unwrap();
    assert!(!back.default_environment);
    assert_eq!(back.scene, loaded.scene);
}

/// The vendored scanned bunny (tests/assets/bunny/): 1,839 vertices with normals, vertex 1's
/// `vn 0 0 0`.
fn bunny_obj() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny/bunny.obj")
}

/// The area-weighted normal of the triangles around the vertex at `at` (what a repaired normal
/// must be), and the normals of the other vertices of those triangles.
fn around(mesh: &kage::scene::Mesh, at: usize) -> (Vec3, Vec<Vec3>) {
    let mut sum = Vec3::ZERO;
    let mut neighbours = Vec::new();
    for tri in mesh.indices.chunks_exact(3).filter(|t| t.contains(&(at as u32))) {
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[tri[k] as usize]));
        sum += (b - a).cross(c - a);
        neighbours
            .extend(tri.iter().filter(|&&i| i as usize != at).map(|&i| Vec3::from(mesh.normals[i as usize])));
    }
    (sum.normalize(), neighbours)
}

/// An OBJ given straight to `--scene` is a scene: the mesh at rest in one group, albedo 0.8,
/// the constant sky of radiance 1, the whole model in view, no ground; the bunny's zero normal
/// is recomputed from its faces and the file's other normals kept.
#[test]
fn a_scanned_obj_with_a_zero_normal_loads_alone_repaired() {
    let path = bunny_obj();
    let scene = Scene::from_arg(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.name, "bunny");
    assert_eq!(scene.groups.len(), 1, "no ground is added");
    let group = &scene.groups[0];
    assert!(group.motion.is_none() && group.transform == kage::scene::Transform::default());
    assert_eq!(group.meshes.len(), 1);
    let mesh = &group.meshes[0];
    assert_eq!(mesh.vertex_count(), 1839);
    assert_eq!(mesh.albedo, kage::scene::LONE_OBJ_ALBEDO);
    assert_eq!(mesh.albedo, [0.8; 3]);
    assert_eq!(scene.environment, kage::scene::EnvMap::constant([1.0; 3]));
    assert!(scene.lights.is_empty() && scene.walkthrough.is_empty() && scene.probes.is_empty());
    assert_eq!(scene.camera, kage::scene::gltf::overview(&scene.groups));
    // Every vertex is in front of the camera and inside its view.
    let view_projection = scene.camera.projection(1.0) * scene.camera.view();
    for p in &mesh.positions {
        let clip = view_projection * Vec3::from(*p).extend(1.0);
        let ndc = clip.truncate() / clip.w;
        assert!(clip.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{p:?} is out of view");
    }

    let at = mesh.positions.iter().position(|p| *p == [1.301895, 0.122622, 2.550061]).unwrap();
    let repaired = Vec3::from(mesh.normals[at]);
    assert!((repaired.length() - 1.0).abs() < 1e-6, "{repaired}");
    let (faces, neighbours) = around(mesh, at);
    assert!(repaired.dot(faces) > 1.0 - 1e-5, "{repaired} is not its faces' normal {faces}");
    assert!(neighbours.len() >= 4);
    for n in neighbours {
        assert!(repaired.dot(n) > 0.8, "{repaired} is far from its neighbour's normal {n}");
    }
    // The file's other normals are its own (6 decimals), not recomputed ones.
    let second = mesh.positions.iter().position(|p| *p == [1.045326, 0.139058, 2.835156]).unwrap();
    let given = Vec3::new(-0.043332, -0.999055, -0.003240);
    assert!(Vec3::from(mesh.normals[second]).distance(given.normalize()) < 1e-6);

    // The extension in any case; the same scene through Scene::load.
    let dir = temp_dir("obj-alone");
    let upper = dir.join("BUNNY.OBJ");
    std::fs::copy(&path, &upper).unwrap();
    let loud = Scene::load(&upper).unwrap();
    assert_eq!(loud.groups[0].meshes[0].normals, mesh.normals);
}

/// A NaN or infinite normal in an OBJ is repaired like a zero one.
#[test]
fn non_finite_obj_normals_are_repaired() {
    let dir = temp_dir("obj-nan-normal");
    let obj = "v 0 0 0\nv 1 0 0\nv 0 0 -1\nv 1 0 -1\nvn nan 0 1\nvn 0 1 0\nvn 0 inf 0\nvn 0 1 0\n\
               f 1//1 2//2 3//3\nf 2//2 4//4 3//3\n";
    let path = write(&dir, "nan-normal.obj", obj);
    let scene = Scene::from_arg(path.to_str().unwrap()).unwrap();
    let normals = &scene.groups[0].meshes[0].normals;
    assert_eq!(normals, &vec![[0.0, 1.0, 0.0]; 4]);
}

/// An OBJ read alone that cannot be read is an error naming it, never JSON's or a built-in
/// scene's.
#[test]
fn bad_obj_files_alone_are_errors_naming_them() {
    let dir = temp_dir("obj-alone-bad");
    let cases = [
        ("malformed.obj", "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n", "malformed"),
        ("range.Obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "out of"),
        ("empty.obj", "", "no triangles"),
    ];
    for (file, contents, problem) in cases {
        let path = write(&dir, file, contents);
        let message = Scene::from_arg(path.to_str().unwrap()).unwrap_err().to_string();
        assert!(message.contains(file) && message.contains(problem), "{message}");
        assert!(!message.contains("JSON"), "{message}");
    }
    let missing = dir.join("absent.OBJ");
    let message = Scene::from_arg(missing.to_str().unwrap()).unwrap_err().to_string();
    assert!(message.contains("absent.OBJ") && message.contains("cannot read"), "{message}");
}

/// The C ABI reads a lone OBJ as `--scene` does (a bad one is `KAGE_RESULT_FILE`), and repairs
/// a NaN or zero normal in the host's arrays instead of refusing the scene.
#[test]
fn the_c_abi_loads_a_lone_obj_and_repairs_normals() {
    use kage::capi::{self, kage_result};
    use std::ptr::{null, null_mut};
    let path = std::ffi::CString::new(bunny_obj().to_str().unwrap()).unwrap();
    let mut scene = null_mut();
    // SAFETY: a NUL-terminated path and a writable out-handle.
    assert_eq!(unsafe { capi::scene::kage_scene_load(path.as_ptr(), &mut scene) }, kage_result::Ok);
    let mut count = 0;
    // SAFETY: a live handle and a writable count.
    assert_eq!(unsafe { capi::scene::kage_scene_group_count(scene, &mut count) }, kage_result::Ok);
    assert_eq!(count, 1);
    assert_eq!(capi::scene::kage_scene_destroy(scene), kage_result::Ok);

    let dir = temp_dir("capi-obj");
    let bad = write(&dir, "bad.obj", "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n");
    let bad = std::ffi::CString::new(bad.to_str().unwrap()).unwrap();
    // SAFETY: as above.
    assert_eq!(unsafe { capi::scene::kage_scene_load(bad.as_ptr(), &mut scene) }, kage_result::File);
    assert!(scene.is_null());

    let positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0f32];
    let normals = [f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0f32];
    let indices = [0, 1, 2u32];
    let mesh = capi::scene::kage_mesh_desc {
        positions: positions.as_ptr(),
        normals: normals.as_ptr(),
        vertex_count: 3,
        indices: indices.as_ptr(),
        index_count: 3,
        albedo: [0.5; 3],
    };
    let group = capi::scene::kage_group_desc {
        name: null(),
        transform: capi::scene::kage_transform {
            translation: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            scale: 1.0,
        },
        meshes: &mesh,
        mesh_count: 1,
    };
    let sky = [1.0f32; 3 * 8 * 4];
    let desc = capi::scene::kage_scene_desc {
        size: std::mem::size_of::<capi::scene::kage_scene_desc>() as u32,
        groups: &group,
        group_count: 1,
        environment: capi::scene::kage_environment_desc { pixels: sky.as_ptr(), width: 8, height: 4 },
        camera: capi::scene::kage_camera_desc {
            position: [0.0, 1.0, 2.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 60.0,
        },
        lights: null(),
        light_count: 0,
    };
    // SAFETY: the desc's arrays hold the counts it states and outlive the call.
    assert_eq!(unsafe { capi::scene::kage_scene_create(&desc, &mut scene) }, kage_result::Ok);
    assert_eq!(capi::scene::kage_scene_destroy(scene), kage_result::Ok);
}
