//! `kage`: the command-line front end of the Kage engine.
mod bench;
mod bench_asm;
mod bench_probe_count;
mod bench_probes;
mod bench_scale;
mod compare;
mod env_cmd;
mod info;
mod outputs;
mod precompute;
mod probe_image;
mod probes;
mod progress;
mod reference;
mod render;
mod scene_cmd;
mod sh_cmd;
mod sweep;
mod trace;
mod transfer_source;

use anyhow::{bail, Context as _, Result};
use clap::{Parser, Subcommand};
use kage::backend::{Context, ContextDesc};
use std::sync::Arc;

#[derive(Parser)]
#[command(name = "kage", version, about = "Kage (影): real-time lighting on raw Vulkan")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Options every GPU command takes.
#[derive(clap::Args, Clone, Debug)]
pub struct GpuArgs {
    /// Turn on VK_LAYER_KHRONOS_validation; any warning or error it reports fails the command.
    #[arg(long)]
    validate: bool,
    /// Use the first Vulkan device whose name contains this (default: $KAGE_DEVICE, else a
    /// discrete GPU, else any).
    #[arg(long)]
    device: Option<String>,
}

impl GpuArgs {
    pub fn context(&self) -> Result<Arc<Context>> {
        Ok(Context::new(&ContextDesc { validation: self.validate, device: self.device.clone() })?)
    }

    /// Fails when validation reported anything during the command.
    pub fn finish(&self, ctx: &Context) -> Result<()> {
        let messages = ctx.take_validation_messages();
        if !messages.is_empty() {
            bail!("validation reported {} message(s); the first: {}", messages.len(), messages[0]);
        }
        Ok(())
    }
}

/// The scene a command looks at: `--scene` and, optionally, a keyframe of its walkthrough.
#[derive(clap::Args, Clone, Debug)]
pub struct SceneArgs {
    /// A built-in scene name (teapot, teapot-hires-floor, probe-room, asm, atrium), a scene
    /// file (.json), a glTF 2.0 file (.gltf, .glb), or a folder holding scene.json.
    #[arg(long, default_value = "teapot")]
    scene: String,
    /// Look from keyframe K (from 0) of the scene's camera walkthrough instead of its camera.
    #[arg(long)]
    keyframe: Option<usize>,
    /// Light the scene with this equirectangular map (.exr or .hdr, 2:1) instead of its own
    /// (`kage env sun` makes sun maps).
    #[arg(long)]
    env: Option<std::path::PathBuf>,
}

impl SceneArgs {
    pub fn load(&self) -> Result<kage::scene::Scene> {
        let mut scene = read_scene(&self.scene, self.env.is_some())?;
        if let Some(k) = self.keyframe {
            let Some(camera) = scene.walkthrough.get(k) else {
                bail!(
                    "--keyframe {k}: scene {} has {} walkthrough keyframes (\"walkthrough\" in scene files)",
                    scene.name,
                    scene.walkthrough.len()
                );
            };
            scene.camera = *camera;
        }
        if let Some(path) = &self.env {
            scene.environment =
                kage::scene::EnvMap::load(path).with_context(|| format!("--env {}", path.display()))?;
        }
        report_clamped(&scene.environment);
        Ok(scene)
    }
}

/// The scene a `--scene` argument names ([`kage::scene::Scene::from_arg`]), with a note when its
/// file gives no environment, so that it is lit by the default sky, unless the command lights it
/// with maps of its own (`env_replaced`: `--env`). The loader leaves the note to its caller,
/// which alone knows whether the default stays.
pub fn read_scene(arg: &str, env_replaced: bool) -> Result<kage::scene::Scene> {
    let loaded = kage::scene::Scene::read_arg(arg)?;
    if loaded.default_environment && !env_replaced {
        eprintln!(
            "kage: note: {arg} has no environment: lit by a constant sky of radiance {} (give one with \
             --env or \"environment\" in a scene file)",
            kage::scene::DEFAULT_SKY
        );
    }
    Ok(loaded.scene)
}

/// Says so when loading an environment map changed it (negative texels clamped to 0).
pub fn report_clamped(map: &kage::scene::EnvMap) {
    if map.clamped_negative() > 0 {
        eprintln!(
            "kage: note: {} negative texel value(s) in the environment map were clamped to 0",
            map.clamped_negative()
        );
    }
}

/// Parses "x,y,z" (a `--at`-style argument) into three finite numbers.
pub fn parse_xyz<T>(s: &str) -> Result<[T; 3], String>
where
    T: std::str::FromStr + Into<f64> + Copy,
    T::Err: std::fmt::Display,
{
    let parts: Vec<T> = s
        .split(',')
        .map(|p| p.trim().parse::<T>().map_err(|e| format!("{p:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match parts[..] {
        [x, y, z] if parts.iter().all(|&v| v.into().is_finite()) => Ok([x, y, z]),
        _ => Err(format!("expected three finite numbers x,y,z, got {s:?}")),
    }
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene offscreen to PNG (tonemapped, sRGB) or EXR (linear radiance).
    Render(render::RenderArgs),
    /// Print an environment map's 9 SH coefficients per channel (projected on the GPU).
    Sh(sh_cmd::ShArgs),
    /// Environment-map utilities: synthetic sun maps.
    #[command(subcommand)]
    Env(env_cmd::EnvCommand),
    /// Print the device, driver, Vulkan version and each feature Kage uses.
    Info(GpuArgs),
    /// Precompute the PRT transfer of every vertex (cached; prints time and bytes).
    Precompute(precompute::PrecomputeArgs),
    /// Scene utilities.
    #[command(subcommand)]
    Scene(scene_cmd::SceneCommand),
    /// Ray-traced ground truth: Monte Carlo direct lighting with full visibility (an image,
    /// or irradiance at listed points).
    Reference(reference::ReferenceArgs),
    /// Error metrics of one EXR image against a reference, and a false-colour difference.
    Compare(compare::CompareArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// A technique's settings side by side: error against the reference at several poses, GPU
    /// time per frame, precomputation time and memory, written to DIR/sweep.csv.
    Sweep(sweep::SweepArgs),
    /// Light probes: tetrahedralize a probe set, look a point up in it, capture one from an
    /// image, place probes in a scene automatically.
    #[command(subcommand)]
    Probes(probes::ProbesCommand),
}

fn main() {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`kage render | head -1`) would
    // panic; the default disposition ends the process quietly, as other command-line tools do.
    // SAFETY: no other thread exists yet, and SIG_DFL is a valid disposition for SIGPIPE.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL)
    };
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Sh(args) => sh_cmd::run(&args),
        Command::Env(command) => env_cmd::run(&command),
        Command::Info(args) => info::run(&args),
        Command::Precompute(args) => precompute::run(&args),
        Command::Scene(command) => scene_cmd::run(&command),
        Command::Reference(args) => reference::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Bench(command) => bench::run(&command),
        Command::Sweep(args) => sweep::run(&args),
        Command::Probes(command) => probes::run(&command),
    };
    if let Err(e) = result {
        // Arguments and file contents quoted in the message are clipped to a readable length.
        eprintln!("kage: error: {}", kage::scene::clip_message(&format!("{e:#}")));
        std::process::exit(1);
    }
}
