//! `kage sh MAP`: the environment's SH coefficients, and optionally the irradiance they give.
use crate::args::GpuArgs;
use anyhow::{Context as _, Result};
use clap::Args;
use kage::scene::EnvMap;
use std::path::PathBuf;

#[derive(Args)]
pub struct ShArgs {
    /// An equirectangular map (.exr or .hdr, 2:1).
    map: PathBuf,
    /// Also print the irradiance E(n) for this normal, given as x,y,z (normalised for you).
    #[arg(long, value_parser = parse_vec3)]
    irradiance: Option<glam::Vec3>,
    #[command(flatten)]
    gpu: GpuArgs,
}

fn parse_vec3(s: &str) -> Result<glam::Vec3, String> {
    crate::args::parse_xyz(s).map(glam::Vec3::from_array)
}

pub fn run(args: &ShArgs) -> Result<()> {
    let map = EnvMap::load(&args.map)?;
    crate::args::report_clamped(&map);
    let ctx = args.gpu.context()?;
    let sh = kage::frame::sh_projection::project(&ctx, &map).context("projecting on the GPU")?;
    crate::outputs::print_coefficients(&sh);
    if let Some(n) = args.irradiance {
        if n.length_squared() == 0.0 {
            anyhow::bail!("--irradiance needs a non-zero normal");
        }
        let n = n.normalize();
        let e = sh.irradiance(n);
        println!(
            "irradiance at n = ({:.6}, {:.6}, {:.6}): {:.6e} {:.6e} {:.6e}",
            n.x, n.y, n.z, e[0], e[1], e[2]
        );
    }
    args.gpu.finish(&ctx)
}
