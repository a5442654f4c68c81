//! `kage bench probe-count`: the error of probe-interpolated irradiance against the ray-cast
//! ground truth, as the probe count grows, for a regular grid with trilinear interpolation and
//! for automatic placement with tetrahedral interpolation (Morishige 2014).
//!
//! Test points: random points in the moving group's bounding box at random times of its
//! motion (`--animate`: its keyframes; the first of the moving groups, see `ProbeGroups`), those
//! inside a solid dropped, each with random normals. Truth: the reference's irradiance E(p, n)
//! (every moving group moved far away, as the probes leave them out), cached. Error: the RMS of |E_probes − E| over points, normals and channels
//! divided by the RMS of E (a relative error that dark normals cannot blow up).
//!
//! Each set is scored with the visibility test and without (`--visibility`, [`probe_score`]),
//! and with `--closed-room` against its closed room, with its leaked fraction.
//!
//! Captures are shared: the grid levels are captured once each, and automatic placement's
//! candidates are one level's probes outside solids (`--candidates`, by default the finest
//! grid's), placed at each tolerance on the host. Automatic placement is measured step by step:
//! the reduction's probes with their own captures; the same probes with their SH fitted to
//! every candidate's; and, as the engine runs it, relocated before the fit. Each grid is also
//! measured fitted to the same candidates, to tell the fit's gain from the placement's.
use crate::args::GpuArgs;
use crate::bench::probe_score::{squared_error, Frames, LookupCost, Score, Scorer, NORMALS};
use crate::bench::Pcg32;
use anyhow::{bail, Context as _, Result};
use clap::Args;
use glam::{DVec3, Vec3};
use kage::backend::Context;
use kage::files;
use kage::frame::GpuScene;
use kage::reference::irradiance::{IrradianceFile, Point};
use kage::reference::IrradianceReference;
use kage::scene::Scene;
use kage::sh::ShRgb9;
use kage::techniques::probes::{
    bounds, capture_at, grid_lattice, open_to_probes, reduce, CaptureSettings, Lattice, Occluders,
    ProbeGroups, ProbeSet, ProbeVisibility, Solids, MAX_GRID,
};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Grid levels and placement tolerances measured unless told (`kage sweep --technique probes`
/// measures these too).
pub const DEFAULT_GRIDS: [u32; 6] = [2, 3, 4, 6, 8, 10];
pub const DEFAULT_TOLERANCES: [f32; 6] = [0.5, 0.35, 0.25, 0.1, 0.05, 0.025];

#[derive(Args)]
pub struct ProbeCountArgs {
    /// Built-in scene names or scene files, each with a moving group (a group with keyframes;
    /// the test points follow the first of them; `--scenes` is the old name).
    #[arg(long = "scene", alias = "scenes", value_delimiter = ',', default_values_t = ["probe-room".to_string(), "atrium".to_string()])]
    scenes: Vec<String>,
    /// Grid levels: probes along the static box's longest side (the others in proportion, at
    /// least 2). The finest level's probes outside solids are automatic placement's candidates.
    #[arg(long, value_delimiter = ',', default_values_t = DEFAULT_GRIDS)]
    grids: Vec<u32>,
    /// Automatic placement's candidates: the probes of this grid level outside solids. Default:
    /// the finest of `--grids`, which then compares placement with a grid of its own candidates.
    #[arg(long)]
    candidates: Option<u32>,
    /// Tolerances of automatic placement (relative irradiance error at the candidates).
    #[arg(long, value_delimiter = ',', default_values_t = DEFAULT_TOLERANCES)]
    tolerances: Vec<f32>,
    /// Test positions (before those inside solids are dropped).
    #[arg(long, default_value_t = 64)]
    points: usize,
    /// Random normals per test position.
    #[arg(long, default_value_t = 6)]
    normals: usize,
    /// Where the test points are: `path`, in the moving group's box along its motion (grids
    /// and placement over the static box and over the path); `box`, anywhere in the static
    /// groups' box outside solids (grids and placement over the box only: the paper's
    /// setting, a grid over the whole scene against probes kept where the light needs them).
    #[arg(long, value_enum, default_value_t = TestRegion::Path)]
    test_region: TestRegion,
    /// Reference samples per point.
    #[arg(long, default_value_t = 8192)]
    spp: u32,
    /// Texels per side of a probe's cube-map face (as `kage render --probe-cube-size`;
    /// `--cube-size` is the old name).
    #[arg(long = "probe-cube-size", alias = "cube-size", default_value_t = 32)]
    cube_size: u32,
    /// The light the probes capture: `sky` is what the reference integrates today (the
    /// environment with visibility, no bounce); rerun with the reference's transport when it
    /// changes.
    #[arg(long, value_enum, default_value_t = kage::techniques::probes::CapturedLight::Sky)]
    probe_light: kage::techniques::probes::CapturedLight,
    /// Lookups measured: `rays` leaves out the probes a test point cannot see through the
    /// static groups (as `kage render` does by default), `off` weighs every probe of the cell
    /// (methods named "..., no visibility").
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [ProbeVisibility::Rays, ProbeVisibility::Off])]
    visibility: Vec<ProbeVisibility>,
    /// Also measure each set's closed room (its probes that the path's centre sees, alone: in
    /// a convex room, the room's own) and the leaked fraction (the share of the interpolated
    /// irradiance from the probes the path's centre does not see).
    #[arg(long)]
    closed_room: bool,
    /// Also follow the moving group's centre over this many frames of its motion and report
    /// each set's largest frame-to-frame irradiance jump (6 axis normals), against the
    /// reference's and a probe captured at each frame's point (0: not measured).
    #[arg(long, default_value_t = 0)]
    path_frames: usize,
    /// The relative error a method must reach; default: each grid level's own error.
    #[arg(long)]
    target: Option<f64>,
    /// Where reference irradiance is cached.
    #[arg(long, default_value = "target/probe-count")]
    cache: PathBuf,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// One measurement of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub method: String,
    pub setting: Setting,
    pub probes: usize,
    pub error: f64,
    /// The leaked fraction (with `--closed-room`).
    pub leaked: Option<f64>,
    /// The largest frame-to-frame jump (with `--path-frames`).
    pub jump: Option<f64>,
}

