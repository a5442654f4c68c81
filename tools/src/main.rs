//! `kage`: the command-line front end of the Kage engine.
mod args;
mod bench;
mod chart;
mod compare;
mod env_cmd;
mod info;
mod outputs;
mod precompute;
mod probe_image;
mod probes;
mod progress;
mod reference;
mod render;
mod scene_cmd;
mod sh_cmd;
mod sweep;
mod trace;
mod transfer_source;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "kage", version, about = "Kage (影): real-time lighting on raw Vulkan")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene offscreen to PNG (tonemapped, sRGB) or EXR (linear radiance).
    Render(render::RenderArgs),
    /// Print an environment map's 9 SH coefficients per channel (projected on the GPU).
    Sh(sh_cmd::ShArgs),
    /// Environment-map utilities: synthetic sun maps.
    #[command(subcommand)]
    Env(env_cmd::EnvCommand),
    /// Print the device, driver, Vulkan version and each feature Kage uses.
    Info(args::GpuArgs),
    /// Precompute the PRT transfer of every vertex (cached; prints time and bytes).
    Precompute(precompute::PrecomputeArgs),
    /// Scene utilities.
    #[command(subcommand)]
    Scene(scene_cmd::SceneCommand),
    /// Ray-traced ground truth: Monte Carlo direct lighting with full visibility (an image,
    /// or irradiance at listed points).
    Reference(reference::ReferenceArgs),
    /// Error metrics of one EXR image against a reference, and a false-colour difference.
    Compare(compare::CompareArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// A technique's settings side by side: error against the reference at several poses, GPU
    /// time per frame, precomputation time and memory, written to DIR/sweep.csv.
    Sweep(sweep::SweepArgs),
    /// Light probes: tetrahedralize a probe set, look a point up in it, capture one from an
    /// image, place probes in a scene automatically.
    #[command(subcommand)]
    Probes(probes::ProbesCommand),
}

fn main() {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`kage render | head -1`) would
    // panic; the default disposition ends the process quietly, as other command-line tools do.
    // SAFETY: no other thread exists yet, and SIG_DFL is a valid disposition for SIGPIPE.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL)
    };
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Sh(args) => sh_cmd::run(&args),
        Command::Env(command) => env_cmd::run(&command),
        Command::Info(args) => info::run(&args),
        Command::Precompute(args) => precompute::run(&args),
        Command::Scene(command) => scene_cmd::run(&command),
        Command::Reference(args) => reference::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Bench(command) => bench::run(&command),
        Command::Sweep(args) => sweep::run(&args),
        Command::Probes(command) => probes::run(&command),
    };
    if let Err(e) = result {
        // Arguments and file contents quoted in the message are clipped to a readable length.
        eprintln!("kage: error: {}", kage::scene::clip_message(&format!("{e:#}")));
        std::process::exit(1);
    }
}
