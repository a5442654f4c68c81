//! `kage bench scale`: what each cost does as the scene grows. One scene family at several
//! triangle counts (the default scene with its teapot replaced by a generated bumpy sphere of
//! N triangles, which shadows itself; a spot light added for the shadow-map techniques): BVH
//! build, PRT precomputation, device memory and frame time per technique, side by side in one
//! run; `DIR/scale.csv` and a log-log chart `DIR/scale.png`, each curve's slope printed per
//! decade.
use crate::args::{technique_name, GpuArgs};
use crate::chart;
use anyhow::{anyhow, bail, Context as _, Result};
use clap::Args;
use glam::Vec3;
use kage::pass::TimingTable;
use kage::prt::{transfer, PrtParams, TransferSet};
use kage::raycast::SceneBvh;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{motion, shapes, Group, Light, Mesh, Scene, Transform};
use kage::techniques::description::{TechniqueDesc, TechniqueKind};
use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Args)]
pub struct ScaleArgs {
    /// Triangles of the generated object at each step (the 1,800-triangle floor comes on top).
    #[arg(long, value_delimiter = ',', default_values_t = [1_000, 10_000, 100_000, 1_000_000])]
    triangles: Vec<u32>,
    /// PRT rays per vertex (the precomputation's time grows linearly with them).
    #[arg(long, default_value_t = 256)]
    rays: u32,
    /// Techniques timed at each step.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [
        TechniqueKind::Unshadowed, TechniqueKind::SloanSelf, TechniqueKind::Tamura,
        TechniqueKind::ParallelLights, TechniqueKind::ShadowMap, TechniqueKind::Asm, TechniqueKind::Probes])]
    techniques: Vec<TechniqueKind>,
    /// Side of the timed frames, pixels.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// Frames timed per technique and step while the object hops (after one untimed frame);
    /// the median is reported.
    #[arg(long, default_value_t = 10)]
    frames: u32,
    /// Folder for scale.csv and scale.png.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// One measured step.
struct Step {
    triangles: usize,
    vertices: usize,
    bvh_ms: f64,
    bvh_mb: f64,
    precompute_s: Option<f64>,
    traversal_s: Option<f64>,
    /// Per technique: device memory (MB) and median frame (ms).
    techniques: Vec<(TechniqueKind, f64, f64)>,
    peak_rss_mb: f64,
}

pub fn run(args: &ScaleArgs) -> Result<()> {
    if args.triangles.is_empty() || args.techniques.is_empty() || args.frames == 0 {
        bail!("give at least one triangle count, one technique and one frame");
    }
    let prt = PrtParams { rays: args.rays, ..PrtParams::DEFAULT }.validated()?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let ctx = args.gpu.context()?;
    println!(
        "{:>10} {:>9} {:>7} {:>11} {:>8} {:>9} {:>9}  per technique: MB, ms",
        "triangles", "BVH ms", "BVH MB", "precomp. s", "Mrays/s", "not rays", "peak RSS"
    );
    let mut steps = Vec::new();
    for &target in &args.triangles {
        let step = measure(&ctx, args, prt, target).with_context(|| format!("at {target} triangles"))?;
        let mut line = format!(
            "{:>10} {:>9.1} {:>7.1} {:>11} {:>8} {:>9} {:>7.0}MB ",
            step.triangles,
            step.bvh_ms,
            step.bvh_mb,
            step.precompute_s.map_or("-".into(), |s| format!("{s:.2}")),
            step.precompute_s.map_or("-".into(), |s| format!("{:.2}", rays(&step, prt) / s * 1e-6)),
            step.precompute_s
                .zip(step.traversal_s)
                .map_or("-".into(), |(s, t)| format!("{:.1} %", 100.0 * (s - t) / s)),
            step.peak_rss_mb
        );
        for (kind, mb, ms) in &step.techniques {
            write!(line, " {}: {mb:.1}, {ms:.1};", technique_name(*kind)).expect("writing to a String");
        }
        println!("{line}");
        steps.push(step);
    }
    print_slopes(&steps);
    let csv_path = args.out.join("scale.csv");
    std::fs::write(&csv_path, csv(&steps, prt)).with_context(|| format!("writing {}", csv_path.display()))?;
    let png_path = args.out.join("scale.png");
    draw_chart(&png_path, &steps, prt, args).with_context(|| format!("drawing {}", png_path.display()))?;
    println!(
        "wrote {} and {} ({}, {}² frames, {} PRT rays per vertex)",
        csv_path.display(),
        png_path.display(),
        ctx.info().name,
        args.size,
        args.rays
    );
    args.gpu.finish(&ctx)
}

/// The PRT rays of a step: every vertex casts `prt.rays`.
fn rays(step: &Step, prt: PrtParams) -> f64 {
    step.vertices as f64 * f64::from(prt.rays)
}

