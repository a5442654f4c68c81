//! `kage sweep`: a technique's settings side by side in one process: each setting's error
//! against the ray-traced reference at several poses of the animation, its GPU time per frame
//! while the scene moves, its precomputation time and its device memory, in `DIR/sweep.csv`;
//! time against error in `DIR/pareto.png`; and, asked, the setting to pick under a bound.
mod asm;
mod converged;
mod probes;

use crate::args::GpuArgs;
use crate::chart;
use crate::chart::pick::{self, Point};
use crate::progress::Bar;
use crate::transfer_source::PrtArgs;
use anyhow::{bail, Context as _, Result};
use clap::Args;
use kage::backend::Context;
use kage::pass::TimingTable;
use kage::prt::{PrtParams, TransferSet};
use kage::reference::compare;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{EnvMap, Scene};
use kage::techniques::description::{TechniqueDesc, TechniqueKind};
use kage::techniques::tamura::technique::OcclusionSettings;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweptTechnique {
    /// Unshadowed SH irradiance; Sloan's PRT at 2 to 5 bands (self-shadowing only) and with the
    /// whole scene's visibility at rest; Tamura as the paper has it at q = 32 and Kage's default
    /// at q = 4 to 64; parallel lights at q = 32, 64, 128 (the paper's Fig. 3).
    Prt,
    /// Adaptive shadow maps at 4, 8, 16 MB against conventional maps of 1024², 2048², 4096²
    /// over the scene's camera walkthrough (`kage bench asm`'s measurement).
    Asm,
    /// Light probes: grids (trilinear and tetrahedral) against automatic placement
    /// (tetrahedral), error against probe count (`kage bench probe-count`'s measurement).
    Probes,
}

#[derive(Args)]
pub struct SweepArgs {
    #[arg(long, value_enum)]
    technique: SweptTechnique,
    /// A built-in scene name or a scene file (.json, or glTF 2.0: .gltf, .glb); default: teapot (prt), asm (asm),
    /// probe-room (probes).
    #[arg(long)]
    scene: Option<String>,
    /// Environment maps to sweep over, each replacing the scene's (default: the scene's own).
    #[arg(long = "env")]
    envs: Vec<PathBuf>,
    /// Times in the scene's motion (seconds of its groups' keyframes; the built-in scenes' hop
    /// loops in one) at which the error is measured; 0 is the scene pose (the teapot standing on
    /// the floor: contact).
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 0.125, 0.6])]
    poses: Vec<f32>,
    /// Only these settings, e.g. `unshadowed,sloan-self:3,tamura:32,parallel-lights:32` (prt) or
    /// `shadowmap:2048,asm:8` (asm).
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Side of the images compared with the reference, pixels (asm: also of the timed frames).
    #[arg(long, default_value_t = 128)]
    size: u32,
    /// probes: reference samples per test point (default 512). The prt sweep runs its
    /// references to `--noise` instead.
    #[arg(long)]
    spp: Option<u32>,
    /// prt: each reference runs until its relative standard error is at most this (it is
    /// printed beside every error), and is cached under the cache folder.
    #[arg(long, default_value_t = 0.005)]
    noise: f64,
    /// prt: the most samples per pixel a reference may take to reach `--noise`.
    #[arg(long, default_value_t = 65536)]
    max_spp: u32,
    /// prt: frames timed per setting while the scene moves (the median is reported; 0: no
    /// timing). asm: samples of the walkthrough (each also timed).
    #[arg(long, default_value_t = 100)]
    frames: u32,
    /// Side of the timed frames, pixels.
    #[arg(long, default_value_t = 512)]
    time_size: u32,
    /// Visibility rays per vertex of the PRT precomputation.
    #[arg(long, default_value_t = PrtParams::DEFAULT.rays)]
    rays: u32,
    /// Cache folder of the PRT transfers (as `kage precompute --cache`) and, in `references/`,
    /// of the prt sweep's references.
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Output folder (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Print the setting to use: the cheapest within `--max-error`, the most accurate within
    /// `--max-ms` (either or both).
    #[arg(long)]
    pick: bool,
    /// With `--pick`: the largest acceptable relative RMSE (mean over the poses).
    #[arg(long, requires = "pick")]
    max_error: Option<f64>,
    /// With `--pick`: the largest acceptable GPU time per frame, ms (prt, asm).
    #[arg(long, requires = "pick")]
    max_ms: Option<f64>,
    /// With `--pick` (probes): the most probes acceptable.
    #[arg(long, requires = "pick")]
    max_probes: Option<u32>,
    /// probes: where the test points are, as `kage bench probe-count --test-region` (`box`:
    /// grids and placement over the static box, measured anywhere in it).
    #[arg(long, value_enum)]
    test_region: Option<crate::bench::probe_count::TestRegion>,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// One point of the sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Setting {
    Unshadowed,
    SloanSelf { bands: u32 },
    SloanScene,
    TamuraPaper { regions: usize },
    Tamura { regions: usize },
    ParallelLights { regions: usize },
}

