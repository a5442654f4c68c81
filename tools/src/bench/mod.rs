//! `kage bench`: the benchmarks, one module each: `rays` (BVH build and traversal), `probes`
//! (tetrahedralization and lookup), `asm` (shadow-map techniques over a camera walkthrough),
//! `probe_count` (probe error against count) and `scale` (costs as the scene grows).
pub mod asm;
pub mod probe_count;
pub mod probes;
pub mod rays;
mod rng;
pub mod scale;

use anyhow::Result;
use clap::Subcommand;
pub use rng::Pcg32;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// BVH build time and size, and rays per second for coherent (camera) and incoherent
    /// (random directions from random surface points) rays, closest hit and any hit.
    Rays(rays::RaysArgs),
    /// Tetrahedralization time of random probe sets, and lookups per second, coherent (a moving
    /// object) and cold (each from the first tetrahedron).
    Probes(probes::ProbesBenchArgs),
    /// Shadow-map techniques over a scene's camera walkthrough: pixels shadowed unlike the
    /// ray-traced reference, GPU ms per pass and frame side by side, shadow memory, flicker
    /// while the camera moves slowly, frames to converge at rest.
    Asm(asm::AsmBenchArgs),
    /// Light probes' irradiance error against the ray-cast truth as the probe count grows: a
    /// grid with trilinear interpolation against automatic placement with tetrahedral.
    ProbeCount(probe_count::ProbeCountArgs),
    /// Costs as the scene grows: BVH build, PRT precomputation, device memory and frame time
    /// per technique at 1k to 1M triangles of one scene family, with their log-log slopes.
    Scale(scale::ScaleArgs),
}

pub fn run(command: &BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Rays(args) => rays::run(args),
        BenchCommand::Probes(args) => probes::run(args),
        BenchCommand::Asm(args) => asm::run(args),
        BenchCommand::ProbeCount(args) => probe_count::run(args),
        BenchCommand::Scale(args) => scale::run(args),
    }
}
