//! The arguments and helpers every command shares: the GPU (`--validate`, `--device`), the
//! scene (`--scene`, `--keyframe`, `--env`), "x,y,z" values and `--probes` with probe files.
use anyhow::{bail, Context as _, Result};
use glam::DVec3;
use kage::backend::{Context, ContextDesc};
use kage::files;
use kage::scene::Scene;
use kage::techniques::description::{RenderedLight, TechniqueKind};
use kage::techniques::probes::{positions_file, ProbePlacement, DEFAULT_TOLERANCE};
use std::path::Path;
use std::sync::Arc;

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
    /// A built-in scene name (teapot, teapot-hires-floor, probe-room, asm, atrium, two-rooms), a scene
    /// file (.json), a glTF 2.0 file (.gltf, .glb), or a folder holding scene.json.
    #[arg(long, default_value = "teapot")]
    scene: String,
    /// Look from keyframe K (from 0) of the scene's camera walkthrough instead of its camera.
    #[arg(long)]
    pub keyframe: Option<usize>,
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

/// A technique's name as the command line spells it.
pub fn technique_name(kind: TechniqueKind) -> String {
    clap::ValueEnum::to_possible_value(&kind)
        .map_or_else(|| format!("{kind:?}"), |v| v.get_name().to_string())
}

/// Says so when the scene has lights that `kind` leaves out ([`TechniqueKind::rendered_light`]):
/// each technique renders its paper's light, and a spot missing from a picture should not pass
/// for a bug.
pub fn report_unrendered_lights(kind: TechniqueKind, scene: &Scene) {
    let lights = scene.lights.len();
    let name = technique_name(kind);
    let note = match kind.rendered_light() {
        RenderedLight::Environment if lights > 0 => format!(
            "technique {name} renders the environment alone: the scene's {lights} point or spot light(s) are left out (`shadowmap` and `asm` render them)"
        ),
        RenderedLight::Probes if lights > 0 => format!(
            "the scene's {lights} point or spot light(s) reach the moving groups through the probes' capture but not the static groups, which technique {name} lights by the environment alone"
        ),
        _ => return,
    };
    eprintln!("kage: note: {note}");
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

/// `--probes`: `grid:NX,NY,NZ`, `auto[:TOL[:NX,NY,NZ]]`, `scene` or a probe file.
pub fn probe_placement(arg: &str, scene: &Scene) -> Result<ProbePlacement> {
    if arg == "scene" {
        if scene.probes.is_empty() {
            anyhow::bail!(
                "--probes scene: scene \"{}\" places no probes (its file has no \"probes\")",
                scene.name
            );
        }
        let positions: Vec<glam::DVec3> = scene.probes.iter().map(|p| p.position.as_dvec3()).collect();
        return Ok(ProbePlacement::Positions(positions.into()));
    }
    let counts = |text: &str, form: &str| -> Result<[u32; 3]> {
        let counts: Vec<u32> = text
            .split(',')
            .map(|n| n.trim().parse())
            .collect::<Result<_, _>>()
            .with_context(|| format!("--probes {arg}: expected {form} with whole numbers"))?;
        counts.try_into().map_err(|_| anyhow::anyhow!("--probes {arg}: expected three counts, {form}"))
    };
    if let Some(grid) = arg.strip_prefix("grid:") {
        return Ok(ProbePlacement::Grid(counts(grid, "grid:NX,NY,NZ")?));
    }
    if arg == "auto" || arg.starts_with("auto:") {
        let mut parts = arg.splitn(3, ':').skip(1);
        let tolerance = match parts.next() {
            Some(t) => t
                .trim()
                .parse()
                .with_context(|| format!("--probes {arg}: expected auto:TOL with TOL a number"))?,
            None => DEFAULT_TOLERANCE,
        };
        let candidates = parts.next().map(|c| counts(c, "auto:TOL:NX,NY,NZ")).transpose()?;
        return Ok(ProbePlacement::Auto { tolerance, candidates });
    }
    Ok(ProbePlacement::Positions(read_positions(std::path::Path::new(arg))?.into()))
}

/// The positions of a probe file.
pub fn read_positions(path: &Path) -> Result<Vec<DVec3>> {
    let bytes = files::read(path, files::JSON).with_context(|| format!("reading {}", path.display()))?;
    positions_file::parse(&bytes).with_context(|| path.display().to_string())
}