impl Setting {
    /// The PRT sweep's settings.
    fn all() -> Vec<Setting> {
        std::iter::once(Setting::Unshadowed)
            .chain((2..=5).map(|bands| Setting::SloanSelf { bands }))
            .chain([Setting::SloanScene, Setting::TamuraPaper { regions: 32 }])
            .chain([4, 8, 16, 32, 64].map(|regions| Setting::Tamura { regions }))
            .chain([32, 64, 128].map(|regions| Setting::ParallelLights { regions }))
            .collect()
    }

    /// (technique, parameter, value): the CSV's columns and the `--only` spelling.
    fn describe(self) -> (&'static str, &'static str, String) {
        match self {
            Setting::Unshadowed => ("unshadowed", "", String::new()),
            Setting::SloanSelf { bands } => ("sloan-self", "bands", bands.to_string()),
            Setting::SloanScene => ("sloan-scene", "", String::new()),
            Setting::TamuraPaper { regions } => ("tamura-paper", "regions", regions.to_string()),
            Setting::Tamura { regions } => ("tamura", "regions", regions.to_string()),
            Setting::ParallelLights { regions } => ("parallel-lights", "regions", regions.to_string()),
        }
    }

    fn name(self) -> String {
        match self.describe() {
            (technique, _, value) if value.is_empty() => technique.to_string(),
            (technique, _, value) => format!("{technique}:{value}"),
        }
    }

    /// The technique and its parameters, as `kage render` and the C ABI take them.
    fn technique(self) -> TechniqueDesc {
        let of = TechniqueDesc::new;
        match (self, of(self.kind())) {
            (Setting::SloanSelf { bands }, TechniqueDesc::SloanSelf { prt }) => {
                TechniqueDesc::SloanSelf { prt: PrtParams { bands, ..prt } }
            }
            (Setting::TamuraPaper { regions }, TechniqueDesc::TamuraPaper { prt, mask_size, .. }) => {
                TechniqueDesc::TamuraPaper { prt, regions, mask_size }
            }
            (Setting::Tamura { regions }, TechniqueDesc::Tamura { prt, occlusion }) => {
                TechniqueDesc::Tamura { prt, occlusion: OcclusionSettings { regions, ..occlusion } }
            }
            (Setting::ParallelLights { regions }, TechniqueDesc::ParallelLights { shadow_map_size, .. }) => {
                TechniqueDesc::ParallelLights { regions, shadow_map_size }
            }
            (_, desc) => desc,
        }
    }

    fn kind(self) -> TechniqueKind {
        match self {
            Setting::Unshadowed => TechniqueKind::Unshadowed,
            Setting::SloanSelf { .. } => TechniqueKind::SloanSelf,
            Setting::SloanScene => TechniqueKind::SloanScene,
            Setting::TamuraPaper { .. } => TechniqueKind::TamuraPaper,
            Setting::Tamura { .. } => TechniqueKind::Tamura,
            Setting::ParallelLights { .. } => TechniqueKind::ParallelLights,
        }
    }

