//! `kage compare A.exr B.exr`: error metrics of image A against the reference B, as text or
//! JSON, with thresholds that set the exit status (for CI).
use anyhow::{bail, Context as _, Result};
use clap::Args;
use kage::reference::{
    compare, diff_image, shadow_mismatch, shadow_mismatch_image, EdgeTies, SHADOW_THRESHOLD,
};
use std::path::PathBuf;

#[derive(Args)]
pub struct CompareArgs {
    /// The image to measure (.exr, linear radiance).
    a: PathBuf,
    /// The reference it is measured against (.exr); relative RMSE divides by its mean.
    b: PathBuf,
    /// Write a false-colour picture of |luminance(A) − luminance(B)| per pixel (.png, viridis,
    /// yellow at the 99th percentile of those errors).
    #[arg(long)]
    diff: Option<PathBuf>,
    /// Also print the fraction of pixels lit in one image and shadowed in the other (for
    /// local-light renders against `kage reference --light local`).
    #[arg(long)]
    shadow_mismatch: bool,
    /// Write where A and B disagree on lit and shadowed (.png: red lit in A only, blue lit in
    /// B only, light grey lit in both, dark grey shadowed in both).
    #[arg(long)]
    mismatch_image: Option<PathBuf>,
    /// With --shadow-mismatch and --mismatch-image: a pixel is lit when its luminance exceeds this fraction of B's
    /// brightest pixel.
    #[arg(long, default_value_t = SHADOW_THRESHOLD)]
    shadow_threshold: f64,
    /// With --shadow-mismatch and --mismatch-image: B's edge ties (`kage reference --light
    /// local --edges`): pixels where an edge passes closer to the centre than the rasterizer
    /// places geometry are counted apart (yellow in the mismatch image), not as mismatches.
    #[arg(long)]
    edges: Option<PathBuf>,
    /// Print the metrics as one JSON object on stdout instead of text.
    #[arg(long)]
    json: bool,
    /// Fail (exit status 3) when the relative RMSE exceeds this.
    #[arg(long)]
    max_rel_rmse: Option<f64>,
    /// Fail (exit status 3) when the fraction of pixels lit in one image only exceeds this
    /// (computes the shadow mismatch).
    #[arg(long)]
    max_mismatch: Option<f64>,
}

/// Exit status of a comparison beyond a threshold (an error is 1).
const BEYOND_THRESHOLD: i32 = 3;

