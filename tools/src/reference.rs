//! `kage reference`: the ray-traced ground truth, rendered progressively in batches with a
//! progress bar and a running estimate of the noise left; or, with `--irradiance`, E(p, n) at
//! listed points.
use crate::args::GpuArgs;
use crate::progress::Bar;
use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use kage::files;
use kage::reference::{
    IrradianceFile, IrradianceReference, LightMode, PointsFile, ReferenceOptions, ReferenceRenderer,
    Statistics,
};
use kage::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Args)]
pub struct ReferenceArgs {
    #[command(flatten)]
    scene: crate::args::SceneArgs,
    /// Samples per pixel (or per point). Each sample casts two shadow rays (one drawn from the
    /// environment, one cosine-weighted). The paper's reference uses 16384.
    #[arg(long, default_value_t = 1024)]
    spp: u32,
    /// Output: .exr (linear radiance, 32-bit float; .png gives a tonemapped preview); with
    /// --irradiance, a .json file.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    exposure: crate::outputs::Exposure,
    /// env: the environment map with full visibility; local: the scene's point and spot
    /// lights with hard shadows (no environment, black background; deterministic, so one
    /// sample per pixel is exact and --spp is not used).
    #[arg(long, value_enum, default_value_t = LightArg::Env)]
    light: LightArg,
    /// With --light local: also write the edge ties (.exr) for `kage compare --edges`: per
    /// pixel the lowest (R) and highest (G) luminance with the primary ray moved by the
    /// device's sub-pixel precision (B, in bits) to each side, where a raster render cannot
    /// be told right from wrong.
    #[arg(long)]
    edges: Option<PathBuf>,
    /// Stop after this many seconds (at a batch boundary) even if --spp is not reached.
    #[arg(long)]
    time_budget: Option<f64>,
    #[arg(long, default_value_t = 512, conflicts_with = "irradiance")]
    width: u32,
    #[arg(long, default_value_t = 512, conflicts_with = "irradiance")]
    height: u32,
    /// Compute irradiance at the points of this file instead of an image:
    /// {"points": [{"position": [x, y, z], "normal": [x, y, z]}, ...]}.
    #[arg(long, conflicts_with = "light")]
    irradiance: Option<PathBuf>,
    /// With --irradiance: light arriving after up to this many reflections off the surfaces
    /// (0: the environment and the point and spot lights, with shadows; 1: and the surfaces lit by
    /// them; 2: and lit by each other once). The surfaces' radiance is computed per vertex and
    /// interpolated across triangles, exactly as light probes capture it (`--bounces 2` is what
    /// `--technique probes` captures by default; the reference's scene keeps its moving group).
    #[arg(long, default_value_t = 0, requires = "irradiance")]
    bounces: u32,
    /// Samples per vertex and bounce for the surfaces' radiance (that of the probes by default).
    #[arg(long, default_value_t = kage::techniques::probes::DEFAULT_SAMPLES, requires = "irradiance")]
    bounce_samples: u32,
    /// Picks the random sequence; references with different seeds are independent.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum LightArg {
    Env,
    Local,
}

/// The longest one batch (one submission) should take: long enough that the per-batch work
/// (primary rays, as costly as a sample on lavapipe) is shared by several samples, short enough
/// for a lively progress bar and far from any driver timeout. Batches are sized from the average
/// time per sample, which includes that fixed part, so they come out somewhat shorter.
const BATCH_TARGET: Duration = Duration::from_secs(2);

/// How often the noise estimate is refreshed: it reads every item's statistics back.
const NOISE_INTERVAL: Duration = Duration::from_secs(2);

/// The part of the two reference kinds that the batch loop drives.
trait Progressive {
    fn run_batch(&mut self, spp: u32) -> kage::Result<()>;
    fn samples(&self) -> u32;
    fn statistics(&self) -> kage::Result<Statistics>;
}

