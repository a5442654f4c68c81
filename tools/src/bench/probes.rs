//! `kage bench probes`: tetrahedralization time of random probe sets and lookups per second.
use crate::bench::Pcg32;
use anyhow::{bail, Result};
use clap::Args;
use glam::DVec3;
use kage::techniques::probes::{TetMesh, Walker};
use std::time::Instant;

#[derive(Args)]
pub struct ProbesBenchArgs {
    /// Probe counts, uniformly random in the unit cube.
    #[arg(long, value_delimiter = ',', default_values_t = [1_000, 10_000, 100_000])]
    sizes: Vec<usize>,
    /// Lookups per measurement.
    #[arg(long, default_value_t = 200_000)]
    lookups: usize,
    /// Tetrahedralizations per size; the median time is reported.
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Probes on a cubic lattice over the unit cube instead (the cube of the nearest whole side
    /// to each size): every cell's corners are cospherical, so every in-sphere tie is broken by
    /// the symbolic perturbation.
    #[arg(long)]
    grid: bool,
}

pub fn run(args: &ProbesBenchArgs) -> Result<()> {
    if args.runs == 0 || args.lookups == 0 {
        bail!("--runs and --lookups must be at least 1");
    }
    println!(
        "{} probes in the unit cube; build: median of {} runs; {} lookups each: coherent (a point moving by a tenth of the probe spacing per lookup, one walker), cold (random points, each walk from tetrahedron 0)",
        if args.grid { "lattice" } else { "random" },
        args.runs,
        args.lookups
    );
    println!(
        "{:>8} {:>8} {:>10} {:>10} {:>13} {:>8} {:>13} {:>8}",
        "probes", "tets", "build ms", "µs/probe", "coh. M/s", "steps", "cold M/s", "steps"
    );
    for &size in &args.sizes {
        // Seeded by the size alone, so a set does not change with the other options.
        let mut rng = Pcg32(0xda3e_39cb_94b9_5bdb ^ size as u64);
        let points =
            if args.grid { lattice(size) } else { (0..size).map(|_| random_point(&mut rng)).collect() };
        let n = points.len();
        let mut times = Vec::new();
        let mut mesh = None;
        for _ in 0..args.runs {
            let start = Instant::now();
            mesh = Some(TetMesh::build(&points)?);
            times.push(start.elapsed().as_secs_f64());
        }
        let Some(mesh) = mesh else { bail!("no run") };
        times.sort_by(f64::total_cmp);
        let build = times[times.len() / 2];

        let step = 0.1 / (n as f64).cbrt();
        let path: Vec<DVec3> = (0..args.lookups)
            .map(|i| {
                let t = i as f64 * step / 0.3;
                DVec3::new(0.5 + 0.3 * t.cos(), 0.5 + 0.3 * t.sin(), 0.5 + 0.2 * (0.37 * t).sin())
            })
            .collect();
        let random: Vec<DVec3> = (0..args.lookups).map(|_| random_point(&mut rng)).collect();
        let mut walker = Walker::default();
        let coherent = time_lookups(&path, |p| walker.locate(&mesh, p))?;
        let cold = time_lookups(&random, |p| Walker::default().locate(&mesh, p))?;
        println!(
            "{n:>8} {:>8} {:>10.1} {:>10.2} {:>13.2} {:>8.2} {:>13.3} {:>8.1}",
            mesh.tets().len(),
            build * 1e3,
            build * 1e6 / n as f64,
            coherent.0 * 1e-6,
            coherent.1,
            cold.0 * 1e-6,
            cold.1
        );
    }
    Ok(())
}

fn random_point(rng: &mut Pcg32) -> DVec3 {
    DVec3::new(rng.next() as f64, rng.next() as f64, rng.next() as f64)
}

/// side³ points on a lattice over the unit cube, side the whole number nearest ∛size (at least 2).
fn lattice(size: usize) -> Vec<DVec3> {
    let side = ((size as f64).cbrt().round() as usize).max(2);
    let at = |i: usize| i as f64 / (side - 1) as f64;
    (0..side * side * side)
        .map(|i| DVec3::new(at(i % side), at(i / side % side), at(i / (side * side))))
        .collect()
}

/// Lookups per second and mean steps per lookup.
fn time_lookups(
    points: &[DVec3],
    mut locate: impl FnMut(DVec3) -> Result<kage::techniques::probes::Location, kage::error::ProbeError>,
) -> Result<(f64, f64)> {
    let start = Instant::now();
    let mut steps = 0u64;
    for &p in points {
        steps += locate(p)?.steps as u64;
    }
    let seconds = start.elapsed().as_secs_f64();
    Ok((points.len() as f64 / seconds, steps as f64 / points.len() as f64))
}
