//! `kage`: the command-line front end of the Kage engine.
mod args;
mod bench;
mod chart;
mod compare;
mod env_cmd;
mod info;
mod outputs;
mod precompute;
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
    ///
    /// kage render [--scene NAME|FILE] [--width W] [--height H] [--frames N] [--warmup W] [--out
    /// FILE.png|FILE.exr] [--exposure E] [--timings FILE.json] [--trace FILE.json] [--validate]
    /// [--device NAME]: renders W warm-up frames (default 2: a pipeline's first frames include its
    /// shader compilation on lavapipe; the one-time SH projection runs in the first, so `--warmup
    /// 0` shows it), then N timed frames offscreen (default 512×512, `kage.png`), writes the last,
    /// prints the per-pass GPU time table (median, min, max), the median frame time (from the
    /// frame's first pass's start to its last pass's end on the device, the time between passes
    /// included but not the host's planning between `asm`'s two submissions, which its line
    /// gives) and the median wall-clock frame (the render call: the GPU's passes, the host's
    /// work and the waits); `--timings` writes the same as JSON: `{"device", "frames", "passes":
    /// [{"name", "median_ms", "min_ms", "max_ms", "frames"}], "frame_median_ms",
    /// "frame_wall_median_ms"}`; `--trace` writes every
    /// frame as a timeline in the Chrome trace event format (open it in Perfetto or
    /// chrome://tracing): one event per frame on a CPU track, one per pass and frame on a GPU track
    /// from the device's timestamps, both on the host's monotonic clock where the device reads its
    /// clock and the host's together (VK_EXT_calibrated_timestamps, which lavapipe has;
    /// `otherData.gpu_clock` says `calibrated` and gives the clocks' largest deviation), elsewhere
    /// each frame's passes placed from its CPU start (`uncalibrated`)
    ///
    /// kage render ... [--technique
    /// unshadowed|sloan-self|sloan-scene|tamura|tamura-paper|parallel-lights|shadowmap] [--env MAP]
    /// [--regions Q] [--penumbra fixed|adaptive] [--mask-size N] [--dominant-lights N]
    /// [--light-map-size N] [--shadow-map-size N] [--bands B] [--rays N] [--cache DIR] [--force]
    /// [--keyframe K] [--env-rotation DEG] [--animate | --time T]: the lighting technique (default
    /// `tamura`, Kage's soft shadows); `--env` replaces the scene's map; the PRT techniques take
    /// their transfer from the cache or compute it first (where the cache cannot be written, a
    /// read-only folder or a file in its place, the render warns and goes on uncached; `kage
    /// precompute` fails): `sloan-self` is Sloan's PRT shadowed by each group itself, `sloan-scene`
    /// by the whole scene at rest (the paper's baseline: shadows between groups baked into the
    /// vertices, left behind when a group moves), `tamura-paper` the Tamura technique as published
    /// (q regions, one box width per group pair from each region's solid angle), `tamura` Kage's
    /// (see "Soft shadows"): up to `--dominant-lights` (default 4, 0 to 8) small bright lights of
    /// the map lit per pixel with an exact cosine, their self-shadow from `--light-map-size`² depth
    /// maps (default 512, 16 to 4096), the box width from each source's energy spread,
    /// `--mask-size`² depth-aware masks (default 128); `--penumbra adaptive` widens Tamura's
    /// shadows per pixel with the distance to the occluder (the paper's `fixed` width is the
    /// default); `parallel-lights` is the paper's Fig. 3 baseline (q regions as directional lights
    /// with binary shadow maps); `shadowmap` lights the scene's point and spot lights with hard
    /// shadows from one conventional shadow map of `--shadow-map-size`² texels per light (alias
    /// `--shadowmap-size`, 16 to 8192; the baseline of adaptive shadow maps): perspective along a
    /// spot light's axis with its cone as field of view, along −Y with 122° for a point light
    /// (points outside that view are lit unshadowed), slope-scaled depth bias, the four texels
    /// around the point tested and their bilinear blend thresholded at ½, lit exactly as `kage
    /// reference --light local` (same falloff and BRDF; the environment lights nothing);
    /// `--animate` plays the scene's motion over `--frames`: its camera walkthrough (`asm`; scene
    /// files: `walkthrough`, a list of cameras) and its groups' keyframes, one pass of the longest
    /// (scene files: `keyframes`; the built-in `teapot`, `probe-room` and `atrium` carry one, a
    /// one-second loop in which the first group slides ±1 of its height across the floor, turns
    /// once and hops, touching the floor at 0 and 0.5 s); a scene without keyframes keeps its
    /// groups where they stand; `--time T` renders the instant T seconds into the groups' motion
    /// instead; `--env-rotation` turns the light about +Y
    ///
    /// kage render ... --technique probes [--probes grid:NX,NY,NZ|scene|FILE] [--probe-cube-size N]
    /// [--probe-light sky-and-walls|sky] [--probe-bounces 1|2] [--probe-samples N] [--probe-dering
    /// off|nonnegative|hanning:W|lanczos:W]: light probes (see "Probes"): captured when the
    /// renderer is built (the time is printed, and its split: the walls' radiance's GPU rays
    /// with their traversal's rate and the rest of their batches, the cube maps, the CPU's
    /// rays), on a grid over the static groups (default
    /// `grid:3,2,3`, cell centres, 2 to 64 a side), at the scene file's `probes` or at the
    /// positions of a probe file; cube faces of 8 to 256 texels (default 128); the moving groups
    /// (those with keyframes; without any, the first group, with a note) each take their irradiance
    /// from the probes at their own centre, leaving out the probes it cannot see through the
    /// static groups (`--probe-visibility off`: every probe of the cell weighs, light leaks
    /// through walls), the others are captured by the probes and lit as by `unshadowed`
    /// (`--probe-statics sloan`: Sloan's PRT)
    ///
    /// kage render ... --technique probes --probes auto[:TOL[:NX,NY,NZ]] [--probe-interpolation
    /// tetrahedral|trilinear] [--probe-statics unshadowed|sloan]: automatic placement (see
    /// "Probes"): candidates on a grid over the static groups (default 8 along the longest side),
    /// those inside solids or sealed in pockets of free space dropped, captured, the redundant
    /// ones dropped at relative tolerance TOL (default 0.05), the kept ones relocated to nearby
    /// candidates and their SH fitted to all the captures; `trilinear` interpolates a `grid:`
    /// placement cell by cell instead of by tetrahedra; `--probe-statics` lights the static
    /// groups unshadowed or by Sloan's PRT; prints how many probes were kept
    ///
    /// kage render ... --technique asm [--asm-budget-mb M] [--asm-time-ms T] [--asm-test bias|id]:
    /// adaptive shadow maps for the scene's one point or spot light (see "Adaptive shadow maps");
    /// prints the hierarchy's state after the last frame
    Render(render::RenderArgs),
    /// Print an environment map's 9 SH coefficients per channel (projected on the GPU).
    ///
    /// kage sh MAP [--irradiance x,y,z]: projects an equirectangular map (.exr, .hdr) on the GPU
    /// and prints its 9×3 SH coefficients, and the irradiance for a normal (each texel with its
    /// exact solid angle; a map of fewer than 512 rows with each texel split into cells up to 512
    /// rows, so that a constant map of any size, 2×1 included, gives π times its radiance within
    /// 10⁻⁴)
    Sh(sh_cmd::ShArgs),
    /// Environment-map utilities: synthetic sun maps.
    #[command(subcommand)]
    Env(env_cmd::EnvCommand),
    /// Print the device, driver, Vulkan version and each feature Kage uses.
    ///
    /// kage info: device, driver, Vulkan version, and each feature or extension Kage uses, present
    /// or not
    Info(args::GpuArgs),
    /// Precompute the PRT transfer of every vertex (cached; prints time and bytes).
    ///
    /// kage precompute [--scene S] [--bands B] [--rays N] [--visibility group|scene] [--cache DIR]
    /// [--force]: per-vertex PRT transfer (visibility against the vertex's own group, in its object
    /// space, albedo left out; `--visibility scene`: against the whole scene at rest,
    /// `sloan-scene`'s) computed on the GPU and cached in a versioned file (`$KAGE_CACHE_DIR`,
    /// `$XDG_CACHE_HOME/kage` or `~/.cache/kage`) named by a hash of what the transfer depends on
    /// (the geometry in its groups' space, the groups' transforms for `--visibility scene`, bands,
    /// rays), never by the scene's name, so scene files around the same geometry share it; a stale
    /// or mismatching file is detected, reported and rebuilt; prints the time, the rays per second
    /// and the split between ray traversal and everything else (the jobs timed again with tracing
    /// off)
    Precompute(precompute::PrecomputeArgs),
    /// Scene utilities.
    #[command(subcommand)]
    Scene(scene_cmd::SceneCommand),
    /// Ray-traced ground truth: Monte Carlo direct lighting with full visibility (an image,
    /// or irradiance at listed points).
    ///
    /// kage reference [--scene S] [--keyframe K] [--env MAP] [--width W --height H] --spp N [--seed
    /// N] --out FILE.exr|FILE.png [--exposure E] [--light env|local [--edges TIES.exr]]
    /// [--time-budget S] [--irradiance POINTS.json [--bounces 0|1|2] [--bounce-samples N]]: the
    /// ground truth: Monte Carlo direct lighting with full visibility (environment importance
    /// sampling + cosine sampling, MIS), same camera and pixel grid as `kage render`, progressive
    /// with a progress bar and the remaining noise; `--light local` renders point and spot lights
    /// with hard shadows (`--edges` also writes where each pixel's state changes when its primary
    /// ray moves by the rasterizer's sub-pixel precision: R, G the lowest and highest luminance, B
    /// the bits); `--irradiance` gives E(p, n) at listed points as JSON: environment and point/spot
    /// lights with shadows, plus, with `--bounces B`, light reflected off the surfaces up to B
    /// times (see "Probes")
    Reference(reference::ReferenceArgs),
    /// Error metrics of one EXR image against a reference, and a false-colour difference.
    ///
    /// kage compare A.exr B.exr [--diff OUT.png] [--shadow-mismatch] [--mismatch-image OUT.png]
    /// [--shadow-threshold T] [--edges TIES.exr] [--json] [--max-rel-rmse X] [--max-mismatch F]:
    /// linear radiance from two .exr files (a .png, tonemapped and clipped, is refused with a
    /// message that says so): RMSE, relative RMSE (RMSE / mean of B), mean absolute error, 99th
    /// percentile and maximum error over all pixels and RGB channels, and a false-colour difference
    /// image; `--shadow-mismatch` adds the fraction of pixels lit in one image and shadowed in the
    /// other (lit: luminance above T × B's brightest pixel, default 10⁻⁴), for a local-light render
    /// (`--technique shadowmap` or `asm`) against `kage reference --light local` of the same scene
    /// and size, leaving out the pixels where B shows no surface (its alpha 0: the sky a local
    /// reference leaves black), and `--mismatch-image` shows where (red: lit in A only, blue: lit
    /// in B only, black: no surface in B);
    /// `--edges` takes B's edge ties (`kage reference --light local --edges`: pixels where an edge
    /// passes closer to the centre than the device's sub-pixel precision, 1/256 px on lavapipe, so
    /// that no raster render can be told right or wrong there) and counts them apart (yellow in the
    /// image); for CI, `--json` prints the metrics as one JSON object on stdout, and
    /// `--max-rel-rmse X` / `--max-mismatch F` make the exit status 3 when the relative RMSE or the
    /// mismatch fraction exceeds them (0 within, 1 on an error)
    Compare(compare::CompareArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// A technique's settings side by side: error against the reference at several poses, GPU
    /// time per frame, precomputation time and memory, written to DIR/sweep.csv.
    ///
    /// kage sweep --technique asm [--scene asm] [--only shadowmap:2048,asm:8,...] [--frames N]
    /// [--size N] [--pick --max-error E --max-ms T] --out DIR: `kage bench asm`'s measurement over
    /// the walkthrough (default: shadowmap 1024, 2048, 4096 and asm 4, 8, 16 MB) as `DIR/sweep.csv`
    /// (mismatch mean, max and at rest, flips, median frame ms, ratio to the first, shadow memory)
    /// and `DIR/pareto.png`; `--pick` as below, the error being the mismatch fraction
    ///
    /// kage sweep --technique probes [--scene probe-room|atrium] [--spp N] [--test-region path|box]
    /// [--pick --max-error E --max-probes N] --out DIR: `kage bench probe-count`'s measurement
    /// (grids of 2–10 along the longest side, trilinear and tetrahedral; automatic placement at
    /// tolerances 0.5–0.025, with captured values, fitted, and relocated then fitted as the engine
    /// runs it; 256 positions × 4 normals; in the building's box and on the moving object's path)
    /// as `DIR/sweep.csv` (probes, relative RMS error, capture seconds, SH memory) and
    /// `DIR/pareto.png` with probes on x: the probe count is this technique's cost; `--pick` gives
    /// the fewest probes within `--max-error` and the most accurate within `--max-probes`
    ///
    /// kage sweep --technique prt [--scene S] [--env MAP]... [--poses 0,0.125,0.6] [--only
    /// unshadowed,sloan-self:3,tamura:32,...] [--size N] [--noise F] [--max-spp N] [--frames N]
    /// [--time-size N] [--rays N] [--cache DIR] [--pick --max-error E --max-ms T] --out DIR: every
    /// setting of a technique side by side in one run (unshadowed; sloan-self at 2–5 bands;
    /// sloan-scene; tamura-paper at q = 32; tamura at q = 4–64; parallel-lights at q = 32, 64,
    /// 128): relative RMSE against `kage reference` at each of `--poses`, times in the scene's
    /// motion (seconds of its groups' keyframes) (`--size`²; each reference run until its relative
    /// standard error is at most `--noise`, default 0.005, within `--max-spp`, cached under the
    /// cache folder's `references/`, its noise printed and written beside every error), median GPU
    /// ms per frame over `--frames` animated frames (`--time-size`²), precomputation seconds and
    /// device memory; writes `DIR/sweep.csv` and `DIR/pareto.png` (GPU ms against error, log
    /// scales, one series per technique, the Pareto front drawn; with several `--env`, one
    /// `pareto-MAP.png` per further map) and prints each setting's error and frame time over
    /// parallel lights' at the same q (q = 32 for the settings without regions), saying so where
    /// the references' noise is within 2× of the difference (too close to rank); `--pick` answers
    /// with the cheapest setting within `--max-error` and the most accurate within `--max-ms`
    Sweep(sweep::SweepArgs),
    /// Light probes: tetrahedralize a probe set, look a point up in it, capture one from an
    /// image, place probes in a scene automatically.
    #[command(subcommand)]
    Probes(probes::ProbesCommand),
    /// Print the reference of every command and flag as Markdown (docs/cli.md is its output).
    #[command(hide = true)]
    CliReference,
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
        Command::CliReference => {
            let options =
                clap_markdown::MarkdownOptions::new().show_footer(false).show_table_of_contents(true);
            print!("{}", clap_markdown::help_markdown_custom::<Cli>(&options));
            Ok(())
        }
    };
    if let Err(e) = result {
        // Arguments and file contents quoted in the message are clipped to a readable length.
        eprintln!("kage: error: {}", kage::scene::clip_message(&format!("{e:#}")));
        std::process::exit(1);
    }
}