    /// The PRT transfer it needs, if any.
    fn precomputation(self) -> Option<PrtParams> {
        self.technique().precomputation()
    }
}

/// The settings `--only` names, in the sweep's order; an unknown name is an error that lists
/// the known ones.
fn chosen(only: &[String]) -> Result<Vec<Setting>> {
    let all = Setting::all();
    for name in only {
        if !all.iter().any(|s| s.name() == *name) {
            let known: Vec<String> = all.iter().map(|s| s.name()).collect();
            bail!("--only {name}: no such setting; the sweep has {}", known.join(", "));
        }
    }
    Ok(all.into_iter().filter(|s| only.is_empty() || only.contains(&s.name())).collect())
}

struct Row {
    env: String,
    setting: Setting,
    errors: Vec<f64>,
    /// The reference's relative standard error at each pose.
    noise: Vec<f64>,
    frame_ms: Option<f64>,
    precompute_s: Option<f64>,
    memory_mb: f64,
}

impl Row {
    fn mean_error(&self) -> f64 {
        self.errors.iter().sum::<f64>() / self.errors.len() as f64
    }

    /// The row on the chart: only with a time, and with both values above 0 (log scales).
    fn point(&self) -> Option<Point> {
        let ms = self.frame_ms.filter(|ms| *ms > 0.0)?;
        let error = Some(self.mean_error()).filter(|e| *e > 0.0)?;
        let series = match self.setting {
            Setting::Unshadowed => "unshadowed",
            Setting::SloanSelf { .. } => "sloan self (SH bands)",
            Setting::SloanScene => "sloan whole scene",
            Setting::TamuraPaper { .. } => "tamura as published (q)",
            Setting::Tamura { .. } => "tamura (q)",
            Setting::ParallelLights { .. } => "parallel lights (q)",
        };
        let label = self.setting.describe().2;
        Some(Point { series: series.into(), name: self.setting.name(), label, ms, error })
    }
}

pub fn run(args: &SweepArgs) -> Result<()> {
    if args.poses.is_empty() || args.poses.iter().any(|t| !t.is_finite()) {
        bail!("--poses must list finite times, e.g. 0,0.125,0.6");
    }
    if args.size == 0 || args.time_size == 0 || args.spp == Some(0) || args.max_spp == 0 {
        bail!("--size, --time-size, --spp and --max-spp must be at least 1");
    }
    if !(args.noise.is_finite() && args.noise > 0.0) {
        bail!("--noise must be a positive fraction, e.g. 0.005 (0.5 %); got {}", args.noise);
    }
    if args.spp.is_some() && args.technique == SweptTechnique::Prt {
        bail!("--spp: the prt sweep runs each reference to --noise (default 0.005), up to --max-spp");
    }
    if args.pick && args.max_error.is_none() && args.max_ms.is_none() && args.max_probes.is_none() {
        bail!("--pick needs a bound: --max-error E, --max-ms T (--max-probes N for probes), or both");
    }
    if args.max_probes.is_some() && args.technique != SweptTechnique::Probes {
        bail!(
            "--max-probes bounds the probe sweep's cost; the {:?} sweep's is frame time: --max-ms",
            args.technique
        );
    }
    if args.test_region.is_some() && args.technique != SweptTechnique::Probes {
        bail!("--test-region places the probe sweep's test points; the {:?} sweep has none", args.technique);
    }
    if args.max_error.into_iter().chain(args.max_ms).any(|b| !(b.is_finite() && b > 0.0)) {
        bail!("--max-error and --max-ms must be positive numbers");
    }
    if args.pick && args.frames == 0 && args.technique != SweptTechnique::Probes {
        bail!("--pick compares frame times: it needs --frames of at least 1");
    }
    match args.technique {
        SweptTechnique::Prt => run_prt(args),
        SweptTechnique::Asm => asm::run(args),
        SweptTechnique::Probes => probes::run(args),
    }
}

