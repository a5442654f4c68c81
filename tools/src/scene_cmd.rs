//! `kage scene ...`: scene utilities.
use anyhow::{Context as _, Result};
use clap::Subcommand;
use kage::scene::Scene;
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum SceneCommand {
    /// Write a self-contained copy of a scene: DIR/scene.json, every mesh as OBJ and the
    /// environment as EXR; `kage render --scene DIR/scene.json` renders the same picture.
    Export {
        /// A built-in scene name or a scene file.
        #[arg(long, default_value = "teapot")]
        scene: String,
        #[arg(long)]
        out: PathBuf,
    },
}

pub fn run(command: &SceneCommand) -> Result<()> {
    match command {
        SceneCommand::Export { scene, out } => {
            let loaded = Scene::from_arg(scene)?;
            loaded.export(out).with_context(|| format!("exporting scene {scene}"))?;
            println!("wrote {}", out.join(kage::scene::SCENE_FILE).display());
            Ok(())
        }
    }
}
