//! The `kage` program as a user runs it: outputs, timings, and errors for bad input.
use kage_tests::scratch_dir;
use std::process::{Command, Output};

fn kage(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kage")).args(args).output().expect("run kage")
}

fn text(output: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr))
}

/// `kage … | head -1`: output into a closed pipe ends the program quietly (SIGPIPE), never with
/// a panic.
#[cfg(unix)]
#[test]
fn a_closed_pipe_ends_the_program_quietly() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_kage"))
        .args(["info"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run kage");
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}: {stderr}", out.status);
}

#[test]
fn render_writes_png_exr_and_timings() {
    let dir = scratch_dir("cli-render");
    let png = dir.join("teapot.png");
    let exr = dir.join("teapot.exr");
    let timings = dir.join("timings.json");
    // The default technique is Tamura's: its transfer goes to the cache given here.
    let cache = dir.join("cache");
    let cache = cache.to_str().unwrap();
    let out = kage(&[
        "render",
        "--validate",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "2",
        "--cache",
        cache,
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(text(&out).contains("transfer: computed"), "{}", text(&out));
    assert!(out.status.success(), "{}", text(&out));
    let out = kage(&[
        "render",
        "--validate",
        "--width",
        "64",
        "--height",
        "48",
        "--cache",
        cache,
        // No warm-up: the one-time passes of the first frame are in the table too.
        "--warmup",
        "0",
        "--out",
        exr.to_str().unwrap(),
        "--timings",
        timings.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));

    let exr_image = kage::imageio::read_exr(&exr).unwrap();
    assert_eq!((exr_image.width, exr_image.height), (64, 48));
    let png_bytes = std::fs::read(&png).unwrap();
    assert_eq!(&png_bytes[1..4], b"PNG");

    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&timings).unwrap()).unwrap();
    assert_eq!(json["frames"], 1);
    assert!(json["device"].as_str().is_some_and(|d| !d.is_empty()));
    let passes = json["passes"].as_array().unwrap();
    let names: Vec<&str> = passes.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "sh_project",
            "sh_reduce",
            "background",
            "self_shadow",
            "occluder_masks",
            "blur_horizontal",
            "blur_vertical",
            "depth_prepass",
            "scene",
            "readback"
        ]
    );
    for pass in passes {
        for key in ["median_ms", "min_ms", "max_ms"] {
            assert!(pass[key].as_f64().is_some_and(|ms| ms > 0.0), "{pass}");
        }
    }
    assert!(json["frame_median_ms"].as_f64().is_some_and(|ms| ms > 0.0));
    // The render call waits for its passes: its wall clock holds their GPU time.
    assert!(json["frame_wall_median_ms"].as_f64() >= json["frame_median_ms"].as_f64(), "{json}");
}