fn run_prt(args: &SweepArgs) -> Result<()> {
    let settings = chosen(&args.only)?;
    let scene = crate::args::read_scene(args.scene.as_deref().unwrap_or("teapot"), !args.envs.is_empty())?;
    if scene.groups.is_empty() {
        bail!("scene {} has no groups to move", scene.name);
    }
    let envs: Vec<(String, EnvMap)> = if args.envs.is_empty() {
        vec![("scene".to_string(), scene.environment.clone())]
    } else {
        args.envs
            .iter()
            .map(|path| {
                let map = EnvMap::load(path).with_context(|| format!("--env {}", path.display()))?;
                crate::args::report_clamped(&map);
                let name = path
                    .file_name()
                    .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into());
                Ok((name, map))
            })
            .collect::<Result<_>>()?
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let ctx = args.gpu.context()?;

    // Transfers depend on the geometry only: one per precomputation, shared by every map.
    let mut transfers: Vec<(PrtParams, Arc<TransferSet>)> = Vec::new();
    for params in settings.iter().filter_map(|s| s.precomputation()) {
        let params = PrtParams { rays: args.rays, ..params };
        if !transfers.iter().any(|(p, _)| *p == params) {
            let source = PrtArgs { params, cache: args.cache.clone(), force: false };
            let (transfer, _) = source.obtain(&ctx, &scene, params)?;
            transfers.push((params, Arc::new(transfer)));
        }
    }
    let transfer_of = |setting: Setting| {
        let wanted = PrtParams { rays: args.rays, ..setting.precomputation()? };
        transfers.iter().find(|(p, _)| *p == wanted).map(|(_, t)| t.clone())
    };
    let reference_dir = converged::folder(args.cache.as_deref())?;

    let timed = if args.frames > 0 { 1 } else { 0 };
    let steps = envs.len() * (args.poses.len() + settings.len() * (args.poses.len() + timed));
    let bar = Bar::new(steps as u64, "steps");
    let mut rows = Vec::new();
    for (env_name, map) in &envs {
        let mut lit = scene.clone();
        lit.environment = map.clone();
        let references: Vec<converged::Reference> = args
            .poses
            .iter()
            .map(|&t| {
                bar.message(format!("{env_name}: reference at t = {t}"));
                let mut progress = |spp: u32, noise: f64| {
                    bar.message(format!(
                        "{env_name}: reference at t = {t}, {spp} spp, noise {:.2} %",
                        100.0 * noise
                    ))
                };
                let reference = converged::reference(
                    &ctx,
                    &posed(&lit, t),
                    args.size,
                    args.noise,
                    args.max_spp,
                    &reference_dir,
                    &mut progress,
                );
                bar.advance(1);
                if let Ok(r) = &reference {
                    let noise = 100.0 * r.noise;
                    bar.suspend(|| {
                        println!("{env_name}: reference at t = {t}: {} spp, noise {noise:.2} %", r.spp)
                    });
                }
                reference
            })
            .collect::<Result<_>>()?;
        for &setting in &settings {
            bar.message(format!("{env_name}: {}", setting.name()));
            let transfer = transfer_of(setting);
            let before = ctx.allocated_bytes();
            let mut renderer = Renderer::new(
                &ctx,
                &lit,
                &RenderOptions {
                    width: args.size,
                    height: args.size,
                    technique: setting.technique(),
                    transfer: transfer.clone(),
                },
            )
            .with_context(|| format!("setting up {}", setting.name()))?;
            let memory_mb = (ctx.allocated_bytes() - before) as f64 / (1 << 20) as f64;
            let mut errors = Vec::new();
            for (&t, reference) in args.poses.iter().zip(&references) {
                renderer.set_time(t)?;
                renderer.render()?;
                errors.push(compare(&renderer.image()?, &reference.image)?.relative_rmse);
                bar.advance(1);
            }
            drop(renderer);
            let frame_ms = if args.frames > 0 {
                let options = RenderOptions {
                    width: args.time_size,
                    height: args.time_size,
                    technique: setting.technique(),
                    transfer: transfer.clone(),
                };
                let ms = frame_time(&ctx, &lit, &options, args.frames)?;
                bar.advance(1);
                Some(ms)
            } else {
                None
            };
            let row = Row {
                env: env_name.clone(),
                setting,
                errors,
                noise: references.iter().map(|r| r.noise).collect(),
                frame_ms,
                precompute_s: transfer.map(|t| t.seconds),
                memory_mb,
            };
            bar.suspend(|| println!("{}", summary(&row)));
            rows.push(row);
        }
    }
    drop(bar);

    let path = args.out.join("sweep.csv");
    std::fs::write(&path, csv(&scene.name, &args.poses, &rows))
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {} ({} rows, {})", path.display(), rows.len(), ctx.info().name);
    print_ratios(&rows);
    for (e, (env, _)) in envs.iter().enumerate() {
        let points: Vec<Point> = rows.iter().filter(|r| &r.env == env).filter_map(Row::point).collect();
        if points.is_empty() {
            continue;
        }
        let file = if e == 0 { "pareto.png".to_string() } else { format!("pareto-{env}.png") };
        let lit_by = if env == "scene" { "its own map" } else { env.as_str() };
        let noise =
            rows.iter().filter(|r| &r.env == env).flat_map(|r| r.noise.iter().copied()).fold(0.0, f64::max);
        let title = format!(
            "{} under {lit_by}: {} frames at {}², error at {}² (reference noise ≤ {:.2} %)",
            scene.name,
            args.frames,
            args.time_size,
            args.size,
            100.0 * noise
        );
        chart::write(
            &args.out.join(&file),
            &title,
            &chart::frame_time_against("relative RMSE against the reference"),
            &points,
        )?;
        println!("wrote {}", args.out.join(&file).display());
        if args.pick {
            print_picks(
                env,
                &points,
                args.max_error,
                args.max_ms,
                &Terms { metric: "relative RMSE", unit: FRAME_TIME },
            );
        }
    }
    args.gpu.finish(&ctx)
}

