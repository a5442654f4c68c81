//! `kage render`: renders frames offscreen, writes the last one, and reports pass timings.
use crate::args::GpuArgs;
use crate::progress::Bar;
use crate::transfer_source::{Origin, PrtArgs};
use anyhow::{Context as _, Result};
use clap::Args;
use kage::pass::TimingTable;
use kage::prt::PrtParams;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{animation, Scene};
use kage::techniques::asm::technique::MB;
use kage::techniques::asm::AsmSettings;
use kage::techniques::description::{TechniqueDesc, TechniqueKind, TechniqueParams};
use kage::techniques::probes::{ProbeSettings, DEFAULT_GRID};
use kage::techniques::tamura::technique::OcclusionSettings;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct RenderArgs {
    /// The lighting technique; the default shows what Kage is for, Tamura's soft shadows
    /// (its PRT transfer is computed first, in seconds, and cached).
    #[arg(long, value_enum, default_value_t = TechniqueKind::Tamura)]
    technique: TechniqueKind,
    #[command(flatten)]
    occlusion: OcclusionSettings,
    /// Side of a shadow map, texels: parallel-lights 16 to 2048, shadowmap 16 to 8192.
    #[arg(long, visible_alias = "shadowmap-size", default_value_t = kage::techniques::parallel_lights::DEFAULT_SHADOW_MAP_SIZE)]
    shadow_map_size: u32,
    #[command(flatten)]
    asm: AsmSettings,
    /// Light probes (technique `probes`): `grid:NX,NY,NZ` (cell centres over the static groups'
    /// bounding box, 2 to 64 each), `scene` (the scene file's `probes`), a file
    /// `{"positions": [[x,y,z], ...]}`, or `auto`, `auto:TOL` or `auto:TOL:NX,NY,NZ` (candidates
    /// on that grid, outside solids, captured; those the others reproduce within the relative
    /// irradiance error TOL, default 0.05, dropped).
    #[arg(long, default_value_t = format!("grid:{},{},{}", DEFAULT_GRID[0], DEFAULT_GRID[1], DEFAULT_GRID[2]))]
    probes: String,
    #[command(flatten)]
    probe: ProbeSettings,
    /// Turn the environment about +Y by this many degrees (counter-clockwise from above).
    #[arg(long, default_value_t = 0.0)]
    env_rotation: f32,
    /// Play the scene's motion over the frames: its camera walkthrough, and the keyframes of
    /// its groups (one pass of the longest; see README's scene format).
    #[arg(long)]
    animate: bool,
    /// Render the instant T seconds into the scene's motion (its groups' keyframes).
    #[arg(long, value_name = "T")]
    time: Option<f32>,
    #[command(flatten)]
    prt: PrtArgs,
    #[command(flatten)]
    scene: crate::args::SceneArgs,
    #[arg(long, default_value_t = 512)]
    width: u32,
    #[arg(long, default_value_t = 512)]
    height: u32,
    /// Frames rendered before the timed ones, left out of the timings and the trace: a
    /// pipeline's first frames include its shader compilation on lavapipe, and one-time passes
    /// (the environment's SH projection) run in the first frame (`--warmup 0` shows them).
    #[arg(long, default_value_t = 2)]
    warmup: u32,
    /// Frames to render; timings are taken over all of them.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Output image: .png (tonemapped, sRGB) or .exr (linear radiance, 32-bit float).
    #[arg(long, default_value = "kage.png")]
    out: PathBuf,
    #[command(flatten)]
    exposure: crate::outputs::Exposure,
    /// Write per-pass GPU timings as JSON.
    #[arg(long)]
    timings: Option<PathBuf>,
    /// Write every frame's passes as a timeline (.json, Chrome trace event format: open it in
    /// Perfetto or chrome://tracing).
    #[arg(long)]
    trace: Option<PathBuf>,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(serde::Serialize)]