impl Row {
    fn new(method: String, setting: Setting, probes: usize, score: Score) -> Row {
        Row { method, setting, probes, error: score.error, leaked: score.leaked, jump: score.jump }
    }
}

/// The largest frame-to-frame jumps along the moving group's path that the sets' are measured
/// against (relative to the RMS of the truth there).
#[derive(Clone, Copy, Debug)]
pub struct FrameJumps {
    pub frames: usize,
    /// The reference's, noise included.
    pub reference: f64,
    /// The RMS jump the reference's noise alone makes: √2 σ.
    pub reference_noise: f64,
    /// A probe captured at each frame's point: the light as the probes capture it, no noise.
    pub captured: f64,
}

/// What a row's method was given: a grid's counts, or automatic placement's tolerance (or all
/// its candidates kept).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    Grid([u32; 3]),
    Tolerance(f32),
    AllCandidates,
}

impl Setting {
    /// The parameter's name and value, as the sweep's CSV columns.
    pub fn parameter(self) -> (&'static str, String) {
        match self {
            Setting::Grid(c) => ("grid", format!("{}x{}x{}", c[0], c[1], c[2])),
            Setting::Tolerance(t) => ("tolerance", t.to_string()),
            Setting::AllCandidates => ("tolerance", "0".into()),
        }
    }
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = match self {
            Setting::Grid(_) => self.parameter().1,
            Setting::Tolerance(t) => format!("tol {t}"),
            Setting::AllCandidates => "all cand.".into(),
        };
        f.pad(&text)
    }
}

pub struct Measurement {
    pub rows: Vec<Row>,
    /// The box the moving group sweeps, within the static box.
    pub path: (Vec3, Vec3),
    pub test_points: usize,
    /// RMS standard error of the reference relative to the RMS of E: the noise floor.
    pub reference_noise: f64,
    /// The error of a probe captured at each test point: the floor of any interpolation.
    pub capture_floor: f64,
    pub capture_ms_per_probe: f64,
    pub reference_seconds: f64,
    /// Lookups without and with the visibility test.
    pub lookups_off: LookupCost,
    pub lookups_rays: LookupCost,
    pub jumps: Option<FrameJumps>,
}

pub struct Params<'a> {
    pub test_region: TestRegion,
    pub grids: &'a [u32],
    /// The grid level whose probes are automatic placement's candidates; `None`: the finest.
    pub candidates: Option<u32>,
    pub tolerances: &'a [f32],
    pub points: usize,
    pub normals: usize,
    pub spp: u32,
    pub capture: CaptureSettings,
    pub cache: Option<&'a Path>,
    /// Each set is measured with each of these lookups.
    pub visibility: &'a [ProbeVisibility],
    pub closed_room: bool,
    /// Frames of the moving group's motion whose jumps are measured; 0: none.
    pub path_frames: usize,
}