#[test]
fn sh_prints_coefficients_and_irradiance() {
    let dir = scratch_dir("cli-sh");
    let map = dir.join("constant.exr");
    kage::scene::EnvMap::from_pixels(256, 128, vec![[1.0; 3]; 256 * 128]).unwrap().write_exr(&map).unwrap();
    let out = kage(&["sh", map.to_str().unwrap(), "--irradiance", "0,1,0", "--validate"]);
    assert!(out.status.success(), "{}", text(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        stdout.lines().filter(|l| !l.starts_with('#') && !l.starts_with("irradiance")).count(),
        9,
        "{stdout}"
    );
    // Radiance 1 everywhere: E = pi for every normal.
    let e: f32 = stdout
        .lines()
        .find(|l| l.starts_with("irradiance"))
        .unwrap()
        .split_whitespace()
        .rev()
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    assert!((e - std::f32::consts::PI).abs() < 1e-3, "{stdout}");
}

/// Each command fails with exit code 1 and a `kage: error:` line containing the expected text,
/// without a panic.
/// The conventional shadow map of the `asm` scene against the local-light reference through
/// the CLI: render, reference and `compare --shadow-mismatch`; the teapot (no local light) is a
/// clear error for the technique.
#[test]
fn shadowmap_against_the_local_reference_reports_the_mismatch() {
    let dir = scratch_dir("cli-shadowmap");
    let (map, truth, ties) = (dir.join("sm.exr"), dir.join("ref.exr"), dir.join("ties.exr"));
    let size = ["--scene", "asm", "--width", "48", "--height", "48", "--validate"];
    let out = kage(
        &[
            &["render", "--technique", "shadowmap", "--shadowmap-size", "1024"],
            &size[..],
            &["--out", map.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let out = kage(
        &[
            &["reference", "--light", "local", "--spp", "1"],
            &size[..],
            &["--out", truth.to_str().unwrap(), "--edges", ties.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(out.status.success() && text(&out).contains("edge ties at 1/"), "{}", text(&out));
    let compare = |edges: &[&str]| {
        let out = kage(
            &[&["compare", map.to_str().unwrap(), truth.to_str().unwrap(), "--shadow-mismatch"], edges]
                .concat(),
        );
        let all = text(&out);
        let line = all.lines().find(|l| l.starts_with("shadow mismatch")).unwrap_or_else(|| panic!("{all}"));
        let differing: usize =
            line.split('(').nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap();
        let fraction: f64 = line.split_whitespace().nth(2).unwrap().parse().unwrap();
        assert!((0.0..0.05).contains(&fraction), "{line}");
        let ties =
            all.lines().find(|l| l.starts_with("edge ties")).unwrap_or_else(|| panic!("{all}")).to_string();
        (differing, ties)
    };
    // The ties are counted apart: together with the mismatches they are what the comparison
    // without them counts.
    let (all, none) = compare(&[]);
    assert!(none.contains("no --edges"), "{none}");
    let (apart, ties_line) = compare(&["--edges", ties.to_str().unwrap()]);
    let ties: usize = ties_line.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert_eq!(apart + ties, all, "{ties_line}");
    assert_clear_errors(&[
        (&["render", "--technique", "shadowmap", "--width", "8", "--height", "8"], "point or spot lights"),
        (
            &[
                "compare",
                map.to_str().unwrap(),
                truth.to_str().unwrap(),
                "--shadow-mismatch",
                "--shadow-threshold",
                "2",
            ],
            "between 0 and 1",
        ),
        (
            &["reference", "--scene", "asm", "--out", "x.exr", "--edges", "t.exr"],
            "--edges comes with --light local",
        ),
        (
            &["compare", map.to_str().unwrap(), truth.to_str().unwrap(), "--edges", map.to_str().unwrap()],
            "edge-tie image",
        ),
    ]);
}

fn assert_clear_errors(cases: &[(&[&str], &str)]) {
    for &(args, expected) in cases {
        let out = kage(args);
        let all = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {all}");
        assert!(all.contains("kage: error:") && all.contains(expected), "{args:?}: {all}");
        assert!(!all.contains("panicked"), "{args:?}: {all}");
    }
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    let dir = scratch_dir("cli-bad");
    let bad_scene = dir.join("bad.json");
    std::fs::write(&bad_scene, r#"{"camera": {"position": [0,0,1], "target": [0,0,0], "fov_y_deg": 40}, "environment": {"constant": [1,1,1]}, "groups": [], "colour": 1}"#).unwrap();
    let points = dir.join("points.json");
    std::fs::write(&points, r#"{"points": [{"position": [0, 0.5, 0], "normal": [0, 1, 0]}]}"#).unwrap();
    let (points, out_json) = (points.to_str().unwrap(), dir.join("e.json"));
    let no_samples = ["--bounces", "1", "--bounce-samples", "0", "--out", out_json.to_str().unwrap()];
    let cases: [(&[&str], &str); 21] = [
        // Outputs are checked before the work that would fill them (the reference's own write
        // would fail later with another message).
        (&["compare", "a.exr", "b.exr", "--diff", "d.jpg"], "--diff d.jpg: the file must end in .png"),
        (&["compare", "a.png", "b.exr"], "a.png: kage compare reads linear radiance from .exr files"),
        (&["reference", "--out", "/no/such/folder/r.exr"], "the folder /no/such/folder does not exist"),
        (&["reference", "--out", "/proc/r.exr"], "cannot write in the folder /proc"),
        (&["reference", "--exposure", "0", "--out", "r.png"], "--exposure must be a positive number"),
        (&[&["reference", "--irradiance", points][..], &no_samples[..]].concat(), "0 samples per vertex"),
        (&["render", "--scene", "no-such-scene"], "built-in scenes are"),
        (&["render", "--scene", "asm", "--keyframe", "5"], "scene asm has 5 walkthrough keyframes"),
        (&["reference", "--keyframe", "1", "--out", "x.exr"], "scene teapot has 0 walkthrough keyframes"),
        (&["render", "--scene", bad_scene.to_str().unwrap()], "colour"),
        (&["render", "--width", "0"], "image size"),
        (&["render", "--out", "picture.jpg", "--width", "8", "--height", "8"], "picture.jpg"),
        (&["sh", "/nonexistent/map.exr"], "/nonexistent/map.exr"),
        (&["sweep", "--technique", "prt", "--only", "tamura:3", "--out", "x"], "sloan-self:2, sloan-self:3"),
        (&["sweep", "--technique", "prt", "--poses", "nan", "--out", "x"], "--poses"),
        (&["sweep", "--technique", "prt", "--spp", "64", "--out", "x"], "runs each reference to --noise"),
        (
            &["sweep", "--technique", "prt", "--noise", "0", "--out", "x"],
            "--noise must be a positive fraction",
        ),
        (&["env", "sun", "--radius", "0", "--out", "x.exr"], "radius"),
        (&["sweep", "--technique", "prt", "--pick", "--out", "x"], "--pick needs a bound"),
        (&["sweep", "--technique", "asm", "--test-region", "box", "--out", "x"], "--test-region places"),
        (&["bench", "probe-count", "--scene", "probe-room", "--candidates", "1"], "grid level 1"),
    ];
    assert_clear_errors(&cases);
}

/// Files that lie or are not files, scene values out of range and a probe set that would
/// exhaust memory, through the program as a user runs it (the engine's own tests cover the
/// readers one by one): each a clear error naming the file or value, at once (a FIFO read
/// would hang: the harness's test timeout is the bound), never an abort.
#[cfg(unix)]
#[test]
fn hostile_files_and_values_are_clear_errors_through_the_program() {
    let dir = scratch_dir("cli-hostile");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let scene = |name: &str, groups: &str, extra: &str| {
        let json = format!(
            r#"{{"camera": {{"position": [0, 2, 6], "target": [0, 0.5, 0], "fov_y_deg": 40}},
                "environment": {{"constant": [1, 1, 1]}}, "groups": [{groups}]{extra}}}"#
        );
        std::fs::write(dir.join(name), json).unwrap();
        path(name)
    };
    let ball = r#"{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}"#;
    kage_tests::exr_declaring(&dir.join("huge.exr"), 65536, 32768);
    kage_tests::hdr_declaring(&dir.join("huge.hdr"), 65536, 32768);
    kage_tests::fifo(&dir.join("fifo.exr"));
    kage_tests::fifo(&dir.join("fifo.obj"));
    let (huge, huge_hdr, fifo_map) = (path("huge.exr"), path("huge.hdr"), path("fifo.exr"));
    let obj_scene = |name: &str, obj: &str| {
        scene(
            name,
            &format!(r#"{{"name": "g", "meshes": [{{"obj": {obj:?}, "albedo": [0.5, 0.5, 0.5]}}]}}"#),
            "",
        )
    };
    let fifo_obj = obj_scene("fifo-obj.json", &path("fifo.obj"));
    let zero_obj = obj_scene("zero-obj.json", "/dev/zero");
    let far = scene(
        "far.json",
        &format!(
            r#"{{"name": "near", "meshes": [{ball}]}}, {{"name": "far", "translation": [1e20, 0, 0], "meshes": [{ball}]}}"#
        ),
        "",
    );
    let through = scene(
        "through.json",
        &format!(r#"{{"name": "g", "meshes": [{ball}]}}"#),
        r#", "walkthrough": [{"position": [0, 1, 5], "target": [0, 1, 0], "fov_y_deg": 40},
                              {"position": [0, 1, -5], "target": [0, 1, 0], "fov_y_deg": 40}]"#,
    );
    // Probes on two skew lines: their Delaunay tetrahedra grow with the square of the count
    // (2 × 2500 would be about 6 million); the bound stops it in about a second.
    let line = |k: usize| {
        (0..2500).map(move |i| i as f32 / 2500.0).map(move |t| match k {
            0 => format!("[{t}, 0, 0]"),
            _ => format!("[0.5, 1, {t}]"),
        })
    };
    let positions: Vec<String> = line(0).chain(line(1)).collect();
    std::fs::write(dir.join("skew.json"), format!(r#"{{"positions": [{}]}}"#, positions.join(", "))).unwrap();
    let (skew, tetrahedra) = (path("skew.json"), path("tetrahedra.json"));
    let small = ["--width", "8", "--height", "8"];
    fn with<'a>(args: &[&'a str], small: &[&'a str]) -> Vec<&'a str> {
        [args, small].concat()
    }
    let declared = "65536x32768";
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec!["sh", &huge], vec![&huge, declared, "16384x8192"]),
        (vec!["sh", &huge_hdr], vec![&huge_hdr, declared]),
        (with(&["render", "--env", &huge], &small), vec![&huge, declared]),
        (vec!["compare", &huge, &huge], vec![&huge, declared]),
        (vec!["probes", "capture-image", &huge], vec![&huge, declared]),
        (vec!["sh", &fifo_map], vec![&fifo_map, "not a regular file"]),
        (with(&["render", "--scene", &fifo_obj], &small), vec!["fifo.obj", "not a regular file"]),
        (with(&["render", "--scene", &zero_obj], &small), vec!["/dev/zero", "not a regular file"]),
        (
            with(&["render", "--scene", &far, "--technique", "parallel-lights"], &small),
            vec!["far.json", "1e6"],
        ),
        (
            with(&["render", "--scene", &through], &small),
            vec!["through.json", "walkthrough between cameras 0 and 1"],
        ),
        (
            with(&["render", "--scene", "asm", "--technique", "asm", "--asm-budget-mb", "inf"], &small),
            vec!["must be a finite number of MB"],
        ),
        (
            vec!["probes", "tetrahedralize", "--in", &skew, "--out", &tetrahedra],
            vec!["skew.json", "more than 4194304 tetrahedra"],
        ),
    ];
    for (args, expected) in &cases {
        let out = kage(args);
        let all = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {all}");
        for part in expected {
            assert!(
                all.contains("kage: error:") && all.contains(part),
                "{args:?} does not say {part:?}: {all}"
            );
        }
        assert!(!all.contains("panicked"), "{args:?}: {all}");
    }

    // A scene file saved with a UTF-8 byte order mark (as some Windows editors do) reads.
    let plain = scene("plain.json", &format!(r#"{{"name": "g", "meshes": [{ball}]}}"#), "");
    let bom = dir.join("bom.json");
    std::fs::write(&bom, format!("\u{feff}{}", std::fs::read_to_string(&plain).unwrap())).unwrap();
    let out = kage(&with(
        &["render", "--scene", bom.to_str().unwrap(), "--technique", "unshadowed", "--out", &path("bom.png")],
        &small,
    ));
    assert!(out.status.success(), "{}", text(&out));
}

/// `kage scene export` writes its own files, never through a symbolic link to one elsewhere.
#[cfg(unix)]
#[test]
fn scene_export_does_not_write_through_a_symbolic_link() {
    let dir = scratch_dir("cli-export-link");
    let elsewhere = dir.join("elsewhere.txt");
    std::fs::write(&elsewhere, "keep").unwrap();
    let out = dir.join("export");
    std::fs::create_dir_all(&out).unwrap();
    let link = out.join("scene.json");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&elsewhere, &link).unwrap();
    let run = kage(&["scene", "export", "--scene", "teapot", "--out", out.to_str().unwrap()]);
    let all = text(&run);
    assert_eq!(run.status.code(), Some(1), "{all}");
    assert!(all.contains("scene.json") && all.contains("symbolic link"), "{all}");
    assert_eq!(std::fs::read_to_string(&elsewhere).unwrap(), "keep");
}

/// `kage render --trace`: a Chrome trace event file (what Perfetto opens) with one complete
/// event per frame on the CPU track and one per pass and frame on the GPU track, agreeing with
/// the pass counts of `--timings`.
#[test]
fn render_writes_a_trace_with_one_event_per_pass_and_frame() {
    let dir = scratch_dir("cli-trace");
    let (trace, timings) = (dir.join("trace.json"), dir.join("timings.json"));
    let out = kage(&[
        "render",
        "--technique",
        "unshadowed",
        "--frames",
        "3",
        "--width",
        "16",
        "--height",
        "16",
        "--out",
        dir.join("t.png").to_str().unwrap(),
        "--timings",
        timings.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let read = |path: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    let (trace, timings) = (read(&trace), read(&timings));
    let events = trace["traceEvents"].as_array().expect("a traceEvents array");
    let complete = |cat: &str| -> Vec<&serde_json::Value> {
        events.iter().filter(|e| e["ph"] == "X" && e["cat"] == cat).collect()
    };
    for e in complete("cpu").into_iter().chain(complete("gpu")) {
        assert!(
            e["ts"].as_f64().is_some_and(|t| t >= 0.0) && e["dur"].as_f64().is_some_and(|d| d >= 0.0),
            "{e}"
        );
        assert!(e["name"].is_string() && e["pid"].is_number() && e["tid"].is_number(), "{e}");
    }
    let frames: Vec<u64> = complete("cpu").iter().map(|e| e["args"]["frame"].as_u64().unwrap()).collect();
    assert_eq!(frames, [0, 1, 2]);
    for pass in timings["passes"].as_array().unwrap() {
        let name = pass["name"].as_str().unwrap();
        let events = complete("gpu").into_iter().filter(|e| e["name"] == name).count();
        assert_eq!(events as u64, pass["frames"].as_u64().unwrap(), "events of pass {name}");
    }
    // On one clock where the device has VK_EXT_calibrated_timestamps (lavapipe has): then the
    // device ran every pass between the host's recording of its frame and the image being
    // ready, within the clocks' deviation.
    let info = text(&kage(&["info"]));
    let has = info.lines().any(|l| l.contains("[x] VK_EXT_calibrated_timestamps"));
    assert_eq!(trace["otherData"]["gpu_clock"], if has { "calibrated" } else { "uncalibrated" });
    if has {
        let slack_us = 1e-3 * trace["otherData"]["max_deviation_ns"].as_f64().unwrap() + 1.0;
        for gpu in complete("gpu") {
            let cpu =
                complete("cpu").into_iter().find(|c| c["args"]["frame"] == gpu["args"]["frame"]).unwrap();
            let (start, end) =
                (cpu["ts"].as_f64().unwrap(), cpu["ts"].as_f64().unwrap() + cpu["dur"].as_f64().unwrap());
            let (ts, dur) = (gpu["ts"].as_f64().unwrap(), gpu["dur"].as_f64().unwrap());
            assert!(
                ts >= start - slack_us && ts + dur <= end + slack_us,
                "pass {gpu} outside its frame {cpu}"
            );
        }
    }
}

/// `kage compare` for CI: `--json` prints one parsable object, and the thresholds set the exit
/// status (0 within, 3 beyond, naming the one exceeded; 1 for a bad threshold).
#[test]
fn compare_prints_json_and_its_thresholds_set_the_exit_status() {
    use kage::imageio::RgbaF32Image;
    let dir = scratch_dir("cli-compare");
    let image = |name: &str, value: &dyn Fn(usize) -> f32| {
        let pixels = (0..64).map(|i| [value(i), value(i), value(i), 1.0]).collect();
        let path = dir.join(name);
        kage::imageio::write(&path, &RgbaF32Image { width: 8, height: 8, pixels }, 1.0).unwrap();
        path.to_str().unwrap().to_owned()
    };
    // B is 1 everywhere; A is 1.1 (relative RMSE 0.1), then dark in its first half (half the
    // pixels lit in B only).
    let b = image("b.exr", &|_| 1.0);
    let a = image("a.exr", &|_| 1.1);
    let dark = image("dark.exr", &|i| if i < 32 { 0.0 } else { 1.0 });

    let out = kage(&["compare", &a, &b, "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is one JSON object");
    assert!((json["relative_rmse"].as_f64().unwrap() - 0.1).abs() < 1e-6, "{json}");
    assert_eq!((json["width"].as_u64(), json["within_thresholds"].as_bool()), (Some(8), Some(true)));

    let status = |args: &[&str]| {
        let out = kage(args);
        (out.status.code(), text(&out))
    };
    assert_eq!(status(&["compare", &a, &b, "--max-rel-rmse", "0.11"]).0, Some(0));
    let (code, said) = status(&["compare", &a, &b, "--max-rel-rmse", "0.05"]);
    assert_eq!(code, Some(3), "{said}");
    assert!(said.contains("exceeds --max-rel-rmse 0.05"), "{said}");
    assert_eq!(status(&["compare", &dark, &b, "--max-mismatch", "0.6"]).0, Some(0));
    let (code, said) = status(&["compare", &dark, &b, "--max-mismatch", "0.4", "--json"]);
    assert_eq!(code, Some(3), "{said}");
    assert!(said.contains("shadow mismatch 5.000000e-1 exceeds --max-mismatch 0.4"), "{said}");
    let (code, said) = status(&["compare", &a, &b, "--max-rel-rmse=-1"]);
    assert_eq!(code, Some(1), "{said}");
    assert!(said.contains("--max-rel-rmse must be a number at least 0"), "{said}");
}

/// The help of `--scene` names every built-in scene, the list the engine keeps.
#[test]
fn scene_help_names_every_built_in_scene() {
    let help = text(&kage(&["render", "--help"]));
    for name in kage::scene::BUILTIN {
        assert!(help.contains(name), "`kage render --help` does not name the built-in scene {name}");
    }
}

#[test]
fn info_lists_features() {
    let out = kage(&["info"]);
    assert!(out.status.success(), "{}", text(&out));
    let all = text(&out);
    assert!(all.contains("VK_KHR_dynamic_rendering") && all.contains("timestamps"), "{all}");
}

#[test]
fn precompute_caches_and_tamura_renders_from_the_cache() {
    let dir = scratch_dir("cli-prt");
    let cache = dir.join("cache");
    let cache = cache.to_str().unwrap();
    let first = kage(&["precompute", "--rays", "64", "--cache", cache, "--validate"]);
    assert!(first.status.success(), "{}", text(&first));
    assert!(text(&first).contains("computing") && text(&first).contains("cache: wrote"), "{}", text(&first));
    // The split of the time: traversal plus everything else is the whole.
    let split = |out: &Output| -> Option<(f64, f64)> {
        let all = text(out);
        let time: f64 =
            all.lines().find_map(|l| l.strip_prefix("time: "))?.split(' ').next()?.parse().ok()?;
        let line = all.lines().find_map(|l| l.strip_prefix("split: ray traversal "))?;
        let traversal: f64 = line.split(' ').next()?.parse().ok()?;
        let rest: f64 = line.split("everything else ").nth(1)?.split(' ').next()?.parse().ok()?;
        Some((time, traversal + rest))
    };
    let (time, sum) = split(&first).unwrap_or_else(|| panic!("no time and split lines:\n{}", text(&first)));
    assert!((time - sum).abs() <= 0.011, "traversal and the rest add up to {sum} s of {time} s");
    let second = kage(&["precompute", "--rays", "64", "--cache", cache]);
    assert!(text(&second).contains("is valid, nothing to compute"), "{}", text(&second));
    let forced = kage(&["precompute", "--rays", "64", "--cache", cache, "--force"]);
    assert!(text(&forced).contains("(--force)"), "{}", text(&forced));

    let out = dir.join("tamura.png");
    let render = kage(&[
        "render",
        "--technique",
        "tamura",
        "--rays",
        "64",
        "--cache",
        cache,
        "--width",
        "32",
        "--height",
        "32",
        "--animate",
        "--frames",
        "2",
        "--env-rotation",
        "30",
        "--validate",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(render.status.success(), "{}", text(&render));
    assert!(text(&render).contains("transfer: from"), "the cached transfer is used: {}", text(&render));
    for pass in ["self_shadow", "occluder_masks", "blur_horizontal", "blur_vertical", "scene"] {
        assert!(text(&render).contains(pass), "{pass} missing: {}", text(&render));
    }
}

/// A small sweep: one row per setting, the header naming every pose, errors that a working
/// technique and reference give (finite, below 1, Tamura's below unshadowed's: the teapot's
/// shadow on the floor is what unshadowed misses), times and memory filled in.
/// `kage sweep --technique ARGS… --validate --out DIR --pick --max-error 1`, which must
/// succeed; returns its standard output.
fn sweep(dir: &std::path::Path, args: &[&str]) -> String {
    let tail = ["--validate", "--out", dir.to_str().unwrap(), "--pick", "--max-error", "1"];
    let out = kage(&[&["sweep", "--technique"][..], args, &tail[..]].concat());
    assert!(out.status.success(), "{}", text(&out));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// What `kage sweep` wrote to `dir`: its chart is a PNG and its CSV starts with `header`;
/// returns the CSV and its rows split into fields.
fn sweep_outputs(dir: &std::path::Path, header: &str) -> (String, Vec<Vec<String>>) {
    assert_eq!(&std::fs::read(dir.join("pareto.png")).unwrap()[1..4], b"PNG");
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(header), "{csv}");
    let rows = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    (csv, rows)
}

/// Field `column` of a sweep row as a number.
fn number(row: &[String], column: usize) -> f64 {
    row[column].parse().unwrap_or_else(|e| panic!("{row:?}[{column}]: {e}"))
}

#[test]
fn sweep_writes_one_csv_row_per_setting() {
    let dir = scratch_dir("cli-sweep");
    let cache = dir.join("cache");
    let stdout = sweep(
        &dir,
        &[
            "prt",
            "--only",
            "unshadowed,tamura:32,parallel-lights:32",
            "--poses",
            "0,0.3",
            "--size",
            "32",
            "--noise",
            "0.05",
            "--frames",
            "2",
            "--time-size",
            "32",
            "--rays",
            "64",
            "--cache",
            cache.to_str().unwrap(),
            "--max-ms",
            "1e-6",
        ],
    );
    assert!(stdout.contains("scene: cheapest within relative RMSE 1: unshadowed"), "{stdout}");
    assert!(stdout.contains("scene: no setting runs within 0.000001 ms"), "{stdout}");
    let (csv, fields) = sweep_outputs(
        &dir,
        "scene,env,technique,parameter,value,error_mean,error_t0,error_t0.3,reference_noise_t0,\
         reference_noise_t0.3,frame_ms,precompute_s,memory_mb",
    );
    assert_eq!(fields.len(), 3, "{csv}");
    assert_eq!((&*fields[0][2], &*fields[1][2], &*fields[1][4]), ("unshadowed", "tamura", "32"));
    assert_eq!((&*fields[2][2], &*fields[2][4]), ("parallel-lights", "32"));
    // References at 5 % noise cannot rank two settings a few percent apart, and it says so.
    assert!(stdout.contains("scene: tamura:32 / parallel-lights:32: error"), "{stdout}");
    assert!(stdout.contains("too close to rank"), "{stdout}");
    for row in &fields {
        assert!((0.0..1.0).contains(&number(row, 5)), "{row:?}");
        // Each reference ran to the noise asked for.
        assert!((0.0..=0.05).contains(&number(row, 8)) && (0.0..=0.05).contains(&number(row, 9)), "{row:?}");
        assert!(number(row, 10) > 0.0 && number(row, 12) > 0.0, "{row:?}");
    }
    assert!(number(&fields[1], 5) < number(&fields[0], 5), "{csv}");
    assert!(
        number(&fields[1], 11) > 0.0 && fields[0][11].is_empty() && fields[2][11].is_empty(),
        "precompute seconds only for PRT: {csv}"
    );
    // The references are cached under the cache folder, an EXR and its noise for each pose.
    assert_eq!(std::fs::read_dir(cache.join("references")).unwrap().count(), 4);
}

#[test]
fn sweep_asm_compares_budgets_with_map_sizes() {
    let dir = scratch_dir("cli-sweep-asm");
    let stdout = sweep(&dir, &["asm", "--only", "shadowmap:256,asm:1", "--frames", "2", "--size", "32"]);
    assert!(stdout.contains("asm: cheapest within mismatch 1: "), "{stdout}");
    let (csv, rows) = sweep_outputs(
        &dir,
        "scene,technique,parameter,value,error_mean,error_max,error_at_rest,flips_mean,frame_ms,ratio,memory_mb",
    );
    assert_eq!(rows.len(), 2, "{csv}");
    assert_eq!(
        (&*rows[0][1], &*rows[0][3], &*rows[1][1], &*rows[1][2]),
        ("shadowmap", "256", "asm", "budget_mb")
    );
    // 256² D32 texels: 0.25 MiB; the ASM pool: at most its 1 MB (MiB) budget.
    assert_eq!(number(&rows[0], 10), 0.25);
    assert!(number(&rows[1], 10) > 0.0 && number(&rows[1], 10) <= 1.0, "{csv}");
    for row in &rows {
        assert!((0.0..1.0).contains(&number(row, 4)) && number(row, 8) > 0.0, "{row:?}");
    }
}

/// A 3×3×3 grid over [0, 2]³ (every cube's corners cospherical) and two duplicates.
fn probe_file(dir: &std::path::Path) -> std::path::PathBuf {
    let mut positions = Vec::new();
    for x in 0..3 {
        for y in 0..3 {
            for z in 0..3 {
                positions.push([x, y, z]);
            }
        }
    }
    positions.extend([positions[4], positions[0]]);
    let path = dir.join("probes.json");
    std::fs::write(&path, serde_json::json!({ "positions": positions }).to_string()).unwrap();
    path
}

/// `--keyframe K` looks from the walkthrough's keyframe K, for the renderer and the reference
/// alike: two keyframes give two pictures, and a render matches its reference's lit pixels.
#[test]
fn keyframes_of_the_walkthrough_are_cameras_for_render_and_reference() {
    let dir = scratch_dir("cli-keyframe");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let run = |command: &[&str], k: &str, out: &str| {
        let view = ["--scene", "asm", "--keyframe", k, "--width", "24", "--height", "24", "--out", out];
        let out = kage(&[command, &view[..]].concat());
        assert!(out.status.success(), "{}", text(&out));
    };
    for k in ["1", "2"] {
        run(&["render", "--technique", "shadowmap"], k, &path(&format!("k{k}.exr")));
        run(&["reference", "--light", "local"], k, &path(&format!("r{k}.exr")));
    }
    let read = |name: &str| kage::imageio::read_exr(dir.join(name)).unwrap();
    assert!(read("k1.exr").pixels != read("k2.exr").pixels, "two keyframes, one picture");
    let mismatch = |a: &str, b: &str| {
        kage::reference::shadow_mismatch(&read(a), &read(b), kage::reference::SHADOW_THRESHOLD, None)
            .unwrap()
            .fraction
    };
    // The render and the reference of the same keyframe agree far better than across keyframes.
    assert!(mismatch("k1.exr", "r1.exr") < 0.1 && mismatch("k1.exr", "r2.exr") > 0.1);
}

/// `--probes auto` reports how many of its candidates it kept (the issue asks for the count);
/// a grid reports its probe count.
#[test]
fn render_with_probes_reports_what_placement_kept() {
    let dir = scratch_dir("cli-probes-auto");
    let out_png = dir.join("probes.png");
    let run = |probes: &str| {
        let args = [
            "render",
            "--scene",
            "probe-room",
            "--technique",
            "probes",
            "--probes",
            probes,
            "--probe-cube-size",
            "8",
            "--probe-light",
            "sky",
            "--width",
            "32",
            "--height",
            "32",
            "--frames",
            "1",
            "--validate",
            "--out",
            out_png.to_str().unwrap(),
        ];
        let out = kage(&args);
        assert!(out.status.success(), "{}", text(&out));
        text(&out)
    };
    let auto = run("auto:0.05:4,3,3");
    let line = auto.lines().find(|l| l.starts_with("probes: ")).unwrap_or_else(|| panic!("{auto}"));
    let kept: usize = line["probes: ".len()..].split(' ').next().unwrap().parse().unwrap();
    assert!(line.contains("of 36 candidates kept by automatic placement"), "{line}");
    assert!((4..36).contains(&kept), "{line}");
    let grid = run("grid:3,2,3");
    assert!(grid.lines().any(|l| l.starts_with("probes: 18, captured in")), "{grid}");
}

#[test]
fn probes_tetrahedralize_writes_positive_tetrahedra_filling_the_hull() {
    let dir = scratch_dir("cli-probes");
    let probes = probe_file(&dir);
    let tets = dir.join("tets.json");
    let out = kage(&[
        "probes",
        "tetrahedralize",
        "--in",
        probes.to_str().unwrap(),
        "--out",
        tets.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("27 into 4, 28 into 0"), "{}", text(&out));

    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&tets).unwrap()).unwrap();
    let tets: Vec<[usize; 4]> = serde_json::from_value(json["tetrahedra"].clone()).unwrap();
    let p = |i: usize| glam::DVec3::new((i / 9) as f64, (i / 3 % 3) as f64, (i % 3) as f64);
    let mut total = 0.0;
    for t in &tets {
        assert!(t.iter().all(|&i| i < 27), "{t:?} uses a merged duplicate");
        // Six times the volume: an integer here, so the sum is exact.
        let volume6 = (p(t[1]) - p(t[0])).dot((p(t[2]) - p(t[0])).cross(p(t[3]) - p(t[0])));
        assert!(volume6 > 0.0, "{t:?} is not positively oriented");
        total += volume6;
    }
    assert_eq!(total, 6.0 * 8.0, "the tetrahedra fill the hull, a 2×2×2 cube");
}

#[test]
fn probes_lookup_prints_weights_inside_and_outside() {
    let dir = scratch_dir("cli-probes-lookup");
    let probes = probe_file(&dir);
    let probes = probes.to_str().unwrap();
    for (at, inside) in [("0.5,1.25,0.3", true), ("-1,0.5,0.5", false), ("10,10,10", false)] {
        let out = kage(&["probes", "lookup", "--in", probes, "--at", at]);
        assert!(out.status.success(), "{at}: {}", text(&out));
        let stdout = String::from_utf8_lossy(&out.stdout);
        let number = |line: &str| {
            line.split_whitespace().skip(1).map(|w| w.parse::<f64>().unwrap()).collect::<Vec<_>>()
        };
        let probe_line = stdout.lines().find(|l| l.starts_with("tetrahedron")).unwrap();
        let indices: Vec<usize> = probe_line
            .split("probes")
            .nth(1)
            .unwrap()
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        let weights = number(stdout.lines().find(|l| l.starts_with("weights")).unwrap());
        assert_eq!((indices.len(), weights.len()), (4, 4), "{stdout}");
        assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-8, "{stdout}");
        assert!(weights.iter().all(|w| (0.0..=1.0).contains(w)), "{stdout}");
        assert_eq!(stdout.contains("inside the hull"), inside, "{at}: {stdout}");
        assert_eq!(stdout.contains("extrapolated"), !inside, "{at}: {stdout}");
        if at == "10,10,10" {
            // The nearest point of the hull is the grid's corner (2, 2, 2), probe 26.
            let corner = indices.iter().position(|&i| i == 26).unwrap();
            assert!((weights[corner] - 1.0).abs() < 1e-8, "{stdout}");
        }
    }
}

#[test]
fn probes_bad_input_is_a_clear_error() {
    let dir = scratch_dir("cli-probes-bad");
    let write = |name: &str, json: &str| {
        let path = dir.join(name);
        std::fs::write(&path, json).unwrap();
        path.to_str().unwrap().to_owned()
    };
    let flat = write("flat.json", r#"{"positions": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[2,3,0]]}"#);
    let few = write("few.json", r#"{"positions": [[0,0,0],[1,0,0],[0,1,0],[0,1,0]]}"#);
    let huge = write("huge.json", r#"{"positions": [[0,0,0],[1,0,0],[0,1,0],[0,0,1e31]]}"#);
    let syntax = write("syntax.json", r#"{"positions": [[0,0,0],[1,0,0]"#);
    let unknown = write("unknown.json", r#"{"positions": [], "roles": []}"#);
    let tets = dir.join("tets.json");
    let tets = tets.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["probes", "tetrahedralize", "--in", &flat, "--out", tets], "lie in one plane"),
        (
            &["probes", "tetrahedralize", "--in", &few, "--out", tets],
            "3 distinct probe position(s) among the 4",
        ),
        (&["probes", "tetrahedralize", "--in", &huge, "--out", tets], "probe 3 at"),
        (&["probes", "lookup", "--in", &syntax, "--at", "0,0,0"], "syntax.json: not a probe file"),
        (&["probes", "lookup", "--in", &unknown, "--at", "0,0,0"], "unknown field `roles`"),
        (
            &["probes", "lookup", "--in", "/nonexistent/probes.json", "--at", "0,0,0"],
            "/nonexistent/probes.json",
        ),
    ];
    assert_clear_errors(&cases);
    let out = kage(&["probes", "lookup", "--in", &flat, "--at", "nan,0,0"]);
    assert!(!out.status.success() && text(&out).contains("three finite numbers"), "{}", text(&out));
}

#[test]
fn probes_bench_runs_small_sets() {
    for grid in [false, true] {
        let mut args = vec!["bench", "probes", "--sizes", "100,300", "--lookups", "500", "--runs", "1"];
        if grid {
            args.push("--grid");
        }
        let out = kage(&args);
        assert!(out.status.success(), "{}", text(&out));
        let stdout = String::from_utf8_lossy(&out.stdout);
        // A header line, the column names and one row per size.
        assert_eq!(stdout.lines().count(), 4, "{stdout}");
        let first_row = stdout.lines().nth(2).unwrap();
        assert!(first_row.trim_start().starts_with(if grid { "125" } else { "100" }), "{stdout}");
    }
}

/// `kage bench asm` end to end at a tiny size: two walkthrough samples, one frame held and one
/// leaving slowly at each keyframe, a coarse and a finer conventional map. What any working run
/// gives: one summary row per configuration with the map's bytes (side² × 4), errors that are
/// fractions and fall with the finer map (a 64² map's texels over the 122° cone are 22 cm on the
/// floor, a 512²'s under 3 cm), the first configuration's ratio 1, a conventional map's error
/// constant at rest (converged after 0 frames), flips measured over the slow pairs; a second run
/// takes every reference from the cache. Bad configurations and a scene without a walkthrough
/// are clear errors.
#[test]
fn bench_asm_measures_every_configuration_over_the_walkthrough() {
    let dir = scratch_dir("cli-bench-asm");
    let (cache, out) = (dir.join("cache"), dir.join("out"));
    let args = [
        "bench",
        "asm",
        "--only",
        "shadowmap:64,shadowmap:512",
        "--frames",
        "2",
        "--rest",
        "1",
        "--slow",
        "1",
        "--size",
        "32",
        "--cache",
        cache.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--validate",
    ];
    let first = kage(&args);
    assert!(first.status.success(), "{}", text(&first));
    let stdout = String::from_utf8_lossy(&first.stdout);
    assert!(stdout.contains("references: ") && !stdout.contains("references: 0 ray cast"), "{stdout}");
    for pass in ["shadow_maps", "scene"] {
        assert!(stdout.lines().any(|l| l.starts_with("shadowmap:512") && l.contains(pass)), "{stdout}");
    }
    assert_eq!(&std::fs::read(out.join("error-time.png")).unwrap()[1..4], b"PNG");
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let lines: Vec<&str> = summary.lines().collect();
    assert!(lines[0].starts_with(
        "scene,config,technique,value,shadow_bytes,error_mean,error_max,error_at_rest,frame_ms,ratio,wall_ms,wall_ratio,flips_mean,slow_pairs,converged_after,ms_"
    ));
    assert_eq!(lines.len(), 3, "{summary}");
    let rows: Vec<Vec<&str>> = lines[1..].iter().map(|l| l.split(',').collect()).collect();
    let number = |row: &[&str], column: usize| row[column].parse::<f64>().unwrap();
    assert_eq!((rows[0][4], rows[1][4]), ("16384", "1048576"));
    for row in &rows {
        assert!((0.0..1.0).contains(&number(row, 5)) && number(row, 6) >= number(row, 5), "{row:?}");
        assert!(number(row, 8) > 0.0 && number(row, 13) > 0.0, "{row:?}");
        // The render call's wall clock holds its passes' GPU time (it waits for them).
        assert!(number(row, 10) >= number(row, 8), "{row:?}");
        assert_eq!(row[14], "0", "a conventional map's error does not change at rest: {row:?}");
    }
    assert!(number(&rows[1], 5) < number(&rows[0], 5), "{summary}");
    assert_eq!((number(&rows[0], 9), number(&rows[0], 11)), (1.0, 1.0));
    let frames = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!((frames.lines().count() - 1) % 2, 0, "two rows per frame: {frames}");

    let second = kage(&args);
    assert!(second.status.success(), "{}", text(&second));
    assert!(String::from_utf8_lossy(&second.stdout).contains("references: 0 ray cast"), "{}", text(&second));

    let out = out.to_str().unwrap();
    assert_clear_errors(&[
        (&["bench", "asm", "--only", "cube:4", "--out", out], "no technique \"cube\""),
        (&["bench", "asm", "--only", "shadowmap:8", "--size", "8", "--out", out], "shadow map size 8"),
        (&["bench", "asm", "--scene", "teapot", "--out", out], "no camera walkthrough"),
    ]);
}

/// A probe captured from a photograph (city.exr) has exactly the coefficients `kage sh` gives
/// for the same map (one projection serves both), and its file holds them and the irradiance
/// the SH gives at the six axis normals.
#[test]
fn probes_capture_image_matches_kage_sh() {
    let dir = scratch_dir("cli-capture-image");
    let map = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/assets/city.exr");
    let json = dir.join("probe.json");
    let probe = kage(&["probes", "capture-image", map, "--out", json.to_str().unwrap(), "--validate"]);
    assert!(probe.status.success(), "{}", text(&probe));
    let sh = kage(&["sh", map, "--validate"]);
    assert!(sh.status.success(), "{}", text(&sh));
    let coefficients = |out: &Output| -> Vec<String> {
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter(|l| l.starts_with("  "))
            .map(String::from)
            .collect()
    };
    assert_eq!(coefficients(&probe).len(), 9);
    assert_eq!(coefficients(&probe), coefficients(&sh));
    let file: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let c0 = file["sh"][0][0].as_f64().unwrap();
    let printed: f64 = coefficients(&sh)[0].split_whitespace().nth(3).unwrap().parse().unwrap();
    assert!((c0 - printed).abs() <= 1e-6 * c0, "{c0} against {printed}");
    // E(+y) − E(−y) = 2 Â₁ y₁ c₁ (the odd band alone), for each channel.
    let e = |axis: &str| file["irradiance"][axis][0].as_f64().unwrap();
    let c1 = file["sh"][1][0].as_f64().unwrap();
    let odd = 2.0 * (2.0 * std::f64::consts::PI / 3.0) * 0.488603 * c1;
    assert!((e("+y") - e("-y") - odd).abs() < 1e-4 * odd.abs(), "{} {} {odd}", e("+y"), e("-y"));
}

/// The probes technique on the default scene, whose only static group is a flat floor: its
/// grid is lifted over the teapot instead of lying in the floor's plane (where no tetrahedron
/// spans it).
#[test]
fn probes_render_on_the_default_scene() {
    let dir = scratch_dir("cli-probes-default");
    let png = dir.join("probes.png");
    let args =
        ["render", "--technique", "probes", "--probe-cube-size", "8", "--width", "16", "--height", "16"];
    let out = kage(&[&args[..], &["--validate", "--out", png.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", text(&out));
}

/// The probe capture's own options: bad values are clear errors.
#[test]
fn probe_capture_options_are_checked() {
    let probes = ["render", "--technique", "probes", "--width", "8", "--height", "8"];
    let with =
        |extra: &[&'static str]| -> Vec<&'static str> { probes.iter().chain(extra).copied().collect() };
    let (scene, bounces) =
        (with(&["--probes", "scene"]), with(&["--scene", "probe-room", "--probe-bounces", "3"]));
    // The window is parsed with the options (the engine's parser behind the setting), so a bad
    // one is a usage error naming the option, before anything runs.
    let out = kage(&with(&["--scene", "probe-room", "--probe-dering", "gauss:2"]));
    let all = text(&out);
    assert_eq!(out.status.code(), Some(2), "{all}");
    assert!(
        all.contains("'--probe-dering <WINDOW>'") && all.contains("deringing window \"gauss:2\""),
        "{all}"
    );
    let cases: [(&[&str], &str); 4] = [
        (&scene, "places no probes"),
        (&bounces, "3 bounces: at most 2"),
        (&["probes", "capture-image", "/nonexistent/photo.exr"], "/nonexistent/photo.exr"),
        (&["probes", "capture-image", "/nonexistent/photo.exr", "--dering", "lanczos:0"], "lanczos:0"),
    ];
    assert_clear_errors(&cases);
}

/// Every `kage …` command README quotes (an inline code span starting with `kage `): its
/// command (the leading lowercase words after `kage`) and the span's text.
fn readme_commands() -> Vec<(Vec<String>, String)> {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md")).unwrap();
    let is_word = |w: &str| {
        !w.is_empty() && w.chars().all(|c| c.is_ascii_lowercase() || c == '-') && !w.starts_with('-')
    };
    readme
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|span| span.starts_with("kage ") && !span.contains('\n'))
        .map(|span| {
            let command =
                span.split_whitespace().skip(1).take_while(|w| is_word(w)).map(str::to_string).collect();
            (command, span.to_string())
        })
        .collect()
}

/// Every option README names in a quoted command exists under that name in the command's
/// `--help`: README and the program cannot drift apart (a renamed flag fails here).
#[test]
fn every_option_readme_names_is_one_the_program_takes() {
    let mut checked = 0;
    for (command, span) in readme_commands() {
        let command: Vec<&str> = command.iter().map(String::as_str).collect();
        let help = kage(&[command.as_slice(), &["--help"]].concat());
        assert!(help.status.success(), "`kage {} --help` fails (README: `{span}`)", command.join(" "));
        let help = String::from_utf8_lossy(&help.stdout).into_owned();
        // `kage probes ... --in`: the subcommand elided, so the options are not the parent's.
        if help.contains("\nCommands:\n") {
            continue;
        }
        let options =
            span.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).filter(|w| w.starts_with("--"));
        for option in options.filter(|o| *o != "--help") {
            assert!(
                help.contains(&format!("{option} "))
                    || help.contains(&format!("{option}\n"))
                    || help.contains(&format!("{option}="))
                    || help.contains(&format!("{option},")),
                "README names `{option}` in `{span}`, which `kage {} --help` does not list",
                command.join(" ")
            );
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} options found in README's quoted commands (21 on 2026-12-05)");
}

/// docs/cli.md is `kage cli-reference`: every command and flag with its documentation, generated
/// from the same definitions as `--help`. `KAGE_BLESS=1` rewrites it.
#[test]
fn cli_reference_is_current() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/cli.md");
    let output = kage(&["cli-reference"]);
    assert!(output.status.success(), "{}", text(&output));
    let generated = String::from_utf8(output.stdout).unwrap();
    if std::env::var_os("KAGE_BLESS").is_some() {
        std::fs::write(path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        committed == generated,
        "docs/cli.md is stale: `KAGE_BLESS=1 cargo test --release -p kage-tools --test cli cli_reference` rewrites it"
    );
    // Every flag of every command is in it (a sample that would fail if a command were lost).
    for flag in ["--asm-budget-mb", "--edges", "--probe-dering", "--export", "--test-region", "--format"] {
        assert!(generated.contains(&format!("`{flag}")), "docs/cli.md lacks {flag}");
    }
}

/// README's scene-format section and the scene parser agree: its example parses, and every
/// field and variant the parser accepts, at every level, is named in the section. The parser
/// lists what it accepts itself: an unknown key at a level makes serde name the expected ones.
#[test]
fn readmes_scene_format_names_every_field_the_parser_takes() {
    use kage::scene::file::SceneFile;
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md")).unwrap();
    let section = readme.split("\n## Scene format").nth(1).unwrap().split("\n## ").next().unwrap();
    let example = section.split("```json").nth(1).unwrap().split("```").next().unwrap();
    serde_json::from_str::<SceneFile>(example).unwrap_or_else(|e| panic!("README's example scene: {e}"));
    // A bogus key (or variant) at each level of the format.
    let levels = [
        r#"{"zzz": 0}"#,
        r#"{"camera": {"zzz": 0}}"#,
        r#"{"environment": {"zzz": 0}}"#,
        r#"{"groups": [{"zzz": 0}]}"#,
        r#"{"groups": [{"meshes": [{"zzz": 0}]}]}"#,
        r#"{"groups": [{"keyframes": [{"zzz": 0}]}]}"#,
        r#"{"groups": [{"meshes": [{"plane": {"zzz": 0}}]}]}"#,
        r#"{"groups": [{"meshes": [{"sphere": {"zzz": 0}}]}]}"#,
        r#"{"lights": [{"zzz": {}}]}"#,
        r#"{"lights": [{"point": {"zzz": 0}}]}"#,
        r#"{"lights": [{"spot": {"zzz": 0}}]}"#,
        r#"{"probes": [{"zzz": 0}]}"#,
        r#"{"probes": [{"position": [0, 0, 0], "role": "zzz"}]}"#,
    ];
    let mut names = Vec::new();
    for json in levels {
        let error = serde_json::from_str::<SceneFile>(json).expect_err(json).to_string();
        let expected = error.split("expected").nth(1).unwrap_or_else(|| panic!("{json}: {error}"));
        let listed: Vec<String> = expected.split('`').skip(1).step_by(2).map(str::to_string).collect();
        assert!(!listed.is_empty(), "{json}: {error}");
        names.extend(listed);
    }
    let unnamed: Vec<&String> = names
        .iter()
        .filter(|name| ["`", "\"", "**"].iter().all(|q| !section.contains(&format!("{q}{name}{q}"))))
        .collect();
    assert!(unnamed.is_empty(), "README's scene format does not name {unnamed:?}, which the parser takes");
    assert!(names.len() >= 30, "only {} names found: {names:?}", names.len());
}

/// `--time T` renders one instant of the scene's own motion: a group with keyframes moves, a
/// scene without any stays put (`--animate` no longer moves a group the scene does not move);
/// `--time` with `--animate` is an error.
#[test]
fn render_time_plays_the_scenes_keyframes_and_nothing_else() {
    let dir = scratch_dir("cli-time");
    let ball = r#"{"name": "ball", "translation": [0, 0.5, 0], "meshes": [{"sphere": {"radius": 0.5, "segments": 12}, "albedo": [0.8, 0.8, 0.8]}]KEYS}"#;
    let floor = r#"{"name": "floor", "meshes": [{"plane": {"size": [6, 6], "vertices": [2, 2]}, "albedo": [0.6, 0.6, 0.6]}]}"#;
    let scene = |keys: &str| {
        format!(
            r#"{{"camera": {{"position": [0, 2, 5], "target": [0, 0.5, 0], "fov_y_deg": 40}}, "environment": {{"constant": [1, 1, 1]}}, "groups": [{}, {floor}]}}"#,
            ball.replace("KEYS", keys)
        )
    };
    let keys = r#", "keyframes": [{"time": 0, "translation": [0, 0.5, 0]}, {"time": 1, "translation": [1.5, 0.5, 0]}]"#;
    let (moving, still) = (dir.join("moving.json"), dir.join("still.json"));
    std::fs::write(&moving, scene(keys)).unwrap();
    std::fs::write(&still, scene("")).unwrap();
    let render = |scene: &std::path::Path, time: &str| {
        let out = dir.join(format!("{}-{time}.exr", scene.file_stem().unwrap().to_str().unwrap()));
        let args =
            ["render", "--scene", scene.to_str().unwrap(), "--technique", "unshadowed", "--time", time];
        let result =
            kage(&[&args[..], &["--width", "32", "--height", "32", "--out", out.to_str().unwrap()]].concat());
        assert!(result.status.success(), "{}", text(&result));
        kage::imageio::read_exr(&out).unwrap().pixels
    };
    assert!(render(&moving, "0") != render(&moving, "1"), "the keyframed ball moved");
    assert!(render(&still, "0") == render(&still, "1"), "a scene without keyframes stays put");
    let both = kage(&["render", "--scene", moving.to_str().unwrap(), "--animate", "--time", "1"]);
    assert!(!both.status.success() && text(&both).contains("give one of them"), "{}", text(&both));
}

/// `kage scene export --format gltf` writes scene.glb beside scene.json; the folder renders, and
/// the .glb alone plays the teapot's hop: `--time` instants differ, `--animate` runs.
#[test]
fn scene_export_as_gltf_renders_and_plays_its_motion() {
    let dir = scratch_dir("cli-export-gltf");
    let out = dir.join("teapot");
    let export =
        kage(&["scene", "export", "--scene", "teapot", "--format", "gltf", "--out", out.to_str().unwrap()]);
    assert!(export.status.success() && text(&export).contains("scene.glb"), "{}", text(&export));
    let render = |scene: &std::path::Path, extra: &[&str], name: &str| {
        let image = dir.join(format!("{name}.exr"));
        let args =
            ["render", "--scene", scene.to_str().unwrap(), "--technique", "unshadowed", "--width", "32"];
        let run = kage(&[&args[..], &["--height", "32", "--out", image.to_str().unwrap()], extra].concat());
        assert!(run.status.success(), "{}", text(&run));
        (kage::imageio::read_exr(&image).unwrap().pixels, text(&run))
    };
    render(&out, &[], "folder");
    let glb = out.join("scene.glb");
    let (start, notes) = render(&glb, &["--time", "0"], "start");
    assert!(notes.contains("no environment"), "{notes}");
    assert!(start != render(&glb, &["--time", "0.125"], "hop").0, "the teapot hopped");
    render(&glb, &["--animate", "--frames", "3"], "animated");
}

/// `--exposure auto` gives a readable picture whatever the light's scale: the teapot under its
/// sky and under the same sky 1000× brighter (as a file in candela would be) come out with
/// their mean sRGB value within a few levels of each other, where the fixed default leaves the
/// bright one white.
#[test]
fn auto_exposure_reads_any_scale_of_light() {
    let dir = scratch_dir("cli-exposure");
    let mean_level = |png: &std::path::Path| {
        let image = image::open(png).unwrap().to_rgb8();
        image.as_raw().iter().map(|&b| f64::from(b)).sum::<f64>() / image.as_raw().len() as f64
    };
    let render = |scale: &str, exposure: &[&str]| {
        let scene = dir.join(format!("sky-{scale}.json"));
        std::fs::write(
            &scene,
            format!(
                r#"{{"camera": {{"position": [0, 1, 3], "target": [0, 0.3, 0], "fov_y_deg": 45}},
                    "environment": {{"constant": [1, 1, 1], "intensity": {scale}}},
                    "groups": [{{"name": "ball", "meshes": [{{"sphere": {{"radius": 0.5, "segments": 16}}, "albedo": [0.5, 0.5, 0.5]}}]}}]}}"#
            ),
        )
        .unwrap();
        let png = dir.join(format!("sky-{scale}-{}.png", exposure.len()));
        let args =
            [&["render", "--scene", scene.to_str().unwrap(), "--technique", "unshadowed"][..], exposure]
                .concat();
        let args = [&args[..], &["--width", "16", "--height", "16", "--out", png.to_str().unwrap()]].concat();
        let out = kage(&args);
        assert!(out.status.success(), "{}", text(&out));
        (mean_level(&png), text(&out))
    };
    let (dim, note) = render("1", &["--exposure", "auto"]);
    assert!(note.contains("--exposure auto: "), "{note}");
    let (bright, _) = render("1000", &["--exposure", "auto"]);
    let (white, _) = render("1000", &[]);
    assert!((dim - bright).abs() < 3.0 && dim > 60.0 && dim < 200.0, "{dim} {bright}");
    assert!(white > 250.0, "{white}");
}

/// A scene file around the Khronos Box with a floor added, under `name`, seen from `camera`
/// (JSON), with `extra` fields; no environment.
fn box_on_floor(dir: &std::path::Path, file: &str, name: &str, camera: &str, extra: &str) -> String {
    let gltf = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/assets/gltf/khronos-box/Box.gltf");
    let json = format!(
        r#"{{"name": {}, "gltf": {}, "camera": {camera}, "groups": [{{"name": "floor", "translation": [0, -0.5, 0], "meshes": [{{"plane": {{"size": [3, 3], "vertices": [5, 5]}}, "albedo": [0.6, 0.6, 0.6]}}]}}]{extra}}}"#,
        serde_json::to_string(name).unwrap(),
        serde_json::to_string(gltf).unwrap()
    );
    let path = dir.join(file);
    std::fs::write(&path, json).unwrap();
    path.to_str().unwrap().to_owned()
}

/// The PRT cache is keyed by the geometry, not the scene: two scene files around the same
/// geometry, with other names (one of 300 characters, longer than a file name may be) and
/// cameras, make one cache file, which the second precomputation and a render of either read.
#[test]
fn scene_files_around_the_same_geometry_share_one_cache_file() {
    let dir = scratch_dir("cli-prt-shared");
    let cache = dir.join("cache");
    let cache_arg = cache.to_str().unwrap();
    let near = r#"{"position": [0, 1.5, 3], "target": [0, -0.3, 0], "fov_y_deg": 45}"#;
    let far = r#"{"position": [2, 3, 5], "target": [0, 0, 0], "fov_y_deg": 30}"#;
    let first = box_on_floor(&dir, "first.json", "box on a floor", near, "");
    let long_name = "a scene with a long name ".repeat(12);
    assert_eq!(long_name.len(), 300);
    let second = box_on_floor(&dir, "second.json", &long_name, far, "");
    let precompute = |scene: &str| {
        let run = kage(&["precompute", "--scene", scene, "--rays", "16", "--cache", cache_arg, "--validate"]);
        assert!(run.status.success(), "{}", text(&run));
        text(&run)
    };
    let made = precompute(&first);
    assert!(made.contains("cache: wrote"), "{made}");
    let hit = precompute(&second);
    assert!(hit.contains("is valid, nothing to compute"), "{hit}");
    let files: Vec<String> =
        std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
    assert!(files.len() == 1 && files[0].starts_with("prt-") && files[0].ends_with(".kageprt"), "{files:?}");
    let out = dir.join("second.png");
    let args =
        ["render", "--scene", &second, "--technique", "sloan-self", "--rays", "16", "--cache", cache_arg];
    let render =
        kage(&[&args[..], &["--width", "16", "--height", "16", "--out", out.to_str().unwrap()]].concat());
    assert!(render.status.success(), "{}", text(&render));
    assert!(text(&render).contains("transfer: from"), "the shared file is read: {}", text(&render));
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 1);
}

/// The note that a scene has no environment (a glTF file alone, a scene file without one) is
/// printed when the default sky lights it, and not when `--env` replaces it.
#[test]
fn the_default_sky_note_is_printed_only_when_the_default_stays() {
    let dir = scratch_dir("cli-default-sky");
    let camera = r#"{"position": [0, 1.5, 3], "target": [0, -0.3, 0], "fov_y_deg": 45}"#;
    let composed = box_on_floor(&dir, "composed.json", "composed", camera, "");
    let given = box_on_floor(
        &dir,
        "given.json",
        "given",
        camera,
        r#", "environment": {"constant": [0.5, 0.5, 0.5]}"#,
    );
    let gltf = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/assets/gltf/khronos-box/Box.gltf");
    let map = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/assets/sun/sun2-45-sky.exr");
    let render = |scene: &str, extra: &[&str]| {
        let out = dir.join("out.exr");
        let args = ["render", "--scene", scene, "--technique", "unshadowed", "--width", "8", "--height", "8"];
        let run = kage(&[&args[..], &["--out", out.to_str().unwrap()], extra].concat());
        assert!(run.status.success(), "{}", text(&run));
        text(&run).contains("has no environment: lit by a constant sky of radiance 1")
    };
    assert!(render(gltf, &[]) && render(&composed, &[]), "the note where the default sky lights the scene");
    assert!(!render(gltf, &["--env", map]) && !render(&composed, &["--env", map]), "no note under --env");
    assert!(!render(&given, &[]), "no note where the file gives an environment");
}

/// A technique that leaves out some of the scene's light says so: the Blender export's spot
/// light under an environment technique, and under the probes on the static groups; not under
/// the shadow maps, which render it, nor where the scene has no point or spot light.
#[test]
fn the_lights_a_technique_leaves_out_are_named() {
    let dir = scratch_dir("cli-unrendered-lights");
    let blender = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/assets/gltf/blender-suzanne/scene.glb");
    let gltf = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/assets/gltf/khronos-box/Box.gltf");
    let note = |scene: &str, technique: &str| {
        let out = dir.join("out.exr");
        let args = ["render", "--scene", scene, "--technique", technique, "--width", "8", "--height", "8"];
        let run = kage(&[&args[..], &["--out", out.to_str().unwrap()]].concat());
        assert!(run.status.success(), "{}", text(&run));
        text(&run).lines().find(|l| l.contains("point or spot light(s)")).map(str::to_string)
    };
    let unshadowed = note(blender, "unshadowed").unwrap_or_default();
    assert!(unshadowed.contains("technique unshadowed renders the environment alone: the scene's 1 point or spot light(s) are left out"), "{unshadowed}");
    let probes = note(blender, "probes").unwrap_or_default();
    assert!(
        probes.contains("reach the moving groups through the probes' capture but not the static groups"),
        "{probes}"
    );
    assert_eq!(note(blender, "shadowmap"), None);
    assert_eq!(note(gltf, "unshadowed"), None);
}

/// `kage render --scene bunny.obj`: the scanned bunny with its `vn 0 0 0`, read alone, renders
/// under the constant sky with notes for the defaults and the repaired normal; the default
/// camera has it in the middle of the picture. A bad OBJ is an error naming it.
#[test]
fn an_obj_alone_renders_with_its_zero_normal_repaired() {
    let dir = scratch_dir("cli-obj-alone");
    let bunny = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/assets/bunny/bunny.obj");
    let image = dir.join("bunny.exr");
    let args = ["render", "--validate", "--scene", bunny.to_str().unwrap(), "--technique", "unshadowed"];
    let size = ["--width", "32", "--height", "32", "--frames", "1", "--out", image.to_str().unwrap()];
    let run = kage(&[&args[..], &size[..]].concat());
    let output = text(&run);
    assert!(run.status.success(), "{output}");
    assert!(output.contains("kage: note: mesh \"bunny\": 1 normal(s) were zero or not finite"), "{output}");
    assert!(
        output.contains("read alone") && output.contains("albedo 0.8") && output.contains("no ground"),
        "{output}"
    );
    let picture = kage::imageio::read_exr(&image).unwrap();
    assert_eq!((picture.width, picture.height), (32, 32));
    let luminance = |x: usize, y: usize| {
        let [r, g, b, _] = picture.pixels[y * 32 + x];
        (r + g + b) / 3.0
    };
    // The sky of radiance 1 in the corner; the bunny (albedo 0.8, lit by at most that sky) in
    // the middle.
    assert!((luminance(0, 0) - 1.0).abs() < 0.02, "corner {}", luminance(0, 0));
    assert!(luminance(16, 16) < 0.85, "middle {}", luminance(16, 16));

    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 abc 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let run = kage(&["render", "--scene", bad.to_str().unwrap(), "--width", "32", "--height", "32"]);
    let output = text(&run);
    assert!(
        !run.status.success() && output.contains("bad.obj") && output.contains("malformed OBJ"),
        "{output}"
    );
    assert!(!output.contains("panicked") && !output.contains("JSON"), "{output}");
}

/// `kage scene info --json` says what Kage made of a file users bring: BoxAnimated's static
/// outer box and its animated inner box (a node two levels down, named node2 as it has no name)
/// as two groups, the inner one moving; and BoxTextured's albedo map.
#[test]
fn scene_info_names_the_groups_that_move_and_the_maps() {
    let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/assets/gltf");
    let info = |file: &str| {
        let run = kage(&["scene", "info", "--scene", assets.join(file).to_str().unwrap(), "--json"]);
        assert!(run.status.success(), "{}", text(&run));
        serde_json::from_slice::<serde_json::Value>(&run.stdout).unwrap()
    };
    let animated = info("khronos-box-animated/BoxAnimated.gltf");
    let groups: Vec<(&str, bool)> = animated["groups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| (g["name"].as_str().unwrap(), g["moving"].as_bool().unwrap()))
        .collect();
    assert_eq!(groups, [("node3", false), ("node2", true)]);
    assert!(animated["read_ms"].as_f64().is_some_and(|ms| ms > 0.0));
    let textured = info("khronos-box-textured/BoxTextured.gltf");
    assert_eq!(textured["albedo_map_texels"], 256 * 256);
    assert_eq!(textured["groups"][0]["albedo_maps"][0], "image 0");
}

/// `kage bench scale` at two small sizes: a row per size, every technique's figures, the slopes,
/// the CSV with one line per size and the chart.
#[test]
fn bench_scale_writes_its_table_and_chart() {
    let dir = scratch_dir("cli-scale");
    let out = dir.to_str().unwrap();
    let run = kage(&[
        "bench",
        "scale",
        "--triangles",
        "300,3000",
        "--rays",
        "32",
        "--techniques",
        "unshadowed,sloan-self",
        "--size",
        "32",
        "--frames",
        "1",
        "--out",
        out,
        "--validate",
    ]);
    let all = text(&run);
    assert!(run.status.success(), "{all}");
    let rows: Vec<&str> =
        all.lines().filter(|l| l.contains("unshadowed: ") && l.contains("sloan-self: ")).collect();
    assert_eq!(rows.len(), 2, "{all}");
    assert!(all.contains("log-log slopes") && all.contains("sloan-self frame"), "{all}");
    let csv = std::fs::read_to_string(dir.join("scale.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    // 300 requested triangles on the 1,800-triangle floor.
    assert!(csv.lines().nth(1).unwrap().starts_with("2088,"), "{csv}");
    let png = image::open(dir.join("scale.png")).unwrap();
    assert!(png.width() > 1000, "{}x{}", png.width(), png.height());
}

/// A PNG that cannot be written is an error, not "wrote" and exit 0 over an empty file: before,
/// the image crate's buffered writer dropped the error of its last write. `--out` and
/// `--diff` as links to `/dev/full` fail naming the file and the cause; a PNG written to a
/// regular file leaves no temporary file beside it.
#[cfg(unix)]
#[test]
fn png_writes_that_fail_are_errors() {
    use kage::imageio::RgbaF32Image;
    let dir = scratch_dir("cli-png-full");
    let full = dir.join("full.png");
    std::os::unix::fs::symlink("/dev/full", &full).unwrap();
    let full = full.to_str().unwrap();
    let exr = dir.join("a.exr");
    let pixels = vec![[0.5, 0.5, 0.5, 1.0]; 64];
    kage::imageio::write(&exr, &RgbaF32Image { width: 8, height: 8, pixels }, 1.0).unwrap();
    let exr = exr.to_str().unwrap();
    let render = ["render", "--technique", "unshadowed", "--width", "16", "--height", "16", "--frames", "1"];
    for args in [vec!["compare", exr, exr, "--diff", full], [&render[..], &["--out", full]].concat()] {
        let out = kage(&args);
        let message = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {message}");
        assert!(!message.contains("wrote"), "{args:?}: {message}");
        assert!(message.contains("full.png: cannot write") && message.contains("No space left"), "{message}");
    }
    let good = dir.join("diff.png");
    let out = kage(&["compare", exr, exr, "--diff", good.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left.len(), 3, "{left:?}");
    assert!(image::open(&good).is_ok());
}

/// An unusable cache folder (here a file in its place) no longer fails a render: the transfer
/// is computed, used and not cached, with a warning naming the file and why. `kage
/// precompute`, whose purpose is the cache file, still fails.
#[test]
fn render_degrades_without_a_usable_cache() {
    let dir = scratch_dir("cli-cache-file");
    let cache = dir.join("not-a-folder");
    std::fs::write(&cache, b"a file").unwrap();
    let cache = cache.to_str().unwrap();
    let out = dir.join("out.exr");
    let prt = ["--cache", cache, "--rays", "16", "--bands", "2"];
    let render = ["render", "--technique", "sloan-self", "--width", "16", "--height", "16", "--frames", "1"];
    let run = kage(&[&render[..], &prt, &["--out", out.to_str().unwrap()]].concat());
    let message = text(&run);
    assert!(run.status.success(), "{message}");
    assert!(message.contains("warning: transfer computed") && message.contains("not-a-folder"), "{message}");
    assert!(out.is_file());
    let run = kage(&[&["precompute"][..], &prt].concat());
    assert_eq!(run.status.code(), Some(1), "{}", text(&run));
}

/// Inputs of any length are quoted clipped with a count: before, a 100,000-character scene
/// name made a 100 KB message and a scene file's 1,000,000-character unknown key a 1 MB one.
#[test]
fn long_names_in_messages_are_clipped_with_a_count() {
    let dir = scratch_dir("cli-long-names");
    let long_key = dir.join("long-key.json");
    std::fs::write(&long_key, format!(r#"{{"{}": 1}}"#, "k".repeat(1_000_000))).unwrap();
    let cases = [("q".repeat(100_000), "(998"), (long_key.display().to_string(), "(999")];
    for (scene, count) in cases {
        let output = kage(&["render", "--scene", &scene, "--out", dir.join("x.png").to_str().unwrap()]);
        let message = text(&output);
        assert!(!output.status.success(), "{message}");
        assert!(
            message.len() < 2000 && message.contains(count),
            "{} bytes: {}",
            message.len(),
            &message[..message.len().min(600)]
        );
    }
    // A 300-character scene name never reaches a file name: the cache is named by a hash.
    let named = dir.join("named.json");
    let ball = r#"{"name": "ball", "meshes": [{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}]}"#;
    let json = format!(
        r#"{{"name": "{}", "camera": {{"position": [0, 2, 6], "target": [0, 0, 0], "fov_y_deg": 40}},
            "environment": {{"constant": [1, 1, 1]}}, "groups": [{ball}]}}"#,
        "n".repeat(300)
    );
    std::fs::write(&named, json).unwrap();
    let cache = dir.join("cache");
    let output = kage(&[
        "precompute",
        "--scene",
        named.to_str().unwrap(),
        "--rays",
        "16",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", text(&output));
}

/// README stays readable as text: no line over 400 characters (per-flag detail lives in
/// `--help` and docs/cli.md, not in table rows of several thousand characters).
#[test]
fn readmes_lines_are_short() {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../README.md")).unwrap();
    let long: Vec<String> = readme
        .lines()
        .enumerate()
        .filter(|(_, l)| l.chars().count() >= 400)
        .map(|(i, l)| format!("line {}: {} characters", i + 1, l.chars().count()))
        .collect();
    assert!(long.is_empty(), "README.md has long lines:\n{}", long.join("\n"));
}
