//! `kage precompute`: the PRT transfer of every vertex of a scene, from the cache when a valid
//! file is there, else computed on the GPU and cached; prints the time and the bytes beside the
//! paper's figures.
use crate::args::GpuArgs;
use crate::transfer_source::{Origin, PrtArgs};
use anyhow::{Context as _, Result};
use clap::Args;
use kage::prt::{PrtParams, TransferSet, Visibility};
use kage::scene::Scene;

#[derive(Args)]
pub struct PrecomputeArgs {
    /// A built-in scene name (those of `kage render --scene`) or a scene file (.json, or glTF 2.0: .gltf, .glb).
    #[arg(long, default_value = "teapot")]
    scene: String,
    #[command(flatten)]
    prt: PrtArgs,
    /// Whose shadows the transfer holds: `group` (each group's own: sloan-self, tamura) or
    /// `scene` (the whole scene at rest: sloan-scene).
    #[arg(long, value_enum, default_value_t = Visibility::Group)]
    visibility: Visibility,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(args: &PrecomputeArgs) -> Result<()> {
    let params = PrtParams { visibility: args.visibility, ..args.prt.params()? };
    let scene = Scene::from_arg(&args.scene)?;
    println!(
        "scene {}: {} groups, {} meshes, {} vertices; {} SH bands ({} coefficients per vertex), \
         {} rays per vertex",
        scene.name,
        scene.groups.len(),
        scene.meshes().count(),
        scene.vertex_count(),
        params.bands,
        params.coeffs(),
        params.rays
    );
    let ctx = args.gpu.context()?;
    let (set, origin) = args.prt.obtain(&ctx, &scene, params)?;
    match origin {
        Origin::Cached(path) => {
            println!("cache: {} is valid, nothing to compute", path.display());
            report(&set, file_len(&path)?, None);
        }
        Origin::Computed { path, file_bytes } => {
            println!("cache: wrote {}", path.display());
            report(&set, file_bytes, Some(&ctx.info().name));
        }
        // Writing the cache is this command's purpose.
        Origin::Unsaved { path, error } => {
            anyhow::bail!("writing the cache file {}: {error}", path.display())
        }
    }
    args.gpu.finish(&ctx)
}

fn file_len(path: &std::path::Path) -> Result<u64> {
    Ok(std::fs::metadata(path).with_context(|| format!("reading the size of {}", path.display()))?.len())
}

/// Time and bytes, and the paper's figures for the two scenes it measured.
fn report(set: &TransferSet, file_bytes: u64, device: Option<&str>) {
    let rays = set.vertex_count() as f64 * f64::from(set.params.rays);
    match device {
        Some(device) => println!(
            "time: {:.2} s (BVH build, upload and transfer; {:.2} M rays/s) on {device}",
            set.seconds,
            rays / set.seconds.max(1e-9) * 1e-6
        ),
        None => println!("time: {:.2} s when the cache file was made", set.seconds),
    }
    if set.traversal_seconds > 0.0 && set.seconds > 0.0 {
        let traversal = f64::from(set.traversal_seconds);
        let rest = (set.seconds - traversal).max(0.0);
        println!(
            "split: ray traversal {traversal:.2} s ({:.2} M rays/s), everything else {rest:.2} s = {:.1} % \
             (BVH build and upload, ray generation, SH sums, mending, readback)",
            rays / traversal * 1e-6,
            100.0 * rest / set.seconds.max(1e-9)
        );
    }
    println!(
        "size: {} bytes of transfer data ({:.1} KB, f32, albedo not included), {} bytes of \
         cache file ({:.1} KB)",
        set.data_bytes(),
        set.data_bytes() as f64 / 1000.0,
        file_bytes,
        file_bytes as f64 / 1000.0
    );
    println!(
        "paper (Tamura et al., Pentium 4 3 GHz + GeForce 6600GT, 3 bands): 10 s / 151 KB for the \
         low-resolution scene (teapot + 961-vertex floor), 88 s / 861 KB for the high-resolution \
         one (teapot + 12,321-vertex floor)"
    );
}