pub fn run(args: &ProbeCountArgs) -> Result<()> {
    let ctx = args.gpu.context()?;
    let params = Params {
        test_region: args.test_region,
        grids: &args.grids,
        candidates: args.candidates,
        tolerances: &args.tolerances,
        points: args.points,
        normals: args.normals,
        spp: args.spp,
        capture: CaptureSettings { cube_size: args.cube_size, light: args.probe_light, ..Default::default() },
        cache: Some(&args.cache),
        visibility: &args.visibility,
        closed_room: args.closed_room,
        path_frames: args.path_frames,
    };
    println!(
        "probe count against error: {} test positions x {} normals ({}), reference {} spp, cube faces {}², capture {:?}, {}",
        args.points, args.normals, args.test_region.describe(), args.spp, args.cube_size, params.capture.light, ctx.info().name
    );
    for name in &args.scenes {
        let scene = crate::args::read_scene(name, false)?;
        let m = measure(&ctx, &scene, &params).with_context(|| format!("scene {name}"))?;
        println!(
            "\nscene {}: {} test points; reference noise {:.4}, capture-at-the-point floor {:.4}; reference {:.1} s; capture {:.1} ms per probe",
            scene.name,
            m.test_points,
            m.reference_noise,
            m.capture_floor,
            m.reference_seconds,
            m.capture_ms_per_probe
        );
        if let Some(j) = m.jumps {
            println!(
                "largest frame-to-frame jump over {} frames: reference {:.4} (its noise alone: {:.4} RMS), a probe captured at each frame's point {:.4}",
                j.frames, j.reference, j.reference_noise, j.captured
            );
        }
        for (name, cost) in [("without visibility", m.lookups_off), ("with visibility", m.lookups_rays)] {
            let c = cost.counts;
            if c.lookups > 0 {
                println!(
                    "lookups {name}: {:.2} µs each; of {}, {} renormalised, {} the nearest probe seen, {} unweighted (no probe seen)",
                    cost.micros(), c.lookups, c.renormalised, c.nearest, c.unweighted
                );
            }
        }
        println!(
            "path region {:.2?} to {:.2?}\n{:<52} {:>12} {:>8} {:>10} {:>8} {:>8}",
            m.path.0, m.path.1, "method", "setting", "probes", "rel. RMS", "leaked", "jump"
        );
        for row in &m.rows {
            let leaked = row.leaked.map_or(String::new(), |l| format!("{:.2} %", 100.0 * l));
            let jump = row.jump.map_or(String::new(), |j| format!("{j:.4}"));
            println!(
                "{:<52} {:>12} {:>8} {:>10.4} {leaked:>8} {jump:>8}",
                row.method, row.setting, row.probes, row.error
            );
        }
        print_power_laws(&m.rows);
        // Like for like (each region's grid against automatic placement in it), and the
        // paper's comparison: a grid over the whole box against probes where objects move.
        // Then what the fit adds: placement with captured values against the grid, and the
        // fitted grid against fitted placement.
        let comparisons: &[_] = match args.test_region {
            TestRegion::Path => &[
                (TRILINEAR, AUTO, Region::Box, Region::Box),
                (TRILINEAR, AUTO, Region::Path, Region::Path),
                (TRILINEAR, AUTO, Region::Box, Region::Path),
                (TRILINEAR, AUTO_CAPTURED, Region::Path, Region::Path),
                (TRILINEAR, AUTO_UNMOVED, Region::Path, Region::Path),
                (GRID_FITTED, AUTO, Region::Path, Region::Path),
            ],
            TestRegion::Box => &[
                (TRILINEAR, AUTO, Region::Box, Region::Box),
                (TRILINEAR, AUTO_CAPTURED, Region::Box, Region::Box),
                (TRILINEAR, AUTO_UNMOVED, Region::Box, Region::Box),
                (GRID_FITTED, AUTO, Region::Box, Region::Box),
            ],
        };
        for &(grid, tetra, region, tetra_region) in comparisons {
            compare(&m.rows, &method(grid, region), &method(tetra, tetra_region), args.target);
        }
    }
    args.gpu.finish(&ctx)
}

/// Each method's power law `error ≈ a·n^b` over its sets (n probes), fitted by least squares
/// in log–log, and the sets' scatter about it (the RMS of the log residuals). Placement's sets
/// move by more than the differences runs are compared for when a few candidates change
/// (BENCHMARKS.md), so two runs are compared by their curves as well as set by set.
fn print_power_laws(rows: &[Row]) {
    const AT: [f64; 4] = [4.0, 16.0, 64.0, 256.0];
    println!(
        "power laws (error ≈ a·n^b over each method's sets, all candidates apart; scatter: RMS of the log residuals):\n{:<52} {:>7} {:>7} {:>8}   error at n = {AT:?}",
        "method", "a", "b", "scatter"
    );
    let mut methods: Vec<&str> = Vec::new();
    for row in rows {
        if !methods.contains(&row.method.as_str()) {
            methods.push(&row.method);
        }
    }
    for method in methods {
        let logs: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.method == method && r.setting != Setting::AllCandidates && r.error > 0.0)
            .map(|r| ((r.probes as f64).ln(), r.error.ln()))
            .collect();
        let Some((a, b, scatter)) = power_law(&logs) else { continue };
        let at: Vec<String> = AT.iter().map(|n| format!("{:.4}", a * n.powf(b))).collect();
        println!("{method:<52} {a:>7.4} {b:>7.4} {:>7.1} %   {}", 100.0 * scatter, at.join(", "));
    }
}

/// The least-squares line through `(ln n, ln error)` as `(a, b, scatter)`: `error ≈ a·n^b`;
/// `None` for fewer than three sets or one probe count only.
fn power_law(logs: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    let k = logs.len() as f64;
    let (mx, my) = logs.iter().fold((0.0, 0.0), |(x, y), p| (x + p.0 / k, y + p.1 / k));
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if logs.len() < 3 || sxx <= 0.0 {
        return None;
    }
    let b = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let ln_a = my - b * mx;
    let residual: f64 = logs.iter().map(|p| (p.1 - ln_a - b * p.0).powi(2)).sum();
    Some((ln_a.exp(), b, (residual / k).sqrt()))
}