impl Progressive for ReferenceRenderer {
    fn run_batch(&mut self, spp: u32) -> kage::Result<()> {
        ReferenceRenderer::run_batch(self, spp)
    }
    fn samples(&self) -> u32 {
        ReferenceRenderer::samples(self)
    }
    fn statistics(&self) -> kage::Result<Statistics> {
        ReferenceRenderer::statistics(self)
    }
}

impl Progressive for IrradianceReference {
    fn run_batch(&mut self, spp: u32) -> kage::Result<()> {
        IrradianceReference::run_batch(self, spp)
    }
    fn samples(&self) -> u32 {
        IrradianceReference::samples(self)
    }
    fn statistics(&self) -> kage::Result<Statistics> {
        IrradianceReference::statistics(self)
    }
}

pub fn run(args: &ReferenceArgs) -> Result<()> {
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    if let Some(budget) = args.time_budget {
        if !(budget.is_finite() && budget > 0.0) {
            bail!("--time-budget must be a positive number of seconds, got {budget}");
        }
    }
    // Irradiance results are written as .json, images as .png or .exr.
    let extensions: &[&str] = if args.irradiance.is_some() { &["json"] } else { &["png", "exr"] };
    crate::outputs::check(&args.out, "--out", extensions)?;
    if let Some(edges) = &args.edges {
        if args.light != LightArg::Local || args.irradiance.is_some() {
            bail!("--edges comes with --light local (the edge ties of a local-light image)");
        }
        crate::outputs::check(edges, "--edges", &["exr"])?;
    }
    // Bad input files fail before the GPU is set up.
    let points = args.irradiance.as_deref().map(read_points).transpose()?;
    let scene = args.scene.load()?;
    let exposure = args.exposure.checked(&scene)?;
    let ctx = args.gpu.context()?;
    match points {
        Some(points) => run_irradiance(args, &ctx, &scene, &points)?,
        None => run_image(args, &ctx, &scene, exposure)?,
    }
    args.gpu.finish(&ctx)
}

fn run_image(
    args: &ReferenceArgs,
    ctx: &std::sync::Arc<kage::backend::Context>,
    scene: &Scene,
    exposure: crate::outputs::ExposureRule,
) -> Result<()> {
    let light = match args.light {
        LightArg::Env => LightMode::Environment,
        LightArg::Local => LightMode::Local,
    };
    if light == LightMode::Local && scene.lights.is_empty() {
        eprintln!("kage: note: scene {} has no local lights: the image is black", scene.name);
    }
    let mut renderer = ReferenceRenderer::new(
        ctx,
        scene,
        &ReferenceOptions { width: args.width, height: args.height, light, seed: args.seed },
    )
    .context("setting up the reference renderer")?;
    let start = Instant::now();
    let statistics = if light == LightMode::Local {
        if args.spp > 1 {
            eprintln!(
                "kage: note: local lights with hard shadows are deterministic; 1 sample per pixel is exact, --spp is not used"
            );
        }
        renderer.run_batch(1)?;
        renderer.statistics()?
    } else {
        progressive(&mut renderer, args.spp, args.time_budget, "pixel")?
    };
    let image = renderer.to_image(&statistics);
    kage::imageio::write(&args.out, &image, exposure.for_image(&image))?;
    if let Some(path) = &args.edges {
        let edges = renderer.edge_ties()?;
        kage::imageio::write(path, &edges.to_image(), 1.0)?;
        println!("wrote {} (edge ties at 1/{} px)", path.display(), 1u32 << edges.bits);
    }
    println!(
        "wrote {} ({}x{}, scene {}, {} light, {} spp, {:.1} s, {})",
        args.out.display(),
        args.width,
        args.height,
        scene.name,
        match light {
            LightMode::Environment => "environment",
            LightMode::Local => "local",
        },
        statistics.samples,
        start.elapsed().as_secs_f64(),
        ctx.info().name
    );
    if light == LightMode::Environment {
        print_noise(&statistics);
    }
    Ok(())
}

