//! `kage bench rays`: how fast the BVH is built on the CPU and traversed on the GPU.
use super::Pcg32;
use crate::args::GpuArgs;
use crate::progress::Bar;
use anyhow::{bail, Context as _, Result};
use clap::Args;
use glam::Vec3;
use kage::layouts::{constants, CastRay};
use kage::prt::{directions, PrtParams};
use kage::raycast::{offset_ray_origin, GpuBvh, GpuRays, Query, RayCaster, SceneBvh};
use kage::scene::Scene;
use std::time::Instant;

#[derive(Args)]
pub struct RaysArgs {
    /// A built-in scene name (those of `kage render --scene`) or a scene file (.json, or glTF 2.0: .gltf, .glb).
    #[arg(long, default_value = "teapot")]
    scene: String,
    /// Rays per cast, rounded down to a square number for the camera's square image.
    #[arg(long, default_value_t = 262_144)]
    rays: u32,
    /// Timed casts per measurement, after one untimed warm-up (which includes a JIT compile
    /// on CPU drivers); the median is reported.
    #[arg(long, default_value_t = 5)]
    runs: u32,
    /// Also writes the scene's world-space triangles and both ray sets to this folder as raw
    /// little-endian 32-bit values, for `scripts/embree-rays.py` to cast the same rays:
    /// `triangles.f32` (9 per triangle), `triangle-groups.u32` (each triangle's group),
    /// `coherent.f32`, `incoherent.f32` (origin, direction, tmax per ray) and `prt.f32`: the
    /// PRT precomputation's rays (default 2048 per vertex, each against its own group) of every
    /// 16th vertex, in world space, with the group as an f32 after the tmax.
    #[arg(long, value_name = "DIR")]
    export: Option<std::path::PathBuf>,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(args: &RaysArgs) -> Result<()> {
    if args.runs == 0 {
        bail!("--runs must be at least 1");
    }
    let side = (args.rays as f64).sqrt() as u32;
    if side == 0 {
        bail!("--rays must be at least 1");
    }
    let scene = Scene::from_arg(&args.scene)?;
    if scene.triangle_count() == 0 {
        bail!("scene {} has no triangles to cast rays at", scene.name);
    }
    let start = Instant::now();
    let bvh = SceneBvh::build(&scene).context("building the BVH")?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    println!(
        "scene {}: {} triangles in {} groups; BVH built in {build_ms:.1} ms (CPU), {} nodes, {:.2} MiB",
        scene.name,
        scene.triangle_count(),
        scene.groups.len(),
        bvh.node_count(),
        bvh.byte_size() as f64 / (1 << 20) as f64
    );

    let ctx = args.gpu.context()?;
    if ctx.info().timestamp_period_ns.is_none() {
        bail!("{} has no GPU timestamps, so cast times cannot be measured", ctx.info().name);
    }
    let gpu = GpuBvh::new(&ctx, &bvh)?;
    let mut caster = RayCaster::new(&ctx)?;
    let (coherent, incoherent) = (camera_rays(&scene, side), surface_rays(&scene, side * side));
    if let Some(dir) = &args.export {
        export(dir, &scene, &coherent, &incoherent)?;
    }
    let sets =
        [("coherent", GpuRays::new(&ctx, &coherent)?), ("incoherent", GpuRays::new(&ctx, &incoherent)?)];
    let queries = [("closest hit", Query::ClosestHit), ("any hit", Query::Occluded)];

    let bar = Bar::new((sets.len() * queries.len()) as u64 * (args.runs as u64 + 1), "casts");
    bar.message("casting");
    let count = (side * side) as f64;
    let mut rates = Vec::new();
    for (query_name, query) in queries {
        let mut row = Vec::new();
        for (set_name, rays) in &sets {
            let mut ms = Vec::new();
            for run in 0..=args.runs {
                let gpu_ms = caster.cast(&gpu, rays, query)?.context("the cast pass returned no GPU time")?;
                if run > 0 {
                    ms.push(gpu_ms);
                }
                bar.advance(1);
            }
            ms.sort_by(f64::total_cmp);
            let median = ms[ms.len() / 2];
            // What the rays hit, to compare BVH layouts and other tracers by: how many hit, and
            // for closest hits the sum of their distances.
            let results = rays.read()?;
            let hits: Vec<_> = results.iter().filter(|r| r.ids[0] != constants::NO_HIT).collect();
            let distance = hits.iter().map(|r| f64::from(r.hit[0])).sum::<f64>();
            row.push((*set_name, median, count / (median * 1e-3), hits.len(), distance));
        }
        rates.push((query_name, row));
    }
    drop(bar);

    println!("{} rays per cast ({side}x{side} camera image; as many random surface rays), median of {} runs, GPU time, {}", side * side, args.runs, ctx.info().name);
    println!(
        "{:<12} {:>10} {:>14} {:>10} {:>14} {:>10}   hits (coherent, incoherent; closest: sum of t)",
        "query", "coh. ms", "coh. Mrays/s", "inc. ms", "inc. Mrays/s", "coh./inc."
    );
    for (query_name, row) in &rates {
        let [(_, coherent_ms, coherent, coherent_hits, coherent_t), (_, incoherent_ms, incoherent, incoherent_hits, incoherent_t)] =
            row[..]
        else {
            unreachable!("two ray sets")
        };
        let distances = if *query_name == "closest hit" {
            format!("; {coherent_t:.6e}, {incoherent_t:.6e}")
        } else {
            String::new()
        };
        println!(
            "{query_name:<12} {coherent_ms:>10.2} {:>14.3} {incoherent_ms:>10.2} {:>14.3} {:>10.2}   {coherent_hits}, {incoherent_hits}{distances}",
            coherent * 1e-6,
            incoherent * 1e-6,
            coherent / incoherent
        );
    }
    args.gpu.finish(&ctx)
}

/// Writes what `--export` promises (see [`RaysArgs::export`]).
fn export(dir: &std::path::Path, scene: &Scene, coherent: &[CastRay], incoherent: &[CastRay]) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let write = |name: &str, floats: Vec<f32>| {
        let path = dir.join(name);
        let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
        std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))
    };
    write("triangles.f32", world_triangles(scene).iter().flatten().flat_map(|v| v.to_array()).collect())?;
    let groups: Vec<u8> = scene
        .groups
        .iter()
        .enumerate()
        .flat_map(|(g, group)| {
            std::iter::repeat_n(g as u32, group.meshes.iter().map(|m| m.indices.len() / 3).sum())
        })
        .flat_map(u32::to_le_bytes)
        .collect();
    let path = dir.join("triangle-groups.u32");
    std::fs::write(&path, groups).with_context(|| format!("writing {}", path.display()))?;
    write("prt.f32", prt_rays(scene, PRT_SAMPLE))?;
    for (name, rays) in [("coherent.f32", coherent), ("incoherent.f32", incoherent)] {
        let floats =
            rays.iter().flat_map(|r| [&r.origin[..3], &r.direction[..3], &r.origin[3..]].concat()).collect();
        write(name, floats)?;
    }
    Ok(())
}