/// A sweep's files for one scene: `sweep.csv`, and `pareto.png` when any setting is on the chart;
/// then the picks `--pick` asks for, `max_cost` bounding the cost the points count.
pub(crate) fn write_outputs(
    args: &SweepArgs,
    scene: &str,
    csv: &str,
    chart: (&str, &chart::Axes),
    points: &[Point],
    max_cost: Option<f64>,
    terms: &Terms,
) -> Result<()> {
    let path = args.out.join("sweep.csv");
    std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {}", path.display());
    if !points.is_empty() {
        let path = args.out.join("pareto.png");
        chart::write(&path, chart.0, chart.1, points)?;
        println!("wrote {}", path.display());
    }
    if args.pick {
        print_picks(scene, points, args.max_error, max_cost, terms);
    }
    Ok(())
}

/// How a sweep's picks name what they compare: the error metric, and the cost's unit (`ms`, or
/// `probes` where the probe count is the cost).
pub(crate) struct Terms<'a> {
    pub metric: &'a str,
    pub unit: &'a str,
}

pub(crate) const FRAME_TIME: &str = "ms";

pub(crate) fn print_picks(
    env: &str,
    points: &[Point],
    max_error: Option<f64>,
    max_cost: Option<f64>,
    terms: &Terms,
) {
    let (metric, unit) = (terms.metric, terms.unit);
    let cost = |v: f64| if unit == FRAME_TIME { format!("{v:.2} {unit}") } else { format!("{v} {unit}") };
    if let Some(bound) = max_error {
        match pick::cheapest_within(points, bound) {
            Some(p) => println!(
                "{env}: cheapest within {metric} {bound}: {} ({}, error {:.4})",
                p.name,
                cost(p.ms),
                p.error
            ),
            None => println!("{env}: no setting reaches {metric} {bound}"),
        }
    }
    if let Some(bound) = max_cost {
        match pick::most_accurate_within(points, bound) {
            Some(p) => println!(
                "{env}: most accurate within {bound} {unit}: {} ({}, error {:.4})",
                p.name,
                cost(p.ms),
                p.error
            ),
            None => println!("{env}: no setting runs within {bound} {unit}"),
        }
    }
}