fn measure(ctx: &Arc<kage::backend::Context>, args: &ScaleArgs, prt: PrtParams, target: u32) -> Result<Step> {
    let scene = scene(target)?;
    let triangles = scene.triangle_count();
    let start = Instant::now();
    let bvh = SceneBvh::build(&scene)?;
    let bvh_ms = start.elapsed().as_secs_f64() * 1e3;
    let bvh_mb = bvh.byte_size() as f64 / (1 << 20) as f64;
    drop(bvh);

    // One precomputation per parameter set the techniques ask for.
    let mut transfers: HashMap<(u32, u32, u32), Arc<TransferSet>> = HashMap::new();
    let mut techniques = Vec::new();
    let mut group_transfer = None;
    for &kind in &args.techniques {
        let technique = TechniqueDesc::new(kind).with_prt(prt);
        let transfer = match technique.precomputation() {
            Some(params) => {
                let key = (params.bands, params.rays, params.visibility as u32);
                let set = match transfers.get(&key) {
                    Some(set) => set.clone(),
                    None => {
                        let set =
                            Arc::new(transfer::precompute(ctx, &scene, params, &mut kage::progress::silent)?);
                        transfers.insert(key, set.clone());
                        set
                    }
                };
                if params.visibility == kage::prt::Visibility::Group {
                    group_transfer = Some(set.clone());
                }
                Some(set)
            }
            None => None,
        };
        let before = ctx.allocated_bytes();
        let options = RenderOptions { width: args.size, height: args.size, technique, transfer };
        let mut renderer = Renderer::new(ctx, &scene, &options)
            .with_context(|| format!("setting up {}", technique_name(kind)))?;
        let mb = (ctx.allocated_bytes() - before) as f64 / (1 << 20) as f64;
        renderer.render()?;
        let mut table = TimingTable::default();
        for frame in 0..args.frames {
            renderer.set_time(frame as f32 / args.frames as f32 * scene.duration())?;
            table.add_frame(&renderer.render()?);
        }
        techniques.push((kind, mb, table.frame_median_ms()));
    }
    Ok(Step {
        triangles,
        vertices: scene.vertex_count(),
        bvh_ms,
        bvh_mb,
        precompute_s: group_transfer.as_ref().map(|t| t.seconds),
        traversal_s: group_transfer.as_ref().map(|t| f64::from(t.traversal_seconds)),
        techniques,
        peak_rss_mb: peak_rss_bytes()? as f64 / (1 << 20) as f64,
    })
}

/// The default scene with its teapot replaced by a bumpy sphere of about `triangles`
/// triangles (a UV sphere of s segments has s² - 2s), hopping as the teapot does, and a spot
/// light above for the shadow-map techniques.
fn scene(triangles: u32) -> Result<Scene> {
    let segments = ((f64::from(triangles)).sqrt().round() as u32 + 1).max(4);
    let mut scene = Scene::builtin("teapot")?;
    scene.name = format!("scale-{triangles}");
    let sphere = shapes::sphere("blob", 0.5, segments, [0.75; 3])?;
    // Bumps of 15 % of the radius, about six across: each shadows its neighbours.
    let positions = sphere
        .positions
        .iter()
        .map(|p| {
            let d = Vec3::from(*p).normalize();
            let bump = (6.0 * d.x).sin() * (6.0 * d.y).sin() * (6.0 * d.z).sin();
            (d * 0.5 * (1.0 + 0.15 * bump)).to_array()
        })
        .collect();
    let blob = Mesh::new("blob", positions, None, sphere.indices.clone(), [0.75; 3])?;
    scene.groups[0] = motion::hopping(Group::new(
        "blob",
        vec![blob],
        Transform { translation: Vec3::new(0.0, 0.5, 0.0), ..Transform::default() },
    ));
    scene.lights.push(
        Light::Spot {
            position: Vec3::new(1.0, 3.0, 1.0),
            direction: Vec3::new(-1.0, -3.0, -1.0),
            fov_deg: 60.0,
            intensity: [20.0; 3],
        }
        .validated()?,
    );
    Ok(scene)
}

/// The process's peak resident memory (VmHWM).
fn peak_rss_bytes() -> Result<u64> {
    let status = std::fs::read_to_string("/proc/self/status").context("reading /proc/self/status")?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).ok_or_else(|| anyhow!("no VmHWM line"))?;
    let kb: u64 =
        line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).ok_or_else(|| anyhow!("bad {line}"))?;
    Ok(kb * 1024)
}

/// Every measured series: name, unit and one value per step (None where not measured).
fn series(steps: &[Step], prt: PrtParams) -> Vec<(String, &'static str, Vec<Option<f64>>)> {
    let mut out = vec![
        ("BVH build".to_string(), "ms", steps.iter().map(|s| Some(s.bvh_ms)).collect()),
        (
            format!("PRT precompute ({} rays)", prt.rays),
            "ms",
            steps.iter().map(|s| s.precompute_s.map(|v| v * 1e3)).collect(),
        ),
        ("BVH".to_string(), "MB", steps.iter().map(|s| Some(s.bvh_mb)).collect()),
        ("peak RSS".to_string(), "MB", steps.iter().map(|s| Some(s.peak_rss_mb)).collect()),
    ];
    for (t, (kind, _, _)) in steps[0].techniques.iter().enumerate() {
        out.push((
            format!("{} frame", technique_name(*kind)),
            "ms",
            steps.iter().map(|s| Some(s.techniques[t].2)).collect(),
        ));
        out.push((
            format!("{} memory", technique_name(*kind)),
            "MB",
            steps.iter().map(|s| Some(s.techniques[t].1)).collect(),
        ));
    }
    out
}

