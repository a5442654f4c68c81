//! `kage bench asm`: shadow-map techniques for local lights side by side over a scene's camera
//! walkthrough: per frame, the fraction of pixels shadowed differently
//! from the ray-traced reference, the GPU time of every pass, and, where the camera moves
//! slowly, the pixels whose shadow flips when the reference's does not; per configuration, the
//! shadow memory, and the frames the error takes to stop falling once the camera rests.
//!
//! The configurations render every frame in turn (the first one first in frame 0, the second
//! in frame 1, ...), so a load that comes and goes during the run weighs on all of them alike;
//! each one's time is also divided by the first configuration's in the same frame, and the
//! median of those ratios is reported beside the ratio of the medians.
mod frames;
mod references;
pub mod report;

use crate::args::GpuArgs;
use crate::progress::Bar;
use anyhow::{bail, Context as _, Result};
use clap::Args;
use kage::frame::MAX_SIZE;
use kage::imageio::RgbaF32Image;
use kage::reference::{shadow_flips, shadow_mismatch, SHADOW_THRESHOLD};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::Scene;
use kage::techniques::asm::technique::AsmTest;
use kage::techniques::asm::{AsmSettings, AsmTimeBudget};
use kage::techniques::description::TechniqueDesc;
use report::{FrameRow, Series};
use std::path::PathBuf;

/// What the benchmark compares unless told: the conventional maps and ASM budgets.
pub const DEFAULT_CONFIGS: [&str; 6] =
    ["shadowmap:1024", "shadowmap:2048", "shadowmap:4096", "asm:4", "asm:8", "asm:16"];