/// `--export` writes the PRT rays of every this-many-th vertex.
const PRT_SAMPLE: usize = 16;

/// The rays `prt_transfer.comp` casts from every `every`-th vertex ([`directions::direction`],
/// from the origin the shader offsets), in world space, each as origin, direction, tmax and
/// its group as an f32.
fn prt_rays(scene: &Scene, every: usize) -> Vec<f32> {
    let rays = PrtParams::DEFAULT.rays;
    let mut out = Vec::new();
    let vertices = scene.groups.iter().enumerate().flat_map(|(g, group)| {
        group
            .meshes
            .iter()
            .flat_map(move |m| m.positions.iter().zip(&m.normals).map(move |(p, n)| (g, group, *p, *n)))
    });
    for (vertex, (g, group, position, normal)) in vertices.enumerate().step_by(every) {
        let n = Vec3::from(normal).normalize();
        let to_world = group.transform.matrix();
        let origin = to_world.transform_point3(offset_ray_origin(position.into(), n));
        for k in 0..rays {
            let dir =
                to_world.transform_vector3(directions::direction(vertex as u32, n, k, rays)).normalize();
            out.extend(origin.to_array());
            out.extend(dir.to_array());
            out.extend([1e30, g as f32]);
        }
    }
    out
}

/// Every triangle of the scene in world space, at rest.
fn world_triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    scene
        .meshes()
        .flat_map(|(group, mesh)| {
            let to_world = group.transform.matrix();
            mesh.indices.chunks_exact(3).map(move |t| {
                [0, 1, 2].map(|k| to_world.transform_point3(mesh.positions[t[k] as usize].into()))
            })
        })
        .collect()
}

/// One ray through each pixel centre of a side x side image from the scene camera.
fn camera_rays(scene: &Scene, side: u32) -> Vec<CastRay> {
    let camera = &scene.camera;
    let forward = (camera.target - camera.position).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let half = (camera.fov_y_deg.to_radians() * 0.5).tan();
    (0..side * side)
        .map(|i| {
            let x = ((i % side) as f32 + 0.5) / side as f32 * 2.0 - 1.0;
            let y = 1.0 - ((i / side) as f32 + 0.5) / side as f32 * 2.0;
            let dir = (forward + half * (x * right + y * up)).normalize();
            ray(camera.position, dir)
        })
        .collect()
}

/// Uniformly distributed points on the scene's surfaces (by area), each with a uniformly
/// random direction, leaving the surface on the side the direction points to.
fn surface_rays(scene: &Scene, count: u32) -> Vec<CastRay> {
    let triangles = world_triangles(scene);
    let mut cumulative = Vec::with_capacity(triangles.len());
    let mut total = 0.0f64;
    for t in &triangles {
        total += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length() as f64;
        cumulative.push(total);
    }
    let mut rng = Pcg32(0x853c_49e6_748f_ea9b);
    (0..count)
        .map(|_| {
            let pick = rng.next() as f64 * total;
            let t = triangles[cumulative.partition_point(|&c| c < pick).min(triangles.len() - 1)];
            let (mut a, mut b) = (rng.next(), rng.next());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let p = t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]);
            let dir = rng.unit_vector();
            let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            let side = if normal.dot(dir) >= 0.0 { normal } else { -normal };
            ray(offset_ray_origin(p, side), dir)
        })
        .collect()
}

fn ray(origin: Vec3, dir: Vec3) -> CastRay {
    CastRay { origin: origin.extend(1e30).to_array(), direction: dir.extend(0.0).to_array() }
}