/// For each target error (`target`, or each of `grid`'s errors), the fewest probes with which
/// `grid` and `tetra` reach it, their ratio, and whether the bar is met.
fn compare(rows: &[Row], grid: &str, tetra: &str, target: Option<f64>) {
    let targets: Vec<f64> = match target {
        Some(t) => vec![t],
        None => rows.iter().filter(|r| r.method == grid).map(|r| r.error).collect(),
    };
    println!("{grid} against {tetra}:");
    println!("{:>10} {:>14} {:>14} {:>8}", "target", "grid probes", "tetra probes", "ratio");
    let mut ratios = Vec::new();
    for target in targets {
        let fewest = |method: &str| {
            rows.iter().filter(|r| r.method == method && r.error <= target).map(|r| r.probes).min()
        };
        let (g, t) = (fewest(grid), fewest(tetra));
        let show = |n: Option<usize>| n.map_or("not reached".to_string(), |n| n.to_string());
        let ratio = g.zip(t).map(|(g, t)| t as f64 / g as f64);
        let shown = ratio.map_or("-".to_string(), |r| format!("{r:.2}"));
        println!("{target:>10.4} {:>14} {:>14} {shown:>8}", show(g), show(t));
        ratios.push(ratio);
    }
    let reached: Vec<f64> = ratios.iter().flatten().copied().collect();
    let worst = reached.iter().copied().fold(0.0, f64::max);
    println!(
        "bar (tetrahedral reaches the grid's error with at most 30 % of its probes): met at {} of {} targets (largest ratio {worst:.2}); {} not reached by the tetrahedral sets",
        reached.iter().filter(|&&r| r <= 0.3).count(),
        ratios.len(),
        ratios.len() - reached.len()
    );
}

/// `name` measured with `visibility`: the engine's default, with visibility, keeps the plain
/// name.
fn named(name: &str, visibility: ProbeVisibility) -> String {
    match visibility {
        ProbeVisibility::Rays => name.to_string(),
        ProbeVisibility::Off => format!("{name}, no visibility"),
    }
}

/// `name`'s closed room (see [`probe_score`](super::probe_score)).
fn closed(name: &str) -> String {
    format!("{name}, closed room")
}

const TRILINEAR: &str = "grid, trilinear";
const GRID_TETRA: &str = "grid, tetrahedral";
const GRID_FITTED: &str = "grid, trilinear, fitted";
/// Automatic placement as the engine does it: the reduction's probes relocated, their SH fitted
/// to every candidate.
const AUTO: &str = "auto, tetrahedral";
/// The reduction's probes with their own captures, and fitted without the relocation.
const AUTO_CAPTURED: &str = "auto, tetrahedral, captured";
const AUTO_UNMOVED: &str = "auto, tetrahedral, not relocated";

/// Where probes go: the static groups' box (as `kage render --probes grid:` and `auto` place
/// them), or the part of it that the moving group sweeps (where the test points are).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    Box,
    Path,
}

/// Where the test points are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TestRegion {
    /// In the moving group's box at random times of its motion: where probe lighting is used.
    Path,
    /// Anywhere in the static groups' box: where any moving object could go.
    Box,
}

impl TestRegion {
    pub fn describe(self) -> &'static str {
        match self {
            TestRegion::Path => "along the moving group's path",
            TestRegion::Box => "anywhere in the static box",
        }
    }

    /// The probe regions measured against these test points: probes confined to the path
    /// would extrapolate over the rest of the box.
    fn probe_regions(self) -> &'static [Region] {
        match self {
            TestRegion::Path => &[Region::Box, Region::Path],
            TestRegion::Box => &[Region::Box],
        }
    }
}

/// A method's name in `region`.
pub fn method(name: &str, region: Region) -> String {
    format!("{name} ({})", if region == Region::Box { "box" } else { "path" })
}

/// The counts of grid `level` over a box of `extent`: `level` along its longest side, the
/// others in proportion, at least 2.
fn grid_counts(extent: Vec3, level: u32) -> [u32; 3] {
    let along = |e: f32| ((level as f32 * e / extent.max_element()).round() as u32).clamp(2, MAX_GRID);
    extent.to_array().map(along)
}

/// The bounds of the moving group's box over 64 times of its motion, within the static box.
fn path_bounds(group: &kage::scene::Group, static_box: (Vec3, Vec3)) -> Option<(Vec3, Vec3)> {
    let corners = group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
    let (lo, hi) = bounds(corners)?;
    let swept = (0..64).flat_map(|s| {
        let m = group.pose_at(s as f32 / 64.0).matrix();
        (0..8).map(move |c| {
            let corner = Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            );
            m.transform_point3(corner)
        })
    });
    let (plo, phi) = bounds(swept)?;
    Some((plo.max(static_box.0), phi.min(static_box.1)))
}

