//! `kage probes capture-image IMAGE`: a light probe captured from an equirectangular photograph
//! or HDR image, as Morishige 2014 captured street-view panoramas: the image projected to 9 SH
//! coefficients per channel on the GPU (the same projection as `kage sh`, so the coefficients
//! are identical), with the irradiance at the six axis normals.
use crate::args::GpuArgs;
use anyhow::{Context as _, Result};
use clap::Args;
use glam::Vec3;
use kage::scene::EnvMap;
use kage::sh::ShRgb9;
use kage::techniques::probes::Dering;
use serde::Serialize;
use std::path::PathBuf;

#[derive(Args)]
pub struct CaptureImageArgs {
    /// An equirectangular image (.exr or .hdr, 2:1), +Y up, −Z at its left edge (README,
    /// "Conventions").
    image: PathBuf,
    /// Also write {"sh": [[r, g, b] × 9], "irradiance": {"+x": [r, g, b], ...}} here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Window on the SH against ringing, as `kage render --probe-dering`.
    #[arg(long, default_value = "off")]
    dering: String,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// The six axis normals and their names.
const AXES: [(&str, Vec3); 6] = [
    ("+x", Vec3::X),
    ("-x", Vec3::NEG_X),
    ("+y", Vec3::Y),
    ("-y", Vec3::NEG_Y),
    ("+z", Vec3::Z),
    ("-z", Vec3::NEG_Z),
];

#[derive(Serialize)]
struct ProbeImageFile {
    sh: [[f32; 3]; 9],
    irradiance: std::collections::BTreeMap<&'static str, [f32; 3]>,
}

pub fn run(args: &CaptureImageArgs) -> Result<()> {
    let dering = Dering::parse(&args.dering)?;
    let map = EnvMap::load(&args.image)?;
    crate::args::report_clamped(&map);
    let ctx = args.gpu.context()?;
    let sh = kage::frame::sh_projection::project(&ctx, &map).context("projecting on the GPU")?;
    let sh: ShRgb9 = dering.apply(&sh);
    crate::outputs::print_coefficients(&sh);
    let irradiance: Vec<(&str, [f32; 3])> = AXES.iter().map(|&(name, n)| (name, sh.irradiance(n))).collect();
    for (name, e) in &irradiance {
        println!("irradiance at {name}: {:.6e} {:.6e} {:.6e}", e[0], e[1], e[2]);
    }
    if let Some(out) = &args.out {
        let file = ProbeImageFile { sh: sh.c, irradiance: irradiance.into_iter().collect() };
        let json = serde_json::to_string_pretty(&file)?;
        std::fs::write(out, json + "\n").with_context(|| format!("writing {}", out.display()))?;
    }
    args.gpu.finish(&ctx)
}
