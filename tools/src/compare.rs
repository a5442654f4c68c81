//! `kage compare A.exr B.exr`: error metrics of image A against the reference B.
use anyhow::{Context as _, Result};
use clap::Args;
use kage::reference::{compare, diff_image, shadow_mismatch, shadow_mismatch_image, SHADOW_THRESHOLD};
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
}

pub fn run(args: &CompareArgs) -> Result<()> {
    for (path, flag) in [(&args.diff, "--diff"), (&args.mismatch_image, "--mismatch-image")] {
        if let Some(path) = path {
            crate::outputs::check(path, flag, &["png"])?;
        }
    }
    let a = kage::imageio::read_exr(&args.a)?;
    let b = kage::imageio::read_exr(&args.b)?;
    let m = compare(&a, &b)
        .with_context(|| format!("comparing {} with {}", args.a.display(), args.b.display()))?;
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
    if args.shadow_mismatch {
        let relative = args.shadow_threshold;
        let s = shadow_mismatch(&a, &b, relative)?;
        println!(
            "shadow mismatch  {:.6e}   ({} pixels lit in one image only, {} of them lit in A only; lit above {:.3e} = {relative} x B's brightest)",
            s.fraction, s.differing, s.lit_in_render_only, s.threshold
        );
    }
    if let Some(path) = &args.mismatch_image {
        let mismatch = shadow_mismatch_image(&a, &b, args.shadow_threshold)?;
        mismatch.write_png(path)?;
        println!(
            "wrote {}: red lit in A only, blue lit in B only (lit above {:.3e})",
            path.display(),
            mismatch.scale
        );
    }
    if let Some(path) = &args.diff {
        let diff = diff_image(&a, &b)?;
        diff.write_png(path)?;
        println!(
            "wrote {}: |luminance difference| per pixel, viridis, yellow = {:.6e} (99th percentile)",
            path.display(),
            diff.scale
        );
    }
    Ok(())
}