pub fn measure(ctx: &Arc<Context>, scene: &Scene, params: &Params) -> Result<Measurement> {
    let Some(&finest) = params.grids.iter().max() else { bail!("--grids: give at least one level") };
    if params.points == 0 || params.normals == 0 {
        bail!("--points and --normals must be at least 1");
    }
    if let Some(level) = params.grids.iter().chain(&params.candidates).find(|l| !(2..=MAX_GRID).contains(*l))
    {
        bail!("grid level {level} (--grids, --candidates): each must be 2 to {MAX_GRID} probes along the longest side");
    }
    let solids = Solids::of_static(scene);
    let unit = grid_lattice(scene, [1; 3])?;
    let static_box = ((unit.first - 0.5 * unit.step).as_vec3(), (unit.first + 0.5 * unit.step).as_vec3());
    let points = test_points(scene, &solids, params, static_box)?;
    let region = format!("{:?}", params.test_region).to_lowercase();
    let (truth, noise, reference_seconds) = reference(ctx, scene, &points, params, &region)?;

    // The probes leave the moving groups out of their captures; they stay where they are.
    let gpu = GpuScene::new(ctx, scene)?;
    let path = path_bounds(&scene.groups[moving_group(scene)?], static_box)
        .filter(|(lo, hi)| (*hi - *lo).min_element() > 0.0)
        .context("the moving group's path has no volume inside the static box")?;
    let occluders = Arc::new(Occluders::of_static(scene)?);
    let room = params.closed_room.then(|| ((path.0 + path.1) * 0.5).as_dvec3());
    let frame_points = match params.path_frames {
        0 => Vec::new(),
        frames => frame_points(scene, frames)?,
    };
    let (frame_truth, frame_noise, _) = match params.path_frames {
        0 => (Vec::new(), 0.0, 0.0),
        _ => reference(ctx, scene, &frame_points, params, "frames")?,
    };
    let frames = (params.path_frames > 0).then_some(Frames { points: &frame_points, truth: &frame_truth });
    let mut scorer = Scorer::new(&points, &truth, &occluders, room, frames);
    let rms_truth = scorer.rms_truth();
    // Each set scored with each visibility, then its closed room (that of the set built for
    // visibility). `build` makes the set, given the occluders its fit and relocation see; a set
    // that neither fits nor relocates (`fits` false) is built once, without.
    let mut record = |rows: &mut Vec<Row>,
                      name: &str,
                      (region, setting): (Region, Setting),
                      fits: bool,
                      build: &dyn Fn(Option<Arc<Occluders>>) -> Result<ProbeSet>| {
        let once = if fits { None } else { Some(build(None)?) };
        let mut room_set = None;
        for &visibility in params.visibility {
            let built = match &once {
                Some(_) => None,
                None => Some(build((visibility == ProbeVisibility::Rays).then(|| occluders.clone()))?),
            };
            let set = once.as_ref().or(built.as_ref()).expect("built once or now");
            let score = scorer.score(set, visibility)?;
            rows.push(Row::new(method(&named(name, visibility), region), setting, set.probe_count(), score));
            if room_set.is_none() || visibility == ProbeVisibility::Rays {
                room_set = built;
            }
        }
        if let Some(room) = once.or(room_set).and_then(|set| scorer.closed_room(&set)) {
            let score = scorer.score(&room, ProbeVisibility::Off)?;
            rows.push(Row::new(method(&closed(name), region), setting, room.probe_count(), score));
        }
        anyhow::Ok(())
    };

    let mut rows = Vec::new();
    let mut captured = 0usize;
    let start = Instant::now();
    for &region in params.test_region.probe_regions() {
        let (lo, hi) = if region == Region::Box { static_box } else { path };
        // Each level's trilinear set with the counts and captures it was built from.
        let mut levels = Vec::new();
        for &level in params.grids {
            let counts = grid_counts(hi - lo, level);
            let lattice = Lattice::cell_centres(lo, hi, counts);
            let sh = capture_at(ctx, scene, &gpu, params.capture, &lattice.positions())?;
            captured += sh.len();
            let at = (region, Setting::Grid(counts));
            record(&mut rows, TRILINEAR, at, false, &|_| Ok(ProbeSet::trilinear(lattice, sh.clone())?))?;
            record(&mut rows, GRID_TETRA, at, false, &|_| {
                Ok(ProbeSet::tetrahedral(&lattice.positions(), sh.clone())?)
            })?;
            levels.push((level, lattice, sh));
        }
        // The candidates: a measured level's captures, or their own.
        let level = params.candidates.unwrap_or(finest);
        let lattice = Lattice::cell_centres(lo, hi, grid_counts(hi - lo, level));
        let sh = match levels.iter().find(|(l, ..)| *l == level) {
            Some((.., sh)) => sh.clone(),
            None => {
                let sh = capture_at(ctx, scene, &gpu, params.capture, &lattice.positions())?;
                captured += sh.len();
                sh
            }
        };
        let (positions, sh): (Vec<DVec3>, Vec<ShRgb9>) = lattice
            .positions()
            .into_iter()
            .zip(sh)
            .filter(|(p, _)| open_to_probes(&solids, &occluders, *p))
            .unzip();
        // Each grid fitted to the same captures as automatic placement: how much of its gain
        // is the fit and how much the placement.
        let (positions, sh) = (&positions, &sh);
        for (_, lattice, own) in levels {
            let fitted = |seen: Option<Arc<Occluders>>| {
                Ok(ProbeSet::trilinear(lattice, own.clone())?.seeing(seen).fitted(positions, sh)?)
            };
            record(&mut rows, GRID_FITTED, (region, Setting::Grid(lattice.counts)), true, &fitted)?;
        }
        for &tolerance in params.tolerances {
            let at = (region, Setting::Tolerance(tolerance));
            let kept = reduce(positions, sh, tolerance)?;
            let reduced = || ProbeSet::kept(positions, sh, &kept);
            record(&mut rows, AUTO_CAPTURED, at, false, &|_| Ok(reduced()?))?;
            let unmoved = |seen: Option<Arc<Occluders>>| Ok(reduced()?.seeing(seen).fitted(positions, sh)?);
            record(&mut rows, AUTO_UNMOVED, at, true, &unmoved)?;
            let placed = |seen| Ok(ProbeSet::placed(positions, sh, tolerance, seen)?);
            record(&mut rows, AUTO, at, true, &placed)?;
        }
        // Every candidate kept: each probe is its own capture, which the fit leaves as it is.
        let all = |_| Ok(ProbeSet::tetrahedral(positions, sh.clone())?);
        record(&mut rows, AUTO, (region, Setting::AllCandidates), false, &all)?;
    }

    // A probe at every test point: what interpolation cannot improve on.
    let at: Vec<DVec3> = points.iter().map(|p| Vec3::from(p.position).as_dvec3()).collect();
    let direct = capture_at(ctx, scene, &gpu, params.capture, &at)?;
    captured += direct.len();
    let capture_ms_per_probe = start.elapsed().as_secs_f64() * 1e3 / captured as f64;
    let floor =
        points.iter().zip(&truth).zip(&direct).map(|((p, e), sh)| squared_error(sh, p, e)).sum::<f64>();
    let jumps = match &scorer.frames {
        None => None,
        Some(f) => {
            let centres: Vec<DVec3> =
                frame_points.chunks(NORMALS.len()).map(|c| Vec3::from(c[0].position).as_dvec3()).collect();
            let captured = capture_at(ctx, scene, &gpu, params.capture, &centres)?;
            let values: Vec<[f64; 3]> = captured
                .iter()
                .flat_map(|sh| NORMALS.map(|n| sh.irradiance(n).map(|e| f64::from(e.max(0.0)))))
                .collect();
            Some(FrameJumps {
                frames: params.path_frames,
                reference: f.largest_jump(&frame_truth),
                reference_noise: 2f64.sqrt() * frame_noise / f.rms(),
                captured: f.largest_jump(&values),
            })
        }
    };
    Ok(Measurement {
        rows,
        path,
        test_points: points.len() / params.normals,
        reference_noise: noise / rms_truth,
        capture_floor: (floor / (3 * truth.len()) as f64).sqrt() / rms_truth,
        capture_ms_per_probe,
        reference_seconds,
        lookups_off: scorer.off,
        lookups_rays: scorer.rays,
        jumps,
    })
}

