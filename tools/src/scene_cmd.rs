//! `kage scene ...`: scene utilities.
use anyhow::{Context as _, Result};
use clap::Subcommand;
use kage::scene::{Scene, SceneFormat};
use kage::techniques::probes::ProbeGroups;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Subcommand)]
pub enum SceneCommand {
    /// Write a self-contained copy of a scene: DIR/scene.json and the environment as EXR, with
    /// every mesh as OBJ (--format json) or the groups, meshes, lights, camera and motion as
    /// DIR/scene.glb (--format gltf, which Blender and three.js open); `kage render --scene
    /// DIR` renders the same picture.
    ///
    /// kage scene export [--scene NAME|FILE] --out DIR [--format json|gltf]: writes
    /// `DIR/scene.json` and the environment as 32-bit EXR, with every mesh as OBJ (`json`, the
    /// default) or the groups, meshes, lights, camera and motion as `DIR/scene.glb` (`gltf`: opens
    /// in Blender and three.js, see "glTF 2.0"); `--scene DIR` reads `DIR/scene.json` back (a
    /// folder without one never hides a built-in name); either folder reads back as the same scene
    /// and renders exactly the built-in scene's picture with every technique (tested)
    Export {
        /// A built-in scene name or a scene file.
        #[arg(long, default_value = "teapot")]
        scene: String,
        #[arg(long)]
        out: PathBuf,
        #[arg(long, value_enum, default_value_t)]
        format: SceneFormat,
    },
    /// What Kage made of a scene: the time to read it, its groups (meshes, triangles, albedo
    /// maps, moving or static: the moving ones are those with keyframes, which the probes light),
    /// lights and camera.
    ///
    /// kage scene info [--scene NAME|FILE] [--json]: what Kage made of a scene: the time to read
    /// it, triangles, vertices and albedo-map texels, each group's meshes, triangles and albedo
    /// maps and whether it moves (the groups with keyframes, which the probes light; without any,
    /// the first), the lights
    Info {
        /// A built-in scene name, a scene file, or a glTF or OBJ file.
        #[arg(long, default_value = "teapot")]
        scene: String,
        /// Print one JSON object on stdout instead of text.
        #[arg(long)]
        json: bool,
    },
}

pub fn run(command: &SceneCommand) -> Result<()> {
    match command {
        SceneCommand::Export { scene, out, format } => {
            let loaded = crate::args::read_scene(scene, false)?;
            loaded.export(out, *format).with_context(|| format!("exporting scene {scene}"))?;
            println!("wrote {}", out.join(kage::scene::SCENE_FILE).display());
            if *format == SceneFormat::Gltf {
                println!("wrote {}", out.join(kage::scene::GLTF_FILE).display());
            }
            Ok(())
        }
        SceneCommand::Info { scene, json } => {
            let start = Instant::now();
            let loaded = crate::args::read_scene(scene, false)?;
            let read_ms = 1e3 * start.elapsed().as_secs_f64();
            let info = describe(&loaded, read_ms);
            if *json {
                println!("{info}");
            } else {
                print_info(&info);
            }
            Ok(())
        }
    }
}

/// The scene as `kage scene info --json` prints it.
fn describe(scene: &Scene, read_ms: f64) -> serde_json::Value {
    let moving = ProbeGroups::of(scene);
    let groups: Vec<_> = scene
        .groups
        .iter()
        .enumerate()
        .map(|(g, group)| {
            let triangles: usize = group.meshes.iter().map(|m| m.triangle_count()).sum();
            let maps: Vec<String> = group
                .meshes
                .iter()
                .filter_map(|m| m.texturing.as_ref())
                .map(|t| t.map.name.clone())
                .collect();
            json!({
                "name": group.name,
                "meshes": group.meshes.len(),
                "triangles": triangles,
                "albedo_maps": maps,
                "keyframes": group.motion.as_ref().map_or(0, |m| m.keys.len()),
                "moving": moving.is_moving(g),
            })
        })
        .collect();
    // Each map once, however many meshes share it.
    let mut maps: Vec<&kage::scene::AlbedoMap> = Vec::new();
    for t in scene.meshes().filter_map(|(_, m)| m.texturing.as_ref()) {
        if !maps.iter().any(|m| std::ptr::eq(*m, &*t.map)) {
            maps.push(&t.map);
        }
    }
    let c = &scene.camera;
    json!({
        "scene": scene.name,
        "read_ms": read_ms,
        "triangles": scene.triangle_count(),
        "vertices": scene.vertex_count(),
        "albedo_map_texels": maps.iter().map(|m| u64::from(m.width) * u64::from(m.height)).sum::<u64>(),
        "moving_by_fallback": moving.fallback(),
        "groups": groups,
        "lights": scene.lights.len(),
        "camera": {"position": c.position.to_array(), "target": c.target.to_array(), "fov_y_deg": c.fov_y_deg},
    })
}

fn print_info(info: &serde_json::Value) {
    println!(
        "scene {}: read in {:.1} ms; {} triangles, {} vertices, {} albedo-map texels, {} point or spot lights",
        info["scene"].as_str().unwrap_or(""),
        info["read_ms"].as_f64().unwrap_or(0.0),
        info["triangles"],
        info["vertices"],
        info["albedo_map_texels"],
        info["lights"]
    );
    for group in info["groups"].as_array().into_iter().flatten() {
        let maps = group["albedo_maps"].as_array().map_or(0, Vec::len);
        let motion = match (group["moving"].as_bool(), group["keyframes"].as_u64()) {
            (Some(true), Some(0)) => "moving (no group has keyframes: the first one is taken)".to_string(),
            (Some(true), Some(k)) => format!("moving ({k} keyframes)"),
            _ => "static".to_string(),
        };
        println!(
            "  group {}: {} meshes, {} triangles, {maps} with an albedo map; {motion}",
            group["name"], group["meshes"], group["triangles"]
        );
    }
}
