//! What `kage bench asm` gathers per frame and reports per configuration: the table on stdout,
//! `frames.csv`, `summary.csv` and the chart of error against frame time.
use super::Config;
use crate::chart;
use crate::chart::pick::Point;
use anyhow::{Context as _, Result};
use kage::pass::{median, PassTiming, TimingRow, TimingTable};
use kage::reference::{frames_to_converge, ShadowFlips};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One configuration's measurements in one frame.
pub struct FrameRow {
    pub frame: usize,
    pub t: f32,
    pub rest: Option<usize>,
    pub extra: bool,
    /// The view's motion from the previous frame, pixels (none for the first frame).
    pub motion_px: Option<f32>,
    /// Index into the configurations.
    pub config: usize,
    /// Fraction of the pixels shadowed differently from the reference, edge ties apart.
    pub error: f64,
    /// Of those, pixels lit in the render and shadowed in the reference.
    pub leaks: usize,
    /// Pixels shadowed differently on an edge tie (`kage::reference::EdgeTies`): not in `error`.
    pub edge_ties: usize,
    /// GPU ms of the frame's passes, and that over the first configuration's in this frame.
    pub frame_ms: f64,
    pub ratio: f64,
    /// Wall-clock ms of the frame's render call (GPU passes, host work and waits), and that
    /// over the first configuration's in this frame.
    pub wall_ms: f64,
    pub wall_ratio: f64,
    /// The flips from the previous frame, where the camera moves slowly.
    pub flips: Option<ShadowFlips>,
}

/// A configuration's frames, gathered as they come.
#[derive(Default)]
pub struct Series {
    timing: TimingTable,
    /// The errors of the walkthrough's samples (not of the extra frames).
    errors: Vec<f64>,
    /// The errors while resting at each keyframe, from the arriving frame on.
    rests: BTreeMap<usize, Vec<f64>>,
    ratios: Vec<f64>,
    walls: Vec<f64>,
    wall_ratios: Vec<f64>,
    /// Spurious flips per slow frame pair, fractions of the pixels.
    flips: Vec<f64>,
}

/// A configuration's figures over the run.
pub struct Summary {
    pub shadow_bytes: Option<u64>,
    pub error_mean: f64,
    pub error_max: f64,
    /// The mean over the keyframes of the error of the last frame held there.
    pub error_at_rest: Option<f64>,
    pub frame_ms: f64,
    /// The median over frames of the frame time over the first configuration's.
    pub ratio: f64,
    /// The median wall-clock frame, and the median of its ratio as for `ratio`.
    pub wall_ms: f64,
    pub wall_ratio: f64,
    pub passes: Vec<TimingRow>,
    pub flips_mean: Option<f64>,
    pub slow_pairs: usize,
    /// The most frames any rest took until its error stopped falling; `Some(None)` when some
    /// rest's error was still falling when it ended; `None` without rests.
    pub converged_after: Option<Option<usize>>,
    pub rest_frames: usize,
}

impl Series {
    pub fn add(&mut self, row: &FrameRow, timings: &[PassTiming]) {
        self.timing.add_frame(timings);
        if !row.extra {
            self.errors.push(row.error);
        }
        if let Some(k) = row.rest {
            self.rests.entry(k).or_default().push(row.error);
        }
        self.ratios.push(row.ratio);
        self.walls.push(row.wall_ms);
        self.wall_ratios.push(row.wall_ratio);
        self.flips.extend(row.flips.map(|f| f.fraction));
    }

    pub fn summary(&self, shadow_bytes: Option<u64>, tolerance: f64) -> Summary {
        let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        let at_rest: Vec<f64> = self.rests.values().filter_map(|e| e.last().copied()).collect();
        let converged: Vec<Option<usize>> =
            self.rests.values().map(|e| frames_to_converge(e, tolerance)).collect();
        Summary {
            shadow_bytes,
            error_mean: mean(&self.errors).unwrap_or(f64::NAN),
            error_max: self.errors.iter().copied().fold(f64::NAN, f64::max),
            error_at_rest: mean(&at_rest),
            frame_ms: self.timing.frame_median_ms(),
            ratio: median(&self.ratios),
            wall_ms: median(&self.walls),
            wall_ratio: median(&self.wall_ratios),
            passes: self.timing.rows(),
            flips_mean: mean(&self.flips),
            slow_pairs: self.flips.len(),
            converged_after: (!converged.is_empty()).then(|| {
                converged
                    .iter()
                    .copied()
                    .collect::<Option<Vec<usize>>>()
                    .map(|v| v.into_iter().max().unwrap_or(0))
            }),
            rest_frames: self.rests.values().map(Vec::len).max().unwrap_or(0),
        }
    }
}

fn mib(bytes: Option<u64>) -> String {
    bytes.map_or_else(|| "-".to_string(), |b| format!("{:.2}", b as f64 / (1 << 20) as f64))
}

fn converged_text(s: &Summary) -> String {
    match s.converged_after {
        None => "-".to_string(),
        Some(Some(frames)) => format!("{frames} frames"),
        Some(None) => format!("not in {}", s.rest_frames),
    }
}