/// The moving group's centre (its bounding box's, where the technique looks its light up) at
/// `frames` + 1 times evenly over its motion, each with the axis normals ([`NORMALS`]).
fn frame_points(scene: &Scene, frames: usize) -> Result<Vec<Point>> {
    let group = &scene.groups[moving_group(scene)?];
    let corners = group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
    let (lo, hi) = bounds(corners).context("the moving group has no vertices")?;
    let duration = group.motion.as_ref().map_or(0.0, |m| m.duration());
    if duration <= 0.0 {
        bail!("--path-frames: the moving group of scene {} has no motion to follow", scene.name);
    }
    let centre = (lo + hi) * 0.5;
    Ok((0..=frames)
        .flat_map(|k| {
            let at = group.pose_at(duration * k as f32 / frames as f32).matrix().transform_point3(centre);
            NORMALS.map(|n| Point { position: at.to_array(), normal: n.to_array() })
        })
        .collect())
}

/// The moving group whose path the test points follow: the first of the probes' moving groups
/// ([`ProbeGroups`]: those with keyframes, or the first group in a scene without any).
fn moving_group(scene: &Scene) -> Result<usize> {
    match ProbeGroups::of(scene).moving().first() {
        Some(&g) => Ok(g),
        None => bail!("scene {} has no moving group to take a path from", scene.name),
    }
}

