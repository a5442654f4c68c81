//! `kage scene ...`: scene utilities.
use anyhow::{Context as _, Result};
use clap::Subcommand;
use kage::scene::SceneFormat;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum SceneCommand {
    /// Write a self-contained copy of a scene: DIR/scene.json and the environment as EXR, with
    /// every mesh as OBJ (--format json) or the groups, meshes, lights, camera and motion as
    /// DIR/scene.glb (--format gltf, which Blender and three.js open); `kage render --scene
    /// DIR` renders the same picture.
    Export {
        /// A built-in scene name or a scene file.
        #[arg(long, default_value = "teapot")]
        scene: String,
        #[arg(long)]
        out: PathBuf,
        #[arg(long, value_enum, default_value_t)]
        format: SceneFormat,
    },
}

pub fn run(command: &SceneCommand) -> Result<()> {
    match command {
        SceneCommand::Export { scene, out, format } => {
            let loaded = crate::read_scene(scene, false)?;
            loaded.export(out, *format).with_context(|| format!("exporting scene {scene}"))?;
            println!("wrote {}", out.join(kage::scene::SCENE_FILE).display());
            if *format == SceneFormat::Gltf {
                println!("wrote {}", out.join(kage::scene::GLTF_FILE).display());
            }
            Ok(())
        }
    }
}