fn read_points(path: &Path) -> Result<PointsFile> {
    let bytes = files::read(path, files::JSON).with_context(|| format!("reading {}", path.display()))?;
    let text = std::str::from_utf8(&bytes).with_context(|| format!("in {}", path.display()))?;
    PointsFile::parse(text).with_context(|| format!("in {}", path.display()))
}

fn run_irradiance(
    args: &ReferenceArgs,
    ctx: &std::sync::Arc<kage::backend::Context>,
    scene: &Scene,
    points: &PointsFile,
) -> Result<()> {
    let radiance = kage::reference::surface_radiance(
        ctx,
        scene,
        args.bounces,
        args.bounce_samples,
        kage::techniques::probes::RADIANCE_SEED,
    )
    .context("computing the surfaces' radiance")?
    .radiance;
    let mut reference =
        IrradianceReference::with_radiance(ctx, scene, &points.points, args.seed, radiance.as_deref())
            .context("setting up the irradiance reference")?;
    let start = Instant::now();
    let statistics = progressive(&mut reference, args.spp, args.time_budget, "point")?;
    let file = IrradianceFile::from_statistics(&statistics);
    std::fs::write(&args.out, serde_json::to_string_pretty(&file)?)
        .with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "wrote {} ({} points, scene {}, {} spp, {:.1} s, {})",
        args.out.display(),
        points.points.len(),
        scene.name,
        statistics.samples,
        start.elapsed().as_secs_f64(),
        ctx.info().name
    );
    print_noise(&statistics);
    Ok(())
}

/// Runs batches until `spp` samples (or the time budget) are reached. Batches start at one
/// sample and are then sized from the last one's time to take at most about [`BATCH_TARGET`] (at
/// most 4× the previous, so the first batch's compile time cannot blow up the second).
fn progressive(
    reference: &mut impl Progressive,
    spp: u32,
    time_budget: Option<f64>,
    item: &str,
) -> Result<Statistics> {
    let bar = Bar::new(u64::from(spp), &format!("samples per {item}"));
    bar.message("sampling");
    let start = Instant::now();
    let budget = time_budget.map(Duration::from_secs_f64);
    let mut batch = 1u32;
    let mut last_noise = start;
    while reference.samples() < spp {
        let mut size = batch.min(spp - reference.samples());
        if let Some(budget) = budget {
            let left = budget.saturating_sub(start.elapsed());
            if left.is_zero() && reference.samples() > 0 {
                break;
            }
            // Shrink the last batch to what the remaining time allows at the last speed.
            if reference.samples() > 0 {
                let per_sample = start.elapsed().as_secs_f64() / f64::from(reference.samples());
                size = size.min(((left.as_secs_f64() / per_sample) as u32).max(1));
            }
        }
        let batch_start = Instant::now();
        reference.run_batch(size)?;
        let seconds = batch_start.elapsed().as_secs_f64().max(1e-6);
        let next = (BATCH_TARGET.as_secs_f64() / seconds * f64::from(size)) as u32;
        batch = next.clamp(1, size.saturating_mul(4));
        bar.at(u64::from(reference.samples()), u64::from(spp));
        if reference.samples() >= 2 && last_noise.elapsed() >= NOISE_INTERVAL {
            if let Some(noise) = reference.statistics()?.relative_standard_error() {
                bar.message(format!("relative standard error {noise:.2e}"));
            }
            last_noise = Instant::now();
        }
    }
    drop(bar);
    if reference.samples() < spp {
        eprintln!(
            "kage: note: the time budget ran out after {} of {spp} samples per {item}",
            reference.samples()
        );
    }
    Ok(reference.statistics()?)
}

fn print_noise(statistics: &Statistics) {
    match statistics.relative_standard_error() {
        Some(noise) => println!(
            "relative standard error {noise:.3e} (RMS over items and channels of the standard error of the mean, / mean; it predicts the relative RMSE against a converged reference)"
        ),
        None => println!("standard error: needs at least 2 samples (and a non-black result)"),
    }
}
