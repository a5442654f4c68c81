//! `kage sweep --technique probes`: light probes on regular grids (trilinear and tetrahedral
//! interpolation) against automatic placement (tetrahedral), each in the static groups' box and
//! in the box the moving group sweeps, measured as `kage bench probe-count` measures them: the
//! relative RMS error of interpolated irradiance against the ray-cast truth at test points
//! along the moving group's path (`--test-region box`: anywhere in the static box, the probes
//! over the box only), against the number of probes. The probe count is the cost
//! here (SH storage and captures; the per-frame lookup is one walk per object whatever the
//! count), so the chart's x axis counts probes and `--pick` takes `--max-probes`.
use super::{write_outputs, SweepArgs, Terms};
use crate::bench::probe_count::{measure, Params, TestRegion, DEFAULT_GRIDS, DEFAULT_TOLERANCES};
use crate::chart::pick::Point;
use crate::chart::Axes;
use anyhow::{bail, Context as _, Result};
use kage::sh::ShRgb9;
use kage::techniques::probes::CaptureSettings;
use kage::techniques::probes::{CapturedLight, ProbeVisibility};
use std::fmt::Write as _;

/// Tolerances over the whole box, where the kept set grows from 4 probes to 57 between
/// tolerances 1.75 and 1 (BENCHMARKS.md).
const BOX_TOLERANCES: [f32; 8] = [1.75, 1.5, 1.25, 1.0, 0.75, 0.5, 0.25, 0.1];
/// Test positions, and random normals at each: as BENCHMARKS.md runs `kage bench probe-count`
/// (the reference for 1024 points takes 13 s on two cores).
const POINTS: usize = 256;
const NORMALS: usize = 4;
/// Cube-map faces of the captures, texels: the error floor of a probe captured at a test point
/// is the same at 32² as at 128² on these scenes (bench probe-count's floor), at 1/16 the time.
const CUBE_SIZE: u32 = 32;

pub fn run(args: &SweepArgs) -> Result<()> {
    if args.max_ms.is_some() {
        bail!("--max-ms: the probe sweep's cost is its probe count, not frame time: use --max-probes N");
    }
    if !args.only.is_empty() {
        bail!("--only: the probe sweep measures every grid level and tolerance together (the automatic placement starts from the finest grid)");
    }
    let scene = crate::args::read_scene(args.scene.as_deref().unwrap_or("probe-room"), false)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let ctx = args.gpu.context()?;
    let cache = args.out.join("reference-cache");
    let test_region = args.test_region.unwrap_or(TestRegion::Path);
    let spp = args.spp.unwrap_or(512);
    let params = Params {
        test_region,
        grids: &DEFAULT_GRIDS,
        candidates: None,
        tolerances: if test_region == TestRegion::Box { &BOX_TOLERANCES } else { &DEFAULT_TOLERANCES },
        points: POINTS,
        normals: NORMALS,
        spp,
        capture: CaptureSettings { cube_size: CUBE_SIZE, light: CapturedLight::Sky, ..Default::default() },
        cache: Some(&cache),
        // As `kage render` looks probes up by default.
        visibility: &[ProbeVisibility::Rays],
        closed_room: false,
        path_frames: 0,
    };
    let m = measure(&ctx, &scene, &params).with_context(|| format!("scene {}", scene.name))?;
    println!(
        "scene {}: {} test points x {NORMALS} normals, reference {} spp (noise {:.4} of the RMS irradiance), a probe at each point {:.4}, capture {:.1} ms per probe, {}",
        scene.name,
        m.test_points,
        spp,
        m.reference_noise,
        m.capture_floor,
        m.capture_ms_per_probe,
        ctx.info().name
    );
    let mut csv = String::from("scene,technique,parameter,value,probes,error,capture_s,memory_mb\n");
    let mut points = Vec::new();
    for row in &m.rows {
        let (parameter, value) = row.setting.parameter();
        let capture_s = row.probes as f64 * m.capture_ms_per_probe / 1e3;
        let memory_mb = (row.probes * size_of::<ShRgb9>()) as f64 / (1 << 20) as f64;
        writeln!(
            csv,
            "{},\"{}\",{parameter},{value},{},{:.6},{capture_s:.3},{memory_mb:.4}",
            scene.name, row.method, row.probes, row.error
        )
        .expect("writing to a String");
        println!(
            "{:<32} {:>12} {:>6} probes, relative RMS error {:.4}",
            row.method, row.setting, row.probes, row.error
        );
        if row.error > 0.0 && row.probes > 0 {
            points.push(Point {
                series: row.method.clone(),
                name: format!("{} {}", row.method, row.setting),
                label: row.probes.to_string(),
                ms: row.probes as f64,
                error: row.error,
            });
        }
    }
    let (region, device) = (test_region.describe(), &ctx.info().name);
    let title = format!("{} ({} x {NORMALS} test points {region}), {device}", scene.name, m.test_points);
    let axes = Axes { cost: "probes", error: "relative RMS irradiance error against the reference" };
    write_outputs(
        args,
        &scene.name,
        &csv,
        (&title, &axes),
        &points,
        args.max_probes.map(f64::from),
        &Terms { metric: "relative RMS error", unit: "probes" },
    )?;
    args.gpu.finish(&ctx)
}