#[derive(Args)]
pub struct AsmBenchArgs {
    /// A built-in scene name or a scene file (.json, or glTF 2.0: .gltf, .glb) with local lights and a `walkthrough`.
    #[arg(long, default_value = "asm")]
    scene: String,
    /// The configurations, `KIND:VALUE` each: `shadowmap:SIDE` (a conventional map of SIDE²
    /// texels per light), `asm:MB` (an adaptive shadow map within MB megabytes), `asm-id:MB`
    /// (the same with the paper's polygon-ID test). The first is the one the others' frame times are divided by.
    /// (`--only`, as `kage sweep` names its settings; `--configs` is the old name.)
    #[arg(long = "only", alias = "configs", value_delimiter = ',', default_values_t = DEFAULT_CONFIGS.map(String::from))]
    configs: Vec<String>,
    /// Frames sampling the walkthrough (t = i / frames, as `kage render --animate`).
    #[arg(long, default_value_t = 40)]
    frames: u32,
    /// Frames the camera is held at each keyframe after arriving there (convergence); 0: none.
    #[arg(long, default_value_t = 4)]
    rest: u32,
    /// Frames leaving each keyframe slowly after the rest (each 1 % further along the eased
    /// move; temporal stability); 0: none.
    #[arg(long, default_value_t = 4)]
    slow: u32,
    /// Side of the square images, pixels.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// Frame pairs whose view moves by at most this many pixels (and more than 0) count as the
    /// camera moving slowly, where the shadow flips are measured.
    #[arg(long, default_value_t = 4.0)]
    slow_px: f32,
    /// The fall in error (a fraction of the pixels) below which a resting camera's error counts
    /// as no longer falling.
    #[arg(long, default_value_t = 1e-4)]
    converge_tolerance: f64,
    /// Folder of the cached references (default: `references` in the PRT cache folder,
    /// `$KAGE_CACHE_DIR`, `$XDG_CACHE_HOME/kage` or `~/.cache/kage`).
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Output folder (created if missing): `frames.csv` (one row per frame and
    /// configuration), `summary.csv` and `error-time.png`.
    #[arg(long)]
    out: PathBuf,
    /// The tile time budget of every `asm` and `asm-id` configuration.
    #[command(flatten)]
    asm_time: AsmTimeBudget,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// A technique `--only` names: `name:VALUE`, VALUE the parameter `settings` turns into the
/// technique's settings. Adding a technique to the benchmark is adding one entry.
struct ConfigKind {
    name: &'static str,
    /// What VALUE is.
    parameter: &'static str,
    /// The chart's series, naming what the values count.
    series: &'static str,
    settings: fn(&str, AsmTimeBudget) -> Result<TechniqueDesc>,
}

const KINDS: &[ConfigKind] = &[
    ConfigKind {
        name: "shadowmap",
        parameter: "side",
        series: "shadow map (side, texels)",
        settings: shadowmap,
    },
    ConfigKind {
        name: "asm",
        parameter: "budget_mb",
        series: "adaptive shadow map (budget, MB)",
        settings: asm,
    },
    ConfigKind {
        name: "asm-id",
        parameter: "budget_mb",
        series: "adaptive shadow map, polygon IDs (budget, MB)",
        settings: asm_id,
    },
];

fn shadowmap(value: &str, _: AsmTimeBudget) -> Result<TechniqueDesc> {
    let size = value.parse().with_context(|| format!("{value:?} is not a whole number of texels"))?;
    Ok(TechniqueDesc::ShadowMap { size })
}

fn asm_with(value: &str, time: AsmTimeBudget, test: AsmTest) -> Result<TechniqueDesc> {
    let budget_mb = value.parse().with_context(|| format!("{value:?} is not a number of MB"))?;
    Ok(TechniqueDesc::Asm(AsmSettings { budget_mb, time, test, ..AsmSettings::default() }))
}

fn asm(value: &str, time: AsmTimeBudget) -> Result<TechniqueDesc> {
    asm_with(value, time, AsmTest::Bias)
}

/// ASM with the paper's polygon-ID test (its pages twice the bytes).
fn asm_id(value: &str, time: AsmTimeBudget) -> Result<TechniqueDesc> {
    asm_with(value, time, AsmTest::Id)
}

/// One configuration of the run.
pub struct Config {
    /// As given: `shadowmap:1024`.
    pub name: String,
    pub kind: &'static str,
    pub parameter: &'static str,
    pub series: &'static str,
    pub value: String,
    settings: TechniqueDesc,
}

fn parse_config(arg: &str, time: AsmTimeBudget) -> Result<Config> {
    let known = || KINDS.iter().map(|k| format!("{}:VALUE", k.name)).collect::<Vec<_>>().join(", ");
    let Some((kind, value)) = arg.split_once(':') else {
        bail!("--only {arg}: expected KIND:VALUE, one of {}", known());
    };
    let Some(kind) = KINDS.iter().find(|k| k.name == kind) else {
        bail!("--only {arg}: no technique {kind:?}; the benchmark knows {}", known());
    };
    let settings = (kind.settings)(value, time).with_context(|| format!("--only {arg}"))?;
    Ok(Config {
        name: arg.to_string(),
        kind: kind.name,
        parameter: kind.parameter,
        series: kind.series,
        value: value.to_string(),
        settings,
    })
}

/// A run's configurations and what was measured of each.
pub struct Measured {
    pub scene: String,
    pub configs: Vec<Config>,
    pub summaries: Vec<report::Summary>,
    rows: Vec<FrameRow>,
    /// The chart's title: scene, frames, image size, device.
    pub title: String,
    slow_px: f32,
}

impl Measured {
    /// The table of figures per configuration and the table of passes.
    pub fn print(&self) {
        report::print(&self.configs, &self.summaries, self.slow_px);
    }
}

impl AsmBenchArgs {
    /// The arguments `kage sweep --technique asm` runs the benchmark with: its defaults but
    /// for these.
    pub fn for_sweep(
        scene: &str,
        configs: Vec<String>,
        frames: u32,
        size: u32,
        out: PathBuf,
        gpu: GpuArgs,
    ) -> Self {
        AsmBenchArgs {
            scene: scene.to_string(),
            configs,
            frames,
            rest: 4,
            slow: 4,
            size,
            slow_px: 4.0,
            converge_tolerance: 1e-4,
            cache: None,
            out,
            asm_time: AsmTimeBudget::default(),
            gpu,
        }
    }
}

pub fn run(args: &AsmBenchArgs) -> Result<()> {
    let measured = measure(args)?;
    measured.print();
    let written =
        report::write(&args.out, &measured.scene, &measured.configs, &measured.summaries, &measured.rows)?;
    for path in written {
        println!("wrote {}", path.display());
    }
    let path = args.out.join("error-time.png");
    if report::chart(&path, &measured.title, &measured.configs, &measured.summaries)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Renders the walkthrough with every configuration and measures each against the reference.
pub fn measure(args: &AsmBenchArgs) -> Result<Measured> {
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    if !(1..=MAX_SIZE).contains(&args.size) {
        bail!("--size {} must be 1 to {MAX_SIZE} pixels", args.size);
    }
    if !(args.slow_px.is_finite() && args.slow_px > 0.0) {
        bail!("--slow-px must be a positive number of pixels");
    }
    if !(args.converge_tolerance.is_finite() && args.converge_tolerance >= 0.0) {
        bail!("--converge-tolerance must be a fraction of the pixels, 0 or more");
    }
    if args.configs.is_empty() {
        bail!("--only needs at least one configuration");
    }
    let configs: Vec<Config> =
        args.configs.iter().map(|c| parse_config(c, args.asm_time)).collect::<Result<_>>()?;
    let scene = Scene::from_arg(&args.scene)?;
    if scene.walkthrough.is_empty() {
        bail!("scene {} has no camera walkthrough to follow (scene files: \"walkthrough\")", scene.name);
    }
    let plan = frames::plan(&scene.walkthrough, args.frames, args.rest, args.slow);
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let ctx = args.gpu.context()?;
    if ctx.info().timestamp_period_ns.is_none() {
        bail!("{} has no GPU timestamps, so frame times cannot be measured", ctx.info().name);
    }
    let options = |config: &Config| -> Result<RenderOptions> {
        let technique = config.settings.clone().validated()?;
        Ok(RenderOptions { width: args.size, height: args.size, technique, transfer: None })
    };
    let mut renderers = configs
        .iter()
        .map(|c| Renderer::new(&ctx, &scene, &options(c)?).with_context(|| format!("setting up {}", c.name)))
        .collect::<Result<Vec<_>>>()?;
    // One untimed frame each: pipelines are compiled on first use on CPU drivers, and the
    // environment's SH projection runs in the first frame only.
    for renderer in &mut renderers {
        renderer.render()?;
    }
    let cache = args.cache.clone().or_else(|| kage::prt::cache::default_dir().map(|d| d.join("references")));
    let mut references = references::References::new(&ctx, &scene, args.size, cache.clone())?;

    let (series, rows) = walk(&plan, &mut renderers, &mut references, args)?;

    let device = ctx.info().name.clone();
    println!(
        "scene {}: {} frames ({} walkthrough samples; {} held and {} leaving slowly at each of {} keyframes) at {}x{}, {device}; references: {} ray cast, {} from {}",
        scene.name,
        plan.len(),
        args.frames,
        args.rest,
        args.slow,
        scene.walkthrough.len(),
        args.size,
        args.size,
        references.computed,
        references.loaded,
        cache.map_or_else(|| "nowhere (no cache folder)".to_string(), |d| d.display().to_string()),
    );
    let memory: Vec<Option<u64>> = renderers.iter().map(|r| r.stats().shadow_memory_bytes).collect();
    let summaries: Vec<report::Summary> =
        series.iter().zip(&memory).map(|(s, &bytes)| s.summary(bytes, args.converge_tolerance)).collect();
    let title = format!("{}: {} frames at {}², {device}", scene.name, plan.len(), args.size);
    args.gpu.finish(&ctx)?;
    Ok(Measured { scene: scene.name.clone(), configs, summaries, rows, title, slow_px: args.slow_px })
}

/// Renders every frame of `plan` with every renderer in turn and measures it against the
/// frame's reference: each configuration's series, and one row per frame and configuration.
fn walk(
    plan: &[frames::Frame],
    renderers: &mut [Renderer],
    references: &mut references::References,
    args: &AsmBenchArgs,
) -> Result<(Vec<Series>, Vec<FrameRow>)> {
    let bar = Bar::new(plan.len() as u64, "frames");
    let n = renderers.len();
    let mut series: Vec<Series> = (0..n).map(|_| Series::default()).collect();
    let mut rows = Vec::new();
    // The last frame's reference and renders, for the flips.
    let mut previous: Option<(references::Truth, Vec<RgbaF32Image>)> = None;
    for (i, frame) in plan.iter().enumerate() {
        bar.message(format!("frame {i}: reference"));
        let truth = references.get(&frame.camera)?;
        let motion = (i > 0).then(|| frames::motion_px(&plan[i - 1].camera, &frame.camera, args.size));
        let slow = motion.is_some_and(|m| m > 0.0 && m <= args.slow_px);
        bar.message(format!("frame {i}: rendering"));
        let mut timings = vec![Vec::new(); n];
        // Wall-clock ms of each render call: the GPU's passes and all the host does between
        // and around them (an adaptive map's planning waits on its analysis, and the GPU on it).
        let mut wall_ms = vec![0.0; n];
        for k in 0..n {
            let c = (i + k) % n;
            renderers[c].set_camera(frame.camera)?;
            let start = std::time::Instant::now();
            timings[c] = renderers[c].render()?;
            wall_ms[c] = start.elapsed().as_secs_f64() * 1e3;
        }
        let images: Vec<RgbaF32Image> = renderers.iter().map(|r| r.image()).collect::<kage::Result<_>>()?;
        let frame_ms = |c: usize| kage::pass::frame_ms(&timings[c]).unwrap_or(0.0);
        for (c, image) in images.iter().enumerate() {
            let mismatch = shadow_mismatch(image, &truth.image, SHADOW_THRESHOLD, Some(&truth.edges))?;
            let flips = match (&previous, slow) {
                (Some((truth_before, before)), true) => Some(shadow_flips(
                    [&before[c], image],
                    [&truth_before.image, &truth.image],
                    SHADOW_THRESHOLD,
                )?),
                _ => None,
            };
            let row = FrameRow {
                frame: i,
                t: frame.t,
                rest: frame.rest,
                extra: frame.extra,
                motion_px: motion,
                config: c,
                error: mismatch.fraction,
                leaks: mismatch.lit_in_render_only,
                edge_ties: mismatch.at_edges,
                frame_ms: frame_ms(c),
                ratio: frame_ms(c) / frame_ms(0),
                wall_ms: wall_ms[c],
                wall_ratio: wall_ms[c] / wall_ms[0],
                flips,
            };
            series[c].add(&row, &timings[c]);
            rows.push(row);
        }
        previous = Some((truth, images));
        bar.advance(1);
    }
    drop(bar);
    Ok((series, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn configurations_parse_or_say_what_is_known() {
        let c = parse_config("shadowmap:2048", AsmTimeBudget::default()).unwrap();
        assert_eq!((c.kind, c.value.as_str()), ("shadowmap", "2048"));
        assert!(matches!(c.settings, TechniqueDesc::ShadowMap { size: 2048 }));
        for (bad, expected) in [
            ("shadowmap", "expected KIND:VALUE, one of shadowmap:VALUE"),
            ("cube:4", "no technique \"cube\""),
            ("shadowmap:big", "\"big\" is not a whole number"),
        ] {
            let err = format!("{:#}", parse_config(bad, AsmTimeBudget::default()).err().unwrap());
            assert!(err.contains(expected), "{bad}: {err}");
        }
    }
}
