//! `kage probes tetrahedralize` and `kage probes lookup`: the probe set's tetrahedra, and the
//! tetrahedron and weights of one point.
use anyhow::{Context as _, Result};
use clap::{Args, Subcommand};
use glam::DVec3;
use kage::techniques::probes::{TetMesh, Walker};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Subcommand)]
pub enum ProbesCommand {
    /// Delaunay tetrahedralization of a probe set: {"positions": [[x,y,z], ...]} in,
    /// {"tetrahedra": [[i,j,k,l], ...]} out (input indices, positively oriented).
    Tetrahedralize(TetrahedralizeArgs),
    /// The tetrahedron holding a point and its four barycentric weights (outside the hull: those
    /// of the hull's nearest point).
    Lookup(LookupArgs),
    /// A probe from an equirectangular photograph or HDR image: its 9 SH coefficients per
    /// channel and the irradiance at the six axis normals.
    CaptureImage(crate::probe_image::CaptureImageArgs),
}

#[derive(Args)]
pub struct TetrahedralizeArgs {
    /// The probe set: {"positions": [[x,y,z], ...]}.
    #[arg(long = "in")]
    input: PathBuf,
    /// Where to write {"tetrahedra": [[i,j,k,l], ...]}.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args)]
pub struct LookupArgs {
    /// The probe set: {"positions": [[x,y,z], ...]}.
    #[arg(long = "in")]
    input: PathBuf,
    /// The point, as x,y,z.
    #[arg(long, value_parser = crate::parse_xyz::<f64>, allow_hyphen_values = true)]
    at: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ProbeFile {
    positions: Vec<[f64; 3]>,
}

#[derive(Serialize)]
struct TetFile<'a> {
    tetrahedra: &'a [[u32; 4]],
}

pub fn run(command: &ProbesCommand) -> Result<()> {
    match command {
        ProbesCommand::Tetrahedralize(args) => tetrahedralize(args),
        ProbesCommand::Lookup(args) => lookup(args),
        ProbesCommand::CaptureImage(args) => crate::probe_image::run(args),
    }
}

/// The positions of a probe file.
pub fn read_positions(path: &Path) -> Result<Vec<DVec3>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let file: ProbeFile = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a probe file {{\"positions\": [[x,y,z], ...]}}", path.display()))?;
    Ok(file.positions.into_iter().map(DVec3::from_array).collect())
}

/// Reads and tetrahedralizes a probe file, warning about merged duplicates.
fn load(path: &Path) -> Result<TetMesh> {
    let positions = read_positions(path)?;
    let mesh = TetMesh::build(&positions).with_context(|| format!("tetrahedralizing {}", path.display()))?;
    if !mesh.merged().is_empty() {
        let pairs: Vec<String> =
            mesh.merged().iter().map(|m| format!("{} into {}", m.index, m.kept)).collect();
        eprintln!(
            "kage: warning: {} duplicate probe position(s) merged (index into the kept one): {}",
            pairs.len(),
            pairs.join(", ")
        );
    }
    Ok(mesh)
}

fn tetrahedralize(args: &TetrahedralizeArgs) -> Result<()> {
    let start = Instant::now();
    let mesh = load(&args.input)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let json = serde_json::to_string(&TetFile { tetrahedra: mesh.tets() })?;
    std::fs::write(&args.out, json + "\n").with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "{} probes ({} distinct), tetrahedra: {}, built in {ms:.1} ms; written to {}",
        mesh.positions().len(),
        mesh.positions().len() - mesh.merged().len(),
        mesh.tets().len(),
        args.out.display()
    );
    Ok(())
}

fn lookup(args: &LookupArgs) -> Result<()> {
    let mesh = load(&args.input)?;
    let at = Walker::default().locate(&mesh, DVec3::from_array(args.at))?;
    let probes = at.probes.map(|p| p.to_string()).join(" ");
    println!("tetrahedron {}: probes {probes}", at.tet);
    println!("weights {}", at.weights.map(|w| format!("{w:.9}")).join(" "));
    if at.extrapolated {
        println!("outside the hull: extrapolated (the weights of the hull's nearest point)");
    } else {
        println!("inside the hull");
    }
    Ok(())
}