pub fn run(args: &CompareArgs) -> Result<()> {
    for (path, flag) in [(&args.diff, "--diff"), (&args.mismatch_image, "--mismatch-image")] {
        if let Some(path) = path {
            crate::outputs::check(path, flag, &["png"])?;
        }
    }
    for (bound, flag) in [(args.max_rel_rmse, "--max-rel-rmse"), (args.max_mismatch, "--max-mismatch")] {
        if let Some(b) = bound.filter(|b| !(b.is_finite() && *b >= 0.0)) {
            bail!("{flag} must be a number at least 0, got {b}");
        }
    }
    for path in [&args.a, &args.b] {
        let exr = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if !exr {
            bail!(
                "{}: kage compare reads linear radiance from .exr files (a .png is tonemapped and \
                 clipped); render and reference with --out FILE.exr",
                path.display()
            );
        }
    }
    let a = kage::imageio::read_exr(&args.a)?;
    let b = kage::imageio::read_exr(&args.b)?;
    let edges = match &args.edges {
        Some(path) => Some(
            EdgeTies::from_image(&kage::imageio::read_exr(path)?)
                .with_context(|| format!("in {}", path.display()))?,
        ),
        None => None,
    };
    let m = compare(&a, &b)
        .with_context(|| format!("comparing {} with {}", args.a.display(), args.b.display()))?;
    let mismatch = match args.shadow_mismatch || args.max_mismatch.is_some() {
        true => Some(shadow_mismatch(&a, &b, args.shadow_threshold, edges.as_ref())?),
        false => None,
    };
    let mut beyond = Vec::new();
    if let Some(max) = args.max_rel_rmse.filter(|&max| m.relative_rmse > max) {
        beyond.push(format!("relative RMSE {:.6e} exceeds --max-rel-rmse {max}", m.relative_rmse));
    }
    if let (Some(max), Some(s)) = (args.max_mismatch, &mismatch) {
        if s.fraction > max {
            beyond.push(format!("shadow mismatch {:.6e} exceeds --max-mismatch {max}", s.fraction));
        }
    }
    if args.json {
        let value = serde_json::json!({
            "a": args.a.display().to_string(),
            "b": args.b.display().to_string(),
            "width": a.width,
            "height": a.height,
            "rmse": m.rmse,
            "relative_rmse": m.relative_rmse,
            "reference_mean": m.reference_mean,
            "mean_abs_error": m.mean_abs_error,
            "p99_abs_error": m.p99_abs_error,
            "max_abs_error": m.max_abs_error,
            "shadow_mismatch": mismatch.as_ref().map(|s| serde_json::json!({
                "fraction": s.fraction,
                "differing_pixels": s.differing,
                "lit_in_a_only": s.lit_in_render_only,
                "no_surface_in_b": s.no_surface,
                "edge_ties": edges.as_ref().map(|_| s.at_edges),
                "lit_above": s.threshold,
            })),
            "max_rel_rmse": args.max_rel_rmse,
            "max_mismatch": args.max_mismatch,
            "within_thresholds": beyond.is_empty(),
        });
        println!("{value}");
    } else {
        println!(
            "{} vs {} ({}x{}; over all pixels and the R, G, B channels)",
            args.a.display(),
            args.b.display(),
            a.width,
            a.height
        );
        println!("rmse             {:.6e}", m.rmse);
        println!("relative rmse    {:.6e}   (rmse / mean of B = {:.6e})", m.relative_rmse, m.reference_mean);
        println!("mean abs error   {:.6e}", m.mean_abs_error);
        println!("p99 abs error    {:.6e}", m.p99_abs_error);
        println!("max abs error    {:.6e}", m.max_abs_error);
        if let Some(s) = &mismatch {
            let relative = args.shadow_threshold;
            println!(
                "shadow mismatch  {:.6e}   ({} pixels lit in one image only, {} of them lit in A only; lit above {:.3e} = {relative} x B's brightest)",
                s.fraction, s.differing, s.lit_in_render_only, s.threshold
            );
            if s.no_surface > 0 {
                println!(
                    "no surface       {} pixels where B shows no surface (alpha 0: not compared)",
                    s.no_surface
                );
            }
            match &edges {
                Some(edges) => println!(
                    "edge ties        {} more pixels lit in one image only lie within 1/{} px of an edge (not counted)",
                    s.at_edges,
                    1u32 << edges.bits
                ),
                None => println!("edge ties        counted above (no --edges)"),
            }
        }
    }
    // With --json, stdout holds the JSON alone.
    let note = |line: String| if args.json { eprintln!("{line}") } else { println!("{line}") };
    if let Some(path) = &args.mismatch_image {
        let mismatch = shadow_mismatch_image(&a, &b, args.shadow_threshold, edges.as_ref())?;
        mismatch.write_png(path)?;
        note(format!(
            "wrote {}: red lit in A only, blue lit in B only, yellow either on an edge tie (lit above {:.3e})",
            path.display(),
            mismatch.scale
        ));
    }
    if let Some(path) = &args.diff {
        let diff = diff_image(&a, &b)?;
        diff.write_png(path)?;
        note(format!(
            "wrote {}: |luminance difference| per pixel, viridis, yellow = {:.6e} (99th percentile)",
            path.display(),
            diff.scale
        ));
    }
    if !beyond.is_empty() {
        for line in &beyond {
            eprintln!("kage: compare: {line}");
        }
        std::process::exit(BEYOND_THRESHOLD);
    }
    Ok(())
}