/// `scene` with its groups at `t` seconds of their motions.
fn posed(scene: &Scene, t: f32) -> Scene {
    let mut scene = scene.clone();
    let poses = scene.poses_at(t);
    for (group, pose) in scene.groups.iter_mut().zip(poses) {
        group.transform = pose;
    }
    scene
}

/// Median GPU milliseconds per frame over `frames` frames through one pass of the scene's motion.
fn frame_time(ctx: &Arc<Context>, scene: &Scene, options: &RenderOptions, frames: u32) -> Result<f64> {
    let mut renderer = Renderer::new(ctx, scene, options)?;
    // One untimed frame: pipelines are compiled on first use on CPU drivers.
    renderer.render()?;
    let mut table = TimingTable::default();
    for frame in 0..frames {
        renderer.set_time(frame as f32 / frames as f32 * scene.duration())?;
        table.add_frame(&renderer.render()?);
    }
    Ok(table.frame_median_ms())
}

fn summary(row: &Row) -> String {
    let mean = row.mean_error();
    let ms = row.frame_ms.map_or_else(|| "-".to_string(), |ms| format!("{ms:.2} ms"));
    let noise = row.noise.iter().copied().fold(0.0, f64::max);
    format!(
        "{:<12} {:<20} relative RMSE {mean:.4} (per pose {:.4?}; reference noise ≤ {:.4}), {ms}, {:.1} MB",
        row.env,
        row.setting.name(),
        row.errors,
        noise,
        row.memory_mb
    )
}

fn csv(scene: &str, poses: &[f32], rows: &[Row]) -> String {
    let mut out = String::from("scene,env,technique,parameter,value,error_mean");
    for t in poses {
        write!(out, ",error_t{t}").expect("writing to a String");
    }
    for t in poses {
        write!(out, ",reference_noise_t{t}").expect("writing to a String");
    }
    out.push_str(",frame_ms,precompute_s,memory_mb\n");
    let optional = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v:.4}"));
    for row in rows {
        let (technique, parameter, value) = row.setting.describe();
        let mean = row.mean_error();
        write!(out, "{scene},{},{technique},{parameter},{value},{mean:.5}", row.env)
            .expect("writing to a String");
        for e in row.errors.iter().chain(&row.noise) {
            write!(out, ",{e:.5}").expect("writing to a String");
        }
        writeln!(out, ",{},{},{:.2}", optional(row.frame_ms), optional(row.precompute_s), row.memory_mb)
            .expect("writing to a String");
    }
    out
}

/// Each setting against parallel lights at the same q (the strongest baseline that does the
/// same job), or at q = 32 for the settings without one: error and frame-time ratios, measured
/// in this run.
fn print_ratios(rows: &[Row]) {
    for row in rows {
        let q = match row.setting {
            Setting::Tamura { regions } | Setting::TamuraPaper { regions } => regions,
            Setting::ParallelLights { .. } => continue,
            _ => 32,
        };
        let baseline = Setting::ParallelLights { regions: q };
        let Some(base) = rows.iter().find(|r| r.env == row.env && r.setting == baseline) else { continue };
        let frame = match (row.frame_ms, base.frame_ms) {
            (Some(ms), Some(base)) if base > 0.0 => format!(", frame time {:.2}x", ms / base),
            _ => String::new(),
        };
        // A difference the references' own noise could make is no ranking.
        let noise = row.noise.iter().chain(&base.noise).fold(0.0f64, |m, &n| m.max(n));
        let difference = (row.mean_error() - base.mean_error()).abs();
        let unranked = match difference < 2.0 * noise {
            true => format!(
                " (the references' noise, up to {noise:.4}, is within 2x of the difference {difference:.4}: \
                 too close to rank)"
            ),
            false => String::new(),
        };
        println!(
            "{}: {} / {}: error {:.2}x{frame}{unranked}",
            row.env,
            row.setting.name(),
            baseline.name(),
            row.mean_error() / base.mean_error()
        );
    }
}