struct TimingsFile {
    device: String,
    frames: usize,
    passes: Vec<kage::pass::TimingRow>,
    frame_median_ms: f64,
    /// The median wall-clock ms of a frame's render call: the GPU's passes, the host's work
    /// between and around them, and the waits.
    frame_wall_median_ms: f64,
}

/// The command line's technique options as the engine's description (each technique reads its
/// own options; the others are ignored).
fn technique(args: &RenderArgs, scene: &Scene) -> Result<TechniqueDesc> {
    Ok(TechniqueDesc::from_params(args.technique, &Flags { args, scene })?.validated()?)
}

/// The technique flags as the techniques' parameters; `scene` for the probes' placement.
struct Flags<'a> {
    args: &'a RenderArgs,
    scene: &'a Scene,
}

impl TechniqueParams for Flags<'_> {
    type Error = anyhow::Error;
    fn prt(&self) -> Result<PrtParams> {
        self.args.prt.params()
    }
    fn regions(&self) -> usize {
        self.args.occlusion.regions
    }
    fn mask_size(&self) -> u32 {
        self.args.occlusion.mask_size
    }
    fn occlusion(&self) -> Result<OcclusionSettings> {
        Ok(self.args.occlusion)
    }
    fn shadow_map_size(&self) -> u32 {
        self.args.shadow_map_size
    }
    fn probes(&self) -> Result<ProbeSettings> {
        Ok(ProbeSettings {
            placement: crate::args::probe_placement(&self.args.probes, self.scene)?,
            ..self.args.probe.clone()
        })
    }
    fn asm(&self) -> Result<AsmSettings> {
        Ok(self.args.asm)
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.frames == 0 {
        anyhow::bail!("--frames must be at least 1");
    }
    crate::outputs::check(&args.out, "--out", &["png", "exr"])?;
    if let Some(timings) = &args.timings {
        crate::outputs::check(timings, "--timings", &["json"])?;
    }
    if let Some(trace) = &args.trace {
        crate::outputs::check(trace, "--trace", &["json"])?;
    }
    if let (true, Some(_)) = (args.animate, args.time) {
        anyhow::bail!(
            "--animate plays the scene's motion and --time holds one instant of it: give one of them"
        );
    }
    if args.time.is_some_and(|t| !t.is_finite()) {
        anyhow::bail!("--time must be a number of seconds");
    }
    if args.animate && args.scene.keyframe.is_some() {
        anyhow::bail!(
            "--animate plays the walkthrough and --keyframe holds one of its cameras: give one of them"
        );
    }
    let scene = args.scene.load()?;
    let exposure = args.exposure.checked(&scene)?;
    let ctx = args.gpu.context()?;
    let technique = technique(args, &scene)?;
    crate::args::report_unrendered_lights(args.technique, &scene);
    let transfer = match technique.precomputation() {
        None => None,
        Some(params) => {
            let (transfer, origin) = args.prt.obtain(&ctx, &scene, params)?;
            match origin {
                Origin::Cached(path) => eprintln!("transfer: from {}", path.display()),
                Origin::Computed { path, .. } => {
                    eprintln!("transfer: computed in {:.2} s, cached in {}", transfer.seconds, path.display())
                }
                Origin::Unsaved { path, error } => eprintln!(
                    "kage: warning: transfer computed in {:.2} s but not cached, {} cannot be written: {error}",
                    transfer.seconds,
                    path.display()
                ),
            }
            Some(std::sync::Arc::new(transfer))
        }
    };
    let setup = Instant::now();
    let options = RenderOptions { width: args.width, height: args.height, technique, transfer };
    let mut renderer =
        crate::progress::with_bar("setting up (capturing the light probes)", "captures", |progress| {
            Renderer::with_progress(&ctx, &scene, &options, progress)
        })
        .context("setting up the renderer")?;
    if let Some(time) = args.time {
        renderer.set_time(time)?;
    }
    if let Some(counts) = renderer.stats().probes {
        let seconds = setup.elapsed().as_secs_f64();
        let left_out = match counts.inside_geometry {
            0 => String::new(),
            n => format!(", {n} inside geometry left out"),
        };
        match counts.kept < counts.candidates {
            true => eprintln!(
                "probes: {} of {} candidates kept by automatic placement{left_out}, captured in {seconds:.2} s",
                counts.kept, counts.candidates
            ),
            false => eprintln!("probes: {}{left_out}, captured in {seconds:.2} s", counts.kept),
        }
        if let Some(cost) = renderer.stats().probe_capture {
            eprintln!("{}", capture_split(&cost, seconds));
        }
    }
    renderer.set_env_rotation(args.env_rotation.to_radians())?;
    let bar = Bar::new(u64::from(args.warmup) + u64::from(args.frames), "frames");
    bar.message("rendering");
    let start = Instant::now();
    let mut table = TimingTable::default();
    let mut trace = crate::trace::Trace::default();
    let mut trace_origin_ns = None;
    let mut dropped = 0;
    // Wall-clock ms of the counted frames' render calls, and of ASM's host planning in them.
    let (mut walls, mut plans) = (Vec::new(), Vec::new());
    for frame in (0..args.warmup).map(|_| None).chain((0..args.frames).map(Some)) {
        let t = frame.map_or(0.0, |f| f as f32 / args.frames as f32);
        if args.animate {
            if let Some(camera) = animation::camera_at(&scene.walkthrough, t) {
                renderer.set_camera(camera)?;
            }
            renderer.set_time(t * scene.duration())?;
        }
        // With a trace, the device's and host's clocks read around the frame where they can be.
        let calibrate = || if args.trace.is_some() { ctx.calibrate() } else { Ok(None) };
        let before = calibrate()?;
        let frame_start = start.elapsed();
        let passes = renderer.render()?;
        let frame_end = start.elapsed();
        let after = calibrate()?;
        bar.advance(1);
        let Some(frame) = frame else { continue };
        if let (Some(before), Some(after)) = (before, after) {
            let origin = *trace_origin_ns.get_or_insert(before.host_ns as f64);
            let us = |host_ns: f64| (host_ns - origin) * 1e-3;
            trace.calibrated(before.deviation_ns.max(after.deviation_ns));
            trace.add_frame(
                frame,
                us(before.host_ns as f64),
                us(after.host_ns as f64) - us(before.host_ns as f64),
                &passes,
                |p| p.start_ticks.map(|t| us(after.host_ns_at(t))),
            );
        } else {
            let cpu_start_us = 1e6 * frame_start.as_secs_f64();
            trace.add_frame(
                frame,
                cpu_start_us,
                1e6 * (frame_end - frame_start).as_secs_f64(),
                &passes,
                |p| p.start_ms.map(|ms| cpu_start_us + 1e3 * ms),
            );
        }
        table.add_frame(&passes);
        walls.push(1e3 * (frame_end - frame_start).as_secs_f64());
        let stats = renderer.stats();
        plans.extend(stats.asm.map(|a| a.plan_ms));
        dropped = dropped.max(stats.dropped_layers);
    }
    drop(bar);
    if let Some(stats) = renderer.stats().asm {
        println!(
            "asm: {} tiles resident, {:.2} of {:.2} MB in use (allocated {:.2}: pages {:.2}, scratch {:.2} ({} layer{}), page table {:.2}, analysis {:.2}, lights {:.3}), deepest level {} (the texels of a {}² map), {} tiles rendered in the last frame; tile cost {:.2e} ms/triangle + {:.3} ms; planning on the host {:.2} ms a frame (median; the device waits for it between the two submissions)",
            stats.resident_tiles,
            stats.bytes_used as f64 / MB as f64,
            stats.budget_bytes as f64 / MB as f64,
            stats.memory.total() as f64 / MB as f64,
            stats.memory.pages as f64 / MB as f64,
            stats.memory.scratch as f64 / MB as f64,
            stats.memory.scratch_layers,
            if stats.memory.scratch_layers == 1 { "" } else { "s" },
            stats.memory.page_table as f64 / MB as f64,
            stats.memory.analysis as f64 / MB as f64,
            stats.memory.lights as f64 / MB as f64,
            stats.deepest_level,
            stats.effective_resolution(),
            stats.refreshed.len() + stats.rendered.len(),
            stats.cost.0,
            stats.cost.1,
            kage::pass::median(&plans)
        );
    }
    if let Some(c) = renderer.stats().probe_lookups {
        println!(
            "probe lookups: {}; a probe hidden from the group's centre in {}; none of the cell's seen, the nearest seen probe in {}; no probe seen, unweighted, in {}",
            c.lookups, c.renormalised, c.nearest, c.unweighted
        );
    }
    if dropped > 0 {
        eprintln!(
            "kage: note: up to {dropped} occlusion layer(s) per frame did not fit the {} Kage keeps; the least energetic regions' shadows between groups were left out",
            kage::layouts::constants::MAX_OCCLUSION_LAYERS
        );
    }
    let image = renderer.image()?;
    kage::imageio::write(&args.out, &image, exposure.for_image(&image))?;
    println!("wrote {} ({}x{}, scene {})", args.out.display(), args.width, args.height, scene.name);

    let rows = table.rows();
    println!("{:<16} {:>10} {:>10} {:>10} {:>7}", "pass", "median ms", "min ms", "max ms", "frames");
    for row in &rows {
        println!(
            "{:<16} {:>10.3} {:>10.3} {:>10.3} {:>7}",
            row.name, row.median_ms, row.min_ms, row.max_ms, row.frames
        );
    }
    println!(
        "{:<16} {:>10.3}   (median over {} frames, GPU, {})",
        "frame",
        table.frame_median_ms(),
        table.frame_count(),
        ctx.info().name
    );
    let frame_wall_median_ms = kage::pass::median(&walls);
    println!(
        "{:<16} {:>10.3}   (median over {} frames, wall clock: the GPU's passes, the host's work and the waits)",
        "frame (wall)",
        frame_wall_median_ms,
        walls.len()
    );
    if let Some(path) = &args.timings {
        let file = TimingsFile {
            device: ctx.info().name.clone(),
            frames: table.frame_count(),
            passes: rows,
            frame_median_ms: table.frame_median_ms(),
            frame_wall_median_ms,
        };
        std::fs::write(path, serde_json::to_string_pretty(&file)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.trace {
        trace.write(path, &ctx.info().name)?;
    }
    args.gpu.finish(&ctx)
}

/// Where the probes' capture time went (`CaptureCost`), split as the precompute's time is: the
/// walls' radiance (its GPU rays' traversal and rate, everything else of its batches, its
/// set-up), the cube maps, the CPU's rays, and the rest of `seconds` (placement,
/// tetrahedralization, visibility set-up).
fn capture_split(cost: &kage::techniques::probes::CaptureCost, seconds: f64) -> String {
    let per_probe = match cost.cubes {
        0 => 0.0,
        n => 1e3 * cost.cube_seconds / f64::from(n),
    };
    let traversal = cost.radiance_traversal_seconds();
    format!(
        "capture split: walls' radiance {:.2} s (ray traversal {traversal:.2} s, {} rays, {:.2} M rays/s; \
         everything else {:.2} s = {:.1} % of its batches; set-up and the split's timing {:.2} s), {} cube maps {:.2} s ({per_probe:.1} ms \
         each, {:.1} M texels/s), {} CPU rays {:.2} s, BVH {:.2} s, the rest {:.2} s",
        cost.radiance_seconds,
        cost.radiance_rays,
        cost.radiance_mrays_per_second(),
        cost.radiance_untraced_seconds,
        100.0 * cost.radiance_untraced_seconds / cost.radiance_batch_seconds.max(f64::MIN_POSITIVE),
        (cost.radiance_seconds - cost.radiance_batch_seconds).max(0.0),
        cost.cubes,
        cost.cube_seconds,
        cost.cube_mtexels_per_second(),
        cost.cpu_rays,
        cost.cpu_seconds,
        cost.bvh_seconds,
        (seconds - cost.seconds()).max(0.0),
    )
}