/// `normals` points per position, each with random normals: random positions outside solids,
/// in the moving group's bounding box at random times of its motion (`TestRegion::Path`) or in
/// the static box (`TestRegion::Box`).
fn test_points(
    scene: &Scene,
    solids: &Solids,
    params: &Params,
    static_box: (Vec3, Vec3),
) -> Result<Vec<Point>> {
    let (positions, normals) = (params.points, params.normals);
    let group = &scene.groups[moving_group(scene)?];
    let corners = group.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from(*p)));
    let Some((lo, hi)) = bounds(corners) else {
        bail!("the moving group of scene {} has no vertices", scene.name)
    };
    let (lo, hi, moving) = match params.test_region {
        TestRegion::Path => (lo, hi, Some(group)),
        TestRegion::Box => (static_box.0, static_box.1, None),
    };
    let mut rng = Pcg32(0x2545_f491_4f6c_dd1d);
    let mut points = Vec::new();
    // Positions inside solids are redrawn, up to a bound so that a moving group buried in
    // geometry is an error, not a hang.
    for _ in 0..positions * 20 {
        if points.len() == positions * normals {
            break;
        }
        // The time is drawn for both regions, so that each keeps the random stream it had.
        let t = rng.next();
        let local = lo + (hi - lo) * Vec3::new(rng.next(), rng.next(), rng.next());
        let p = moving.map_or(local, |g| g.pose_at(t).matrix().transform_point3(local));
        if solids.contains(p) {
            continue;
        }
        for _ in 0..normals {
            points.push(Point { position: p.to_array(), normal: rng.unit_vector().to_array() });
        }
    }
    if points.len() < positions * normals {
        bail!(
            "only {} of {positions} test positions {} are outside solids",
            points.len() / normals,
            params.test_region.describe()
        );
    }
    Ok(points)
}

#[derive(Serialize, Deserialize)]
struct Cached {
    scene: String,
    points: Vec<Point>,
    irradiance: IrradianceFile,
}

