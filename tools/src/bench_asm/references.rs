//! The local-light references of `kage bench asm` (`kage reference --light local` of each
//! frame's camera), kept on disk: ray casting them is the slow part of the benchmark on a CPU
//! driver, and every run visits the same cameras.
//!
//! A reference is a 32-bit EXR named for a hash of everything it depends on: the geometry
//! (`geometry_hash`), the group transforms, the lights, the camera and the image size, and a
//! version to bump when the reference renderer's output changes. A file that cannot be read is
//! computed again and replaced.
use anyhow::{Context as _, Result};
use kage::backend::Context;
use kage::imageio::RgbaF32Image;
use kage::prt::cache::{geometry_hash, Fnv64};
use kage::reference::{LightMode, ReferenceOptions, ReferenceRenderer};
use kage::scene::{Camera, Scene};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Part of every file name's hash: bump it when `kage reference --light local` changes.
const VERSION: u32 = 1;

pub struct References {
    ctx: Arc<Context>,
    scene: Scene,
    size: u32,
    /// Where the files are; `None`: nothing is kept.
    dir: Option<PathBuf>,
    /// The hash of the scene and size, to which each camera is added.
    key: Fnv64,
    /// Built at the first reference not found on disk.
    renderer: Option<ReferenceRenderer>,
    /// The last camera's reference: a camera held still asks for it again.
    last: Option<(Camera, RgbaF32Image)>,
    pub computed: usize,
    pub loaded: usize,
}

impl References {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, size: u32, dir: Option<PathBuf>) -> Result<References> {
        if let Some(dir) = &dir {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        let mut key = Fnv64::new();
        key.write(&VERSION.to_le_bytes());
        key.write(&geometry_hash(scene).to_le_bytes());
        // Debug formatting prints every float exactly (shortest round-trip form).
        let transforms: Vec<_> = scene.groups.iter().map(|g| g.transform).collect();
        key.write(format!("{transforms:?} {:?} {size}", scene.lights).as_bytes());
        Ok(References {
            ctx: ctx.clone(),
            scene: scene.clone(),
            size,
            dir,
            key,
            renderer: None,
            last: None,
            computed: 0,
            loaded: 0,
        })
    }

    /// The reference seen from `camera`, from the disk if it is there, else ray cast (and kept).
    pub fn get(&mut self, camera: &Camera) -> Result<RgbaF32Image> {
        if let Some((last, image)) = &self.last {
            if last == camera {
                return Ok(image.clone());
            }
        }
        let image = self.load_or_compute(camera)?;
        self.last = Some((*camera, image.clone()));
        Ok(image)
    }

    fn load_or_compute(&mut self, camera: &Camera) -> Result<RgbaF32Image> {
        let path = self.dir.as_deref().map(|dir| self.path(dir, camera));
        if let Some(path) = &path {
            if path.exists() {
                match kage::imageio::read_exr(path) {
                    Ok(image) if (image.width, image.height) == (self.size, self.size) => {
                        self.loaded += 1;
                        return Ok(image);
                    }
                    Ok(_) => {
                        eprintln!("kage: note: {} has the wrong size; computing it again", path.display())
                    }
                    Err(e) => eprintln!("kage: note: {e}; computing {} again", path.display()),
                }
            }
        }
        let image = self.compute(camera)?;
        if let Some(path) = &path {
            kage::imageio::write(path, &image, 1.0)
                .with_context(|| format!("keeping the reference in {}", path.display()))?;
        }
        self.computed += 1;
        Ok(image)
    }

    fn path(&self, dir: &Path, camera: &Camera) -> PathBuf {
        let mut key = Fnv64::new();
        key.write(&self.key.finish().to_le_bytes());
        key.write(format!("{camera:?}").as_bytes());
        let name: String = self
            .scene
            .name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
            .collect();
        dir.join(format!("{name}-{:016x}-{}.exr", key.finish(), self.size))
    }

    fn compute(&mut self, camera: &Camera) -> Result<RgbaF32Image> {
        let renderer = match &mut self.renderer {
            Some(renderer) => renderer,
            slot => {
                let options = ReferenceOptions {
                    width: self.size,
                    height: self.size,
                    light: LightMode::Local,
                    seed: 0,
                };
                let renderer = ReferenceRenderer::new(&self.ctx, &self.scene, &options)
                    .context("setting up the reference renderer")?;
                slot.insert(renderer)
            }
        };
        renderer.set_camera(*camera)?;
        // Local lights with hard shadows are deterministic: one sample per pixel is exact.
        renderer.run_batch(1)?;
        Ok(renderer.image()?)
    }
}
