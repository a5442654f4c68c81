//! The sweep's references, run until their own noise is far below the differences they rank and
//! cached: a reference at 0.5 % relative standard error takes minutes, and every sweep over the
//! same scene, pose, map and size reuses it.
use anyhow::{Context as _, Result};
use kage::backend::Context;
use kage::files;
use kage::imageio::{self, RgbaF32Image};
use kage::prt::cache;
use kage::reference::{LightMode, ReferenceOptions, ReferenceRenderer, OUTPUT_VERSION};
use kage::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A reference image and the noise it carries.
pub struct Reference {
    pub image: RgbaF32Image,
    /// Relative standard error (see `Statistics::relative_standard_error`).
    pub noise: f64,
    pub spp: u32,
}

/// What the reference depends on: the reference renderer's output version, the scene's
/// geometry, albedos, transforms, camera and map, the image size and the noise target. 64-bit
/// FNV-1a.
fn key(scene: &Scene, size: u32, target: f64) -> u64 {
    let mut h = 0xcbf29ce484222325u64;
    let mut write = |bytes: &[u8]| {
        for b in bytes {
            h = (h ^ u64::from(*b)).wrapping_mul(0x100000001b3);
        }
    };
    write(&OUTPUT_VERSION.to_le_bytes());
    write(&cache::geometry_hash(scene).to_le_bytes());
    for group in &scene.groups {
        group.transform.matrix().to_cols_array().iter().for_each(|v| write(&v.to_le_bytes()));
        group.meshes.iter().flat_map(|m| m.albedo).for_each(|v| write(&v.to_le_bytes()));
    }
    let c = &scene.camera;
    [c.position.to_array(), c.target.to_array(), c.up.to_array()]
        .iter()
        .flatten()
        .for_each(|v| write(&v.to_le_bytes()));
    write(&c.fov_y_deg.to_le_bytes());
    write(&scene.environment.width().to_le_bytes());
    scene.environment.pixels().iter().flatten().for_each(|v| write(&v.to_le_bytes()));
    write(&size.to_le_bytes());
    write(&target.to_le_bytes());
    h
}

/// The reference of `scene` at `size`², from the cache under `dir` when there, else sampled in
/// batches until its relative standard error is at most `target` or it has `max_spp` samples per
/// pixel (then it says so), and cached. `progress` hears each batch's noise.
pub fn reference(
    ctx: &Arc<Context>,
    scene: &Scene,
    size: u32,
    target: f64,
    max_spp: u32,
    dir: &Path,
    progress: &mut dyn FnMut(u32, f64),
) -> Result<Reference> {
    let stem = dir.join(format!("{}-{size}-{:016x}", scene.name, key(scene, size, target)));
    let (exr, meta) = (stem.with_extension("exr"), stem.with_extension("txt"));
    if let Some(cached) = load(&exr, &meta) {
        return Ok(cached);
    }
    let options = ReferenceOptions { width: size, height: size, light: LightMode::Environment, seed: 0 };
    let mut renderer = ReferenceRenderer::new(ctx, scene, &options).context("setting up the reference")?;
    let mut batch = 64u32.min(max_spp);
    let noise = loop {
        renderer.run_batch(batch)?;
        let samples = renderer.samples();
        let noise = renderer.statistics()?.relative_standard_error().unwrap_or(0.0);
        progress(samples, noise);
        if noise <= target || samples >= max_spp {
            break noise;
        }
        // Noise falls as 1 / sqrt(samples): aim a little past the target.
        let needed = (f64::from(samples) * (noise / target).powi(2) * 1.1).ceil() as u32;
        batch = needed.saturating_sub(samples).clamp(16, samples * 4).min(max_spp - samples);
    };
    let spp = renderer.samples();
    if noise > target {
        eprintln!(
            "kage: note: reference {} stopped at --max-spp {max_spp} with noise {:.2} % (target {:.2} %)",
            exr.display(),
            100.0 * noise,
            100.0 * target
        );
    }
    let image = renderer.image()?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    imageio::write(&exr, &image, 1.0).with_context(|| format!("writing {}", exr.display()))?;
    std::fs::write(&meta, format!("{spp} {noise}\n"))
        .with_context(|| format!("writing {}", meta.display()))?;
    Ok(Reference { image, noise, spp })
}

/// The note beside a cached reference: two numbers.
const NOTE: files::Limit = files::Limit { kind: "a reference's note", bytes: 1024 };

/// A cached reference, or `None` when either file is missing or unreadable (then it is redone).
fn load(exr: &Path, meta: &Path) -> Option<Reference> {
    let bytes = files::read(meta, NOTE).ok()?;
    let mut fields = std::str::from_utf8(&bytes).ok()?.split_whitespace();
    let spp = fields.next()?.parse().ok()?;
    let noise = fields.next()?.parse().ok()?;
    let image = imageio::read_exr(exr).ok()?;
    Some(Reference { image, noise, spp })
}

/// `--cache DIR`'s references folder, or the default cache folder's.
pub fn folder(cache_arg: Option<&Path>) -> Result<PathBuf> {
    let dir = match cache_arg {
        Some(dir) => dir.to_path_buf(),
        None => cache::default_dir()
            .context("no cache folder: pass --cache DIR, or set KAGE_CACHE_DIR, XDG_CACHE_HOME or HOME")?,
    };
    Ok(dir.join("references"))
}
