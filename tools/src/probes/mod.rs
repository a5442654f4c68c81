//! `kage probes tetrahedralize` and `kage probes lookup`: the probe set's tetrahedra, and the
//! tetrahedron and weights of one point; `kage probes place`: automatic placement in a scene.
mod capture_image;

use anyhow::{Context as _, Result};
use clap::{Args, Subcommand};
use glam::DVec3;
use kage::frame::GpuScene;
use kage::techniques::probes::{
    positions_file, CaptureSettings, ProbePlacement, ProbeSet, ProbeSettings, TetMesh, Walker,
};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Subcommand)]
pub enum ProbesCommand {
    /// Delaunay tetrahedralization of a probe set: `{"positions": [[x,y,z], ...]}` in,
    /// `{"tetrahedra": [[i,j,k,l], ...]}` out (input indices, positively oriented).
    ///
    /// kage probes tetrahedralize --in PROBES.json --out TETS.json: the Delaunay tetrahedralization
    /// of a probe set (see "Probes")
    Tetrahedralize(TetrahedralizeArgs),
    /// The tetrahedron holding a point and its four barycentric weights (outside the hull: those
    /// of the hull's nearest point).
    ///
    /// kage probes lookup --in PROBES.json --at x,y,z: the tetrahedron holding a point, its four
    /// probes and their barycentric weights, and whether the point was outside the hull
    /// (extrapolated)
    Lookup(LookupArgs),
    /// A probe from an equirectangular photograph or HDR image: its 9 SH coefficients per
    /// channel and the irradiance at the six axis normals.
    ///
    /// kage probes capture-image IMAGE [--out PROBE.json] [--dering W]: a probe from an
    /// equirectangular photo or HDR image (as the paper captured street-view panoramas): its 9×3 SH
    /// coefficients (the projection of `kage sh`, identical) and the irradiance at the six axis
    /// normals; `--out` writes `{"sh": [[r,g,b] × 9], "irradiance": {"+x": [r,g,b], ...}}`
    CaptureImage(capture_image::CaptureImageArgs),
    /// Automatic placement: candidates on a grid over the scene's static groups (those inside
    /// solids or sealed in pockets of free space dropped) are captured, the redundant ones
    /// dropped; the kept positions are written as a probe file for `kage render --probes FILE`.
    ///
    /// kage probes place [--scene S] [--probes auto:TOL] [--probe-cube-size N] [--probe-light
    /// sky-and-walls|sky] --out PROBES.json: automatic placement once: prints how many of the
    /// candidates are kept and writes their positions for `--probes PROBES.json` (a render from the
    /// file captures each position: the fit to the candidates needs them, so it is `--probes
    /// auto`'s alone)
    Place(PlaceArgs),
}

#[derive(Args)]
pub struct PlaceArgs {
    /// A built-in scene name or a scene file (.json, or glTF 2.0: .gltf, .glb).
    #[arg(long, default_value = "probe-room")]
    scene: String,
    /// `auto`, `auto:TOL` or `auto:TOL:NX,NY,NZ` (see `kage render --probes`).
    #[arg(long, default_value = "auto")]
    probes: String,
    /// Texels per side of a probe's cube-map face, 8 to 256.
    #[arg(long, default_value_t = 32)]
    probe_cube_size: u32,
    /// What the probes capture besides the sky they see.
    #[arg(long, value_enum, default_value_t = kage::techniques::probes::CapturedLight::SkyAndWalls)]
    probe_light: kage::techniques::probes::CapturedLight,
    /// Where to write `{"positions": [[x,y,z], ...]}`.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    gpu: crate::args::GpuArgs,
}

#[derive(Args)]
pub struct TetrahedralizeArgs {
    /// The probe set: `{"positions": [[x,y,z], ...]}`.
    #[arg(long = "in")]
    input: PathBuf,
    /// Where to write `{"tetrahedra": [[i,j,k,l], ...]}`.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args)]
pub struct LookupArgs {
    /// The probe set: `{"positions": [[x,y,z], ...]}`.
    #[arg(long = "in")]
    input: PathBuf,
    /// The point, as x,y,z.
    #[arg(long, value_parser = crate::args::parse_xyz::<f64>, allow_hyphen_values = true)]
    at: [f64; 3],
}

#[derive(Serialize)]
struct TetFile<'a> {
    tetrahedra: &'a [[u32; 4]],
}

pub fn run(command: &ProbesCommand) -> Result<()> {
    match command {
        ProbesCommand::Tetrahedralize(args) => tetrahedralize(args),
        ProbesCommand::Lookup(args) => lookup(args),
        ProbesCommand::Place(args) => place(args),
        ProbesCommand::CaptureImage(args) => capture_image::run(args),
    }
}

fn place(args: &PlaceArgs) -> Result<()> {
    let scene = crate::args::read_scene(&args.scene, false)?;
    let placement = crate::args::probe_placement(&args.probes, &scene)?;
    if !matches!(placement, ProbePlacement::Auto { .. }) {
        anyhow::bail!("--probes {}: expected auto, auto:TOL or auto:TOL:NX,NY,NZ", args.probes);
    }
    let ctx = args.gpu.context()?;
    let gpu = GpuScene::new(&ctx, &scene)?;
    let settings = ProbeSettings {
        placement,
        capture: CaptureSettings {
            cube_size: args.probe_cube_size,
            light: args.probe_light,
            ..Default::default()
        },
        ..Default::default()
    };
    let start = Instant::now();
    let set = crate::progress::with_bar(
        "placing probes: capturing the candidates, then dropping, fitting and moving them",
        "captures",
        |progress| ProbeSet::capture(&ctx, &scene, &gpu, &settings, progress),
    );
    let set = set?;
    let json = positions_file::to_json(set.mesh.positions());
    std::fs::write(&args.out, json).with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "{} of {} candidate probes kept in {:.1} s; written to {}",
        set.probe_count(),
        set.candidates,
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    args.gpu.finish(&ctx)
}

/// Reads and tetrahedralizes a probe file, warning about merged duplicates.
fn load(path: &Path) -> Result<TetMesh> {
    let positions = crate::args::read_positions(path)?;
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