/// The reference irradiance at `points` (from the cache, under `label`, when it holds these
/// points at this spp), the RMS of its standard error, and the seconds it took (0 when cached).
fn reference(
    ctx: &Arc<Context>,
    scene: &Scene,
    points: &[Point],
    params: &Params,
    label: &str,
) -> Result<(Vec<[f64; 3]>, f64, f64)> {
    let path = params
        .cache
        .map(|dir| dir.join(format!("{}-{label}-{}-{}spp.json", scene.name, points.len(), params.spp)));
    let cached = path.as_ref().and_then(|p| files::read(p, files::JSON).ok()).and_then(|bytes| {
        serde_json::from_slice::<Cached>(&bytes).ok().filter(|c| c.scene == scene.name && c.points == points)
    });
    let start = Instant::now();
    let file = match cached {
        Some(c) => c.irradiance,
        None => {
            let mut away = scene.clone();
            for &g in ProbeGroups::of(scene).moving() {
                away.groups[g].transform.translation += Vec3::new(0.0, -1e4, 0.0);
            }
            let mut reference = IrradianceReference::new(ctx, &away, points, 11)?;
            let batch = 512;
            let mut left = params.spp;
            while left > 0 {
                reference.run_batch(left.min(batch))?;
                left -= left.min(batch);
            }
            let irradiance = IrradianceFile::from_statistics(&reference.statistics()?);
            let cached = Cached { scene: scene.name.clone(), points: points.to_vec(), irradiance };
            if let Some(path) = &path {
                if let Some(dir) = path.parent() {
                    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
                }
                std::fs::write(path, serde_json::to_string(&cached)?)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
            cached.irradiance
        }
    };
    reference_values(&file, start.elapsed().as_secs_f64())
}

fn reference_values(file: &IrradianceFile, seconds: f64) -> Result<(Vec<[f64; 3]>, f64, f64)> {
    let truth = file.irradiance.iter().map(|e| e.map(f64::from)).collect::<Vec<_>>();
    let n = file.standard_error.len().max(1) * 3;
    let noise =
        (file.standard_error.iter().flatten().map(|&s| f64::from(s).powi(2)).sum::<f64>() / n as f64).sqrt();
    Ok((truth, noise, seconds))
}

#[cfg(test)]
mod tests {
    use super::*;
    use kage::techniques::probes::CapturedLight;
    use kage_tests::Validated;

    #[test]
    fn a_power_law_is_recovered_with_no_scatter() {
        let logs: Vec<(f64, f64)> =
            [4.0f64, 10.0, 50.0].iter().map(|&n| (n.ln(), (0.8 * n.powf(-0.3)).ln())).collect();
        let (a, b, scatter) = power_law(&logs).unwrap();
        assert!((a - 0.8).abs() < 1e-12 && (b + 0.3).abs() < 1e-12 && scatter < 1e-12, "{a} {b} {scatter}");
        // Sets a factor e above and below the line scatter by 1 (in the log).
        let spread = [(1.0, 1.0), (1.0, -1.0), (2.0, 1.0), (2.0, -1.0)];
        assert_eq!(power_law(&spread), Some((1.0, 0.0, 1.0)));
        assert_eq!(power_law(&logs[..2]), None);
        assert_eq!(power_law(&[(1.0, 0.0), (1.0, 1.0), (1.0, 2.0)]), None);
    }

    #[test]
    fn box_test_points_spread_over_the_static_box() {
        let scene = Scene::builtin("atrium").unwrap();
        let solids = Solids::of_static(&scene);
        let params = Params {
            test_region: TestRegion::Box,
            grids: &[2],
            candidates: None,
            tolerances: &[],
            points: 64,
            normals: 2,
            spp: 1,
            capture: CaptureSettings::default(),
            cache: None,
            visibility: &[ProbeVisibility::Rays],
            closed_room: false,
            path_frames: 0,
        };
        let static_box = (Vec3::new(-1.0, 0.0, -2.0), Vec3::new(5.0, 3.0, 2.0));
        let points = test_points(&scene, &solids, &params, static_box).unwrap();
        assert_eq!(points.len(), 128);
        let positions: Vec<Vec3> = points.iter().map(|p| Vec3::from(p.position)).collect();
        assert!(positions.iter().all(|&p| p.cmpge(static_box.0).all() && p.cmple(static_box.1).all()));
        assert!(positions.iter().all(|&p| !solids.contains(p)));
        // Each position carries its normals; the positions themselves reach both ends of x.
        assert!(positions.chunks(2).all(|c| c[0] == c[1]));
        let (lo, hi) = kage::techniques::probes::bounds(positions.iter().copied()).unwrap();
        assert!(lo.x < 0.0 && hi.x > 4.0, "{lo} {hi}");
    }

    #[test]
    fn the_measurement_runs_at_a_tiny_size() {
        let ctx = Validated::new();
        let scene = Scene::builtin("probe-room").unwrap();
        let params = Params {
            test_region: TestRegion::Path,
            grids: &[2, 4],
            candidates: None,
            tolerances: &[0.2],
            points: 4,
            normals: 2,
            spp: 64,
            capture: CaptureSettings { cube_size: 8, light: CapturedLight::Sky, ..Default::default() },
            cache: None,
            visibility: &[ProbeVisibility::Rays, ProbeVisibility::Off],
            closed_room: true,
            path_frames: 4,
        };
        let m = measure(&ctx, &scene, &params).unwrap();
        assert_eq!(m.test_points, 4);
        let rows: Vec<_> = m.rows.iter().map(|r| (r.method.as_str(), r.probes)).collect();
        let (tri, tet) = (method(TRILINEAR, Region::Box), method(GRID_TETRA, Region::Box));
        let tri_off = method(&named(TRILINEAR, ProbeVisibility::Off), Region::Box);
        let tri_closed = method(&closed(TRILINEAR), Region::Box);
        // Each set with visibility, without, then its closed room. probe-room is one convex
        // room: its path's centre sees every probe, so the closed room is the whole set.
        assert_eq!(&rows[..3], &[(tri.as_str(), 8), (tri_off.as_str(), 8), (tri_closed.as_str(), 8)]);
        assert_eq!(rows[3], (tet.as_str(), 8));
        // probe-room's box is 4 × 2.5 × 4: level 4 is 4 × 3 × 4.
        assert_eq!(rows[6], (tri.as_str(), 48));
        assert!(m.rows.iter().all(|r| r.error.is_finite() && r.error >= 0.0));
        // Nothing hides a probe from the path's centre: no light leaked, visibility or not; and
        // no test point was sealed off from every probe.
        assert!(m.rows.iter().all(|r| r.leaked == Some(0.0)), "{:?}", m.rows);
        assert_eq!(m.lookups_rays.counts.unweighted, 0);
        // Four frames of the hop: every set's largest jump, the reference's and the captures'.
        assert!(m.rows.iter().all(|r| r.jump.is_some_and(|j| j.is_finite() && j >= 0.0)));
        let jumps = m.jumps.unwrap();
        assert!(jumps.frames == 4 && jumps.reference > 0.0 && jumps.captured > 0.0, "{jumps:?}");
        assert!(m.lookups_rays.counts.lookups > 0 && m.lookups_off.counts.lookups > 0);
        for region in [Region::Box, Region::Path] {
            let auto: Vec<_> = m.rows.iter().filter(|r| r.method == method(AUTO, region)).collect();
            assert_eq!(auto.len(), 2);
            // Automatic placement keeps at most the candidates (those of the finest grid
            // outside solids; probe-room has none inside), and at least a tetrahedron.
            let finest =
                m.rows.iter().filter(|r| r.method == method(TRILINEAR, region)).map(|r| r.probes).max();
            assert!(
                auto[0].probes >= 4 && auto[0].probes <= auto[1].probes && Some(auto[1].probes) == finest
            );
        }
        // The bunny's path lies inside the room, under the opening.
        assert!(m.path.0.y >= 0.0 && m.path.1.x - m.path.0.x < 4.0);
        assert!(m.capture_floor.is_finite() && m.capture_ms_per_probe > 0.0);
    }
}