pub fn print(configs: &[Config], summaries: &[Summary], slow_px: f32) {
    let optional =
        |v: Option<f64>, digits: usize| v.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"));
    println!(
        "{:<18} {:>10} {:>10} {:>10} {:>10} {:>10} {:>7} {:>9} {:>7} {:>10} {:>12}",
        "config",
        "shadow MiB",
        "error",
        "max",
        "at rest",
        "frame ms",
        "ratio",
        "wall ms",
        "ratio",
        "flips",
        "converged"
    );
    for (config, s) in configs.iter().zip(summaries) {
        println!(
            "{:<18} {:>10} {:>10.5} {:>10.5} {:>10} {:>10.3} {:>7.3} {:>9.3} {:>7.3} {:>10} {:>12}",
            config.name,
            mib(s.shadow_bytes),
            s.error_mean,
            s.error_max,
            optional(s.error_at_rest, 5),
            s.frame_ms,
            s.ratio,
            s.wall_ms,
            s.wall_ratio,
            optional(s.flips_mean, 6),
            converged_text(s)
        );
    }
    println!(
        "error: fraction of pixels lit in one of render and reference only, mean and max over the walkthrough's samples; at rest: after the frames held at each keyframe; frame ms: median GPU time; ratio: median over frames of the frame time over {}'s in the same frame; wall ms: median wall-clock time of the frame's render call (the GPU's passes, the host's work and the waits between them), its ratio as the GPU's; flips: mean fraction of pixels flipping where the reference does not, over the {} frame pairs moving by at most {slow_px} px; converged: frames until the error stops falling at rest (the slowest keyframe)",
        configs[0].name,
        summaries.first().map_or(0, |s| s.slow_pairs)
    );
    println!("{:<18} {:<16} {:>10} {:>10} {:>10}", "config", "pass", "median ms", "min ms", "max ms");
    for (config, s) in configs.iter().zip(summaries) {
        for pass in &s.passes {
            println!(
                "{:<18} {:<16} {:>10.3} {:>10.3} {:>10.3}",
                config.name, pass.name, pass.median_ms, pass.min_ms, pass.max_ms
            );
        }
    }
}

/// Writes `frames.csv` and `summary.csv` into `dir`; returns their paths.
pub fn write(
    dir: &Path,
    scene: &str,
    configs: &[Config],
    summaries: &[Summary],
    rows: &[FrameRow],
) -> Result<Vec<PathBuf>> {
    let optional = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v:.6}"));
    let mut frames = String::from(
        "frame,t,rest,extra,motion_px,config,technique,value,error,leaks,edge_ties,frame_ms,ratio,wall_ms,wall_ratio,flips_render,flips_reference,flips_spurious\n",
    );
    for r in rows {
        let c = &configs[r.config];
        let flips = r
            .flips
            .map_or_else(|| ",,".to_string(), |f| format!("{},{},{}", f.render, f.reference, f.spurious));
        writeln!(
            frames,
            "{},{:.5},{},{},{},{},{},{},{:.6},{},{},{:.4},{:.4},{:.4},{:.4},{flips}",
            r.frame,
            r.t,
            r.rest.map_or_else(String::new, |k| k.to_string()),
            r.extra,
            optional(r.motion_px.map(f64::from)),
            c.name,
            c.kind,
            c.value,
            r.error,
            r.leaks,
            r.edge_ties,
            r.frame_ms,
            r.ratio,
            r.wall_ms,
            r.wall_ratio
        )
        .expect("writing to a String");
    }
    // One column per pass any configuration ran, in order of first appearance.
    let mut passes: Vec<&str> = Vec::new();
    for pass in summaries.iter().flat_map(|s| &s.passes) {
        if !passes.contains(&pass.name.as_str()) {
            passes.push(&pass.name);
        }
    }
    let mut summary = String::from(
        "scene,config,technique,value,shadow_bytes,error_mean,error_max,error_at_rest,frame_ms,ratio,wall_ms,wall_ratio,flips_mean,slow_pairs,converged_after",
    );
    for pass in &passes {
        write!(summary, ",ms_{pass}").expect("writing to a String");
    }
    summary.push('\n');
    for (c, s) in configs.iter().zip(summaries) {
        let converged = match s.converged_after {
            Some(Some(frames)) => frames.to_string(),
            _ => String::new(),
        };
        write!(
            summary,
            "{scene},{},{},{},{},{:.6},{:.6},{},{:.4},{:.4},{:.4},{:.4},{},{},{converged}",
            c.name,
            c.kind,
            c.value,
            s.shadow_bytes.map_or_else(String::new, |b| b.to_string()),
            s.error_mean,
            s.error_max,
            optional(s.error_at_rest),
            s.frame_ms,
            s.ratio,
            s.wall_ms,
            s.wall_ratio,
            optional(s.flips_mean),
            s.slow_pairs
        )
        .expect("writing to a String");
        for pass in &passes {
            let ms = s.passes.iter().find(|p| p.name == *pass).map(|p| p.median_ms);
            write!(summary, ",{}", ms.map_or_else(String::new, |ms| format!("{ms:.4}")))
                .expect("writing to a String");
        }
        summary.push('\n');
    }
    let mut written = Vec::new();
    for (name, text) in [("frames.csv", frames), ("summary.csv", summary)] {
        let path = dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

/// The configurations on the chart: those with a frame time and a mean error above 0 (log
/// scales).
pub fn points(configs: &[Config], summaries: &[Summary]) -> Vec<Point> {
    configs
        .iter()
        .zip(summaries)
        .filter(|(_, s)| s.frame_ms > 0.0 && s.error_mean > 0.0)
        .map(|(c, s)| Point {
            series: c.series.into(),
            name: c.name.clone(),
            label: c.value.clone(),
            ms: s.frame_ms,
            error: s.error_mean,
        })
        .collect()
}

/// What the charts' error axis measures.
pub const ERROR_AXIS: &str = "fraction of pixels shadowed unlike the reference (mean)";

/// The chart of mean error against median frame time, one series per technique; `false` when
/// no configuration is on it, so there is nothing to draw.
pub fn chart(path: &Path, title: &str, configs: &[Config], summaries: &[Summary]) -> Result<bool> {
    let points = points(configs, summaries);
    if points.is_empty() {
        return Ok(false);
    }
    chart::write(path, title, &chart::frame_time_against(ERROR_AXIS), &points)?;
    Ok(true)
}
