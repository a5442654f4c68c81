//! `kage render`: renders frames offscreen, writes the last one, and reports pass timings.
use crate::GpuArgs;
use anyhow::{Context as _, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use kage::pass::TimingTable;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct RenderArgs {
    /// A built-in scene name (teapot, teapot-hires-floor) or a scene file (.json).
    #[arg(long, default_value = "teapot")]
    scene: String,
    #[arg(long, default_value_t = 512)]
    width: u32,
    #[arg(long, default_value_t = 512)]
    height: u32,
    /// Frames to render; timings are taken over all of them.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Output image: .png (tonemapped, sRGB) or .exr (linear radiance, 32-bit float).
    #[arg(long, default_value = "kage.png")]
    out: PathBuf,
    /// Exposure multiplier applied before tonemapping (PNG only).
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Write per-pass GPU timings as JSON.
    #[arg(long)]
    timings: Option<PathBuf>,
    #[command(flatten)]
    gpu: GpuArgs,
}

#[derive(serde::Serialize)]
struct TimingsFile {
    device: String,
    frames: usize,
    passes: Vec<kage::pass::TimingRow>,
    frame_median_ms: f64,
}

pub fn run(args: &RenderArgs) -> Result<()> {
    if args.frames == 0 {
        anyhow::bail!("--frames must be at least 1");
    }
    if !(args.exposure.is_finite() && args.exposure > 0.0) {
        anyhow::bail!("--exposure must be a positive number");
    }
    let scene = Scene::from_arg(&args.scene)?;
    crate::report_clamped(&scene.environment);
    let ctx = args.gpu.context()?;
    let mut renderer = Renderer::new(
        &ctx,
        &scene,
        &RenderOptions {
            width: args.width,
            height: args.height,
        },
    )
    .context("setting up the renderer")?;
    let bar = ProgressBar::new(args.frames as u64).with_style(
        ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} frames, {elapsed} elapsed, {eta} left",
        )
        .expect("static template"),
    );
    bar.set_message("rendering");
    let start = Instant::now();
    let mut table = TimingTable::default();
    for _ in 0..args.frames {
        table.add_frame(&renderer.render()?);
        bar.inc(1);
        if start.elapsed().as_secs_f32() < 1.0 {
            bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
        } else {
            bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
    }
    bar.finish_and_clear();
    let image = renderer.image()?;
    kage::imageio::write(&args.out, &image, args.exposure)?;
    println!(
        "wrote {} ({}x{}, scene {})",
        args.out.display(),
        args.width,
        args.height,
        scene.name
    );

    let rows = table.rows();
    println!(
        "{:<16} {:>10} {:>10} {:>10} {:>7}",
        "pass", "median ms", "min ms", "max ms", "frames"
    );
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
    if let Some(path) = &args.timings {
        let file = TimingsFile {
            device: ctx.info().name.clone(),
            frames: table.frame_count(),
            passes: rows,
            frame_median_ms: table.frame_median_ms(),
        };
        std::fs::write(path, serde_json::to_string_pretty(&file)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    args.gpu.finish(&ctx)
}
