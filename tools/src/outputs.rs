//! Output paths checked before the work that fills them: a wrong extension, a folder that does
//! not exist or one Kage may not write in fails at once, not after a long render or reference.
use anyhow::{bail, Result};
use clap::Args;
use std::path::Path;

/// How bright a PNG output is: the radiance is multiplied by it before tonemapping.
#[derive(Args)]
pub struct Exposure {
    /// Exposure multiplier applied before tonemapping (PNG only), or `auto`: 0.18 over the
    /// picture's log-average luminance, readable whatever the light's units (default: the
    /// scene's `exposure`, 1 for most scenes, 4 for probe-room)
    #[arg(long)]
    exposure: Option<String>,
}

/// What `--exposure` asked for.
#[derive(Clone, Copy, Debug)]
pub enum ExposureRule {
    Fixed(f32),
    Auto,
}

impl Exposure {
    /// The rule given, once checked (`auto` or a positive number), else `scene`'s exposure.
    pub fn checked(&self, scene: &kage::scene::Scene) -> Result<ExposureRule> {
        match self.exposure.as_deref() {
            None => Ok(ExposureRule::Fixed(scene.exposure)),
            Some("auto") => Ok(ExposureRule::Auto),
            Some(text) => match text.parse::<f32>() {
                Ok(e) if e.is_finite() && e > 0.0 => Ok(ExposureRule::Fixed(e)),
                _ => bail!("--exposure must be a positive number or auto, got {text}"),
            },
        }
    }
}

impl ExposureRule {
    /// The multiplier for `image`: the fixed one, or [`kage::imageio::auto_exposure`]'s (said
    /// in a note, so that the next run can fix it).
    pub fn for_image(self, image: &kage::imageio::RgbaF32Image) -> f32 {
        match self {
            ExposureRule::Fixed(e) => e,
            ExposureRule::Auto => {
                let exposure = kage::imageio::auto_exposure(image);
                eprintln!("kage: note: --exposure auto: {exposure:.4}");
                exposure
            }
        }
    }
}

/// Checks that `path`, given as `flag`, ends in one of `extensions` and lies in an existing
/// folder that Kage can write in.
pub fn check(path: &Path, flag: &str, extensions: &[&str]) -> Result<()> {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !extension.is_some_and(|e| extensions.contains(&e.as_str())) {
        let names: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
        bail!("{flag} {}: the file must end in {}", path.display(), names.join(" or "));
    }
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        bail!("{flag} {}: the folder {} does not exist", path.display(), folder.display());
    }
    // Permissions alone do not say (root ignores them; a read-only mount does not show in
    // them): a file made and removed at once does.
    let probe = folder.join(format!(".kage-write-check-{}", std::process::id()));
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => bail!("{flag} {}: cannot write in the folder {}: {e}", path.display(), folder.display()),
    }
}

/// The 9×3 coefficients as `kage sh` prints them, one line per coefficient after a header.
pub fn print_coefficients(sh: &kage::sh::ShRgb9) {
    println!("# real SH, index = l*(l+1)+m, orthonormal basis (see README, \"SH basis\")");
    println!("# {:>5} {:>3} {:>3} {:>14} {:>14} {:>14}", "index", "l", "m", "red", "green", "blue");
    for (i, c) in sh.c.iter().enumerate() {
        let l = (i as f64).sqrt() as i32;
        let m = i as i32 - l * (l + 1);
        println!("  {i:>5} {l:>3} {m:>3} {:>14.6e} {:>14.6e} {:>14.6e}", c[0], c[1], c[2]);
    }
}
