//! `kage bench`: the benchmarks, one module each: `rays` (BVH build and traversal), `probes`
//! (tetrahedralization and lookup), `asm` (shadow-map techniques over a camera walkthrough),
//! `probe_count` (probe error against count) and `scale` (costs as the scene grows).
pub mod asm;
pub mod probe_count;
mod probe_score;
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
    ///
    /// kage bench rays [--scene S] [--rays N] [--runs R] [--export DIR]: BVH build time, node count
    /// and bytes; rays per second for coherent (camera) and incoherent (random from surface points)
    /// rays, and how many hit (closest hits: the sum of their distances), to compare layouts and
    /// tracers by; `--export` writes the triangles, both ray sets and the PRT precomputation's rays
    /// of every 16th vertex for `scripts/embree-rays.py` (Embree 4 on one thread, benchmark only:
    /// `pip install embreex numpy`; `bash scripts/embree-compare.sh` runs both and prints the
    /// ratios, BENCHMARKS.md "Ray casting")
    Rays(rays::RaysArgs),
    /// Tetrahedralization time of random probe sets, and lookups per second, coherent (a moving
    /// object) and cold (each from the first tetrahedron).
    ///
    /// kage bench probes [--sizes 1000,10000,100000] [--lookups N] [--runs R] [--grid]:
    /// tetrahedralization time of random probe sets in the unit cube (median of R runs) and lookups
    /// per second, coherent (a moving point, one walker) and cold (random points, each walk from
    /// tetrahedron 0), with the mean steps per lookup
    Probes(probes::ProbesBenchArgs),
    /// Shadow-map techniques over a scene's camera walkthrough: pixels shadowed unlike the
    /// ray-traced reference, GPU ms per pass and frame side by side, shadow memory, flicker
    /// while the camera moves slowly, frames to converge at rest.
    ///
    /// kage bench asm [--scene asm] [--only shadowmap:1024,...,asm:16,asm-id:16] [--frames N]
    /// [--rest R] [--slow S] [--slow-px P] [--converge-tolerance F] [--size N] [--cache DIR] --out
    /// DIR: shadow-map techniques side by side over the scene's camera walkthrough (N samples; at
    /// each keyframe the camera held R frames, then S frames leaving it slowly): per frame the
    /// fraction of pixels lit/shadowed unlike `kage reference --light local` (references cached on
    /// disk per camera and size), GPU ms per pass and frame (configurations interleaved in every
    /// frame; the ratio to the first configuration is the median of per-frame ratios), shadow
    /// memory (`Renderer::shadow_memory_bytes`), pixels flipping where the reference does not while
    /// the camera moves slowly, frames until the error stops falling at rest; writes
    /// `DIR/frames.csv`, `DIR/summary.csv` and `DIR/error-time.png`
    Asm(asm::AsmBenchArgs),
    /// Light probes' irradiance error against the ray-cast truth as the probe count grows: a
    /// grid with trilinear interpolation against automatic placement with tetrahedral.
    ///
    /// kage bench probe-count [--scene probe-room,atrium] [--grids 2,3,4,6,8,12] [--candidates
    /// LEVEL] [--tolerances ...] [--probe-light sky] [--test-region path|box] [--points N]
    /// [--normals N] [--spp N] [--probe-cube-size N] [--visibility rays,off] [--closed-room]
    /// [--target E] [--cache DIR]: interpolated
    /// irradiance against the ray-cast truth at points along the moving group's path (`box`:
    /// anywhere in the static groups' box, probes over the box only), for trilinear grids of
    /// growing size and automatic placement at falling tolerance (candidates: grid level LEVEL's
    /// probes, by default the finest grid's; each step measured: reduced, fitted, relocated), each
    /// with and without the visibility test (and against its closed room, with the leaked
    /// fraction), with the fewest probes each needs for a target error (BENCHMARKS.md)
    ProbeCount(probe_count::ProbeCountArgs),
    /// Costs as the scene grows: BVH build, PRT precomputation, device memory and frame time
    /// per technique at 1k to 1M triangles of one scene family, with their log-log slopes.
    ///
    /// kage bench scale [--triangles 1000,10000,100000,1000000] [--rays N] [--techniques
    /// unshadowed,sloan-self,...] [--size N] [--frames N] --out DIR: one scene family (the default
    /// scene with a generated bumpy sphere of N triangles in place of the teapot, and a spot light)
    /// at each size: BVH build ms and MB, PRT precomputation at `--rays` (default 256) per vertex
    /// with its rays per second and the share of its time outside ray traversal, per technique
    /// device memory and median frame ms (`--size`², default 256) while the object hops, the
    /// process's peak RSS; the log-log slope of each curve per interval; `DIR/scale.csv` and
    /// `DIR/scale.png`
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