/// Each series' log-log slope per interval: 1 is linear in the triangles, 0 flat.
fn print_slopes(steps: &[Step]) {
    if steps.len() < 2 {
        return;
    }
    println!("log-log slopes between consecutive steps (1: linear in triangles, 0: flat):");
    for (name, unit, values) in series(steps, PrtParams::DEFAULT) {
        let slopes: Vec<String> = steps
            .windows(2)
            .zip(values.windows(2))
            .map(|(s, v)| match (v[0], v[1]) {
                (Some(a), Some(b)) if a > 0.0 && b > 0.0 => {
                    format!("{:.2}", (b / a).ln() / (s[1].triangles as f64 / s[0].triangles as f64).ln())
                }
                _ => "-".into(),
            })
            .collect();
        let name = if name.starts_with("PRT") { "PRT precompute".to_string() } else { name };
        println!("  {name:<28} ({unit}) {}", slopes.join("  "));
    }
}

fn csv(steps: &[Step], prt: PrtParams) -> String {
    let all = series(steps, prt);
    let mut out = String::from("triangles");
    for (name, unit, _) in &all {
        write!(out, ",{name} ({unit})").expect("writing to a String");
    }
    out.push('\n');
    for (i, step) in steps.iter().enumerate() {
        write!(out, "{}", step.triangles).expect("writing to a String");
        for (_, _, values) in &all {
            match values[i] {
                Some(v) => write!(out, ",{v:.3}"),
                None => write!(out, ","),
            }
            .expect("writing to a String");
        }
        out.push('\n');
    }
    out
}

/// Two log-log panels against triangles: times (ms) on the left, memory (MB) on the right.
fn draw_chart(path: &std::path::Path, steps: &[Step], prt: PrtParams, args: &ScaleArgs) -> Result<()> {
    chart::font()?;
    let size = (chart::SIZE.0 * 2, chart::SIZE.1);
    let mut pixels = vec![0u8; (size.0 * size.1 * 3) as usize];
    let all = series(steps, prt);
    let xs = steps.iter().map(|s| s.triangles as f64);
    let x_range = (xs.clone().fold(f64::INFINITY, f64::min) / 1.5)..(xs.fold(0.0, f64::max) * 1.5);
    {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let panels = root.split_evenly((1, 2));
        for (panel, unit) in panels.iter().zip(["ms", "MB"]) {
            let chosen: Vec<_> = all.iter().filter(|(_, u, _)| *u == unit).collect();
            let values = chosen.iter().flat_map(|(_, _, v)| v.iter().flatten().copied()).filter(|v| *v > 0.0);
            let lo = values.clone().fold(f64::INFINITY, f64::min);
            let hi = values.fold(0.0, f64::max);
            let y_range = (lo / 1.5)..(hi * 1.5);
            let title = if unit == "ms" {
                format!("time against triangles ({}, {}² frames)", "median of the frames", args.size)
            } else {
                "memory against triangles (device memory per technique)".to_string()
            };
            let mut c = ChartBuilder::on(panel)
                .caption(title, ("sans-serif", 20))
                .margin(20)
                .x_label_area_size(50)
                .y_label_area_size(80)
                .build_cartesian_2d(
                    x_range.clone().log_scale().with_key_points(chart::ticks(&x_range)),
                    y_range.clone().log_scale().with_key_points(chart::ticks(&y_range)),
                )
                .map_err(|e| anyhow!("{e}"))?;
            c.configure_mesh()
                .x_desc("triangles")
                .y_desc(if unit == "ms" { "ms" } else { "MB" })
                .x_label_formatter(&chart::tick_label)
                .y_label_formatter(&chart::tick_label)
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(|e| anyhow!("{e}"))?;
            for (i, (name, _, values)) in chosen.iter().enumerate() {
                let colour = Palette99::pick(i).to_rgba();
                let points: Vec<(f64, f64)> = steps
                    .iter()
                    .zip(values.iter())
                    .filter_map(|(s, v)| v.filter(|v| *v > 0.0).map(|v| (s.triangles as f64, v)))
                    .collect();
                c.draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                    .map_err(|e| anyhow!("{e}"))?
                    .label(name.as_str())
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
                c.draw_series(points.into_iter().map(|p| Circle::new(p, 4, colour.filled())))
                    .map_err(|e| anyhow!("{e}"))?;
            }
            c.configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .label_font(("sans-serif", 13))
                .draw()
                .map_err(|e| anyhow!("{e}"))?;
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    image::RgbImage::from_raw(size.0, size.1, pixels)
        .ok_or_else(|| anyhow!("the chart buffer does not hold {}x{} pixels", size.0, size.1))?
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}
