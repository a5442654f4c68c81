//! The local-light references of `kage bench asm` (`kage reference --light local` of each
//! frame's camera), kept on disk: ray casting them is the slow part of the benchmark on a CPU
//! driver, and every run visits the same cameras.
//!
//! A reference is a 32-bit EXR named for a hash of everything it depends on: the geometry
//! (`geometry_hash`), the group transforms, the lights, the camera and the image size, and the
//! reference renderer's [`OUTPUT_VERSION`], with its edge ties beside it
//! (`-edges.exr`, see [`EdgeTies`]). A pair that cannot be read is computed again and replaced.
use anyhow::{Context as _, Result};
use kage::backend::Context;
use kage::imageio::RgbaF32Image;
use kage::prt::cache::{geometry_hash, Fnv64};
use kage::reference::{EdgeTies, LightMode, ReferenceOptions, ReferenceRenderer, OUTPUT_VERSION};
use kage::scene::{Camera, Scene};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A frame's reference: the image and where a raster render's state is a tie.
#[derive(Clone)]
pub struct Truth {
    pub image: RgbaF32Image,
    pub edges: EdgeTies,
}

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
    last: Option<(Camera, Truth)>,
    pub computed: usize,
    pub loaded: usize,
}

impl References {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, size: u32, dir: Option<PathBuf>) -> Result<References> {
        if let Some(dir) = &dir {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        let mut key = Fnv64::new();
        key.write(&OUTPUT_VERSION.to_le_bytes());
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
    pub fn get(&mut self, camera: &Camera) -> Result<Truth> {
        if let Some((last, truth)) = &self.last {
            if last == camera {
                return Ok(truth.clone());
            }
        }
        let truth = self.load_or_compute(camera)?;
        self.last = Some((*camera, truth.clone()));
        Ok(truth)
    }

    fn load_or_compute(&mut self, camera: &Camera) -> Result<Truth> {
        let paths = self.dir.as_deref().map(|dir| self.paths(dir, camera));
        if let Some((image_path, edges_path)) = &paths {
            if image_path.exists() && edges_path.exists() {
                match self.load(image_path, edges_path) {
                    Ok(truth) => {
                        self.loaded += 1;
                        return Ok(truth);
                    }
                    Err(e) => eprintln!("kage: note: {e:#}; computing {} again", image_path.display()),
                }
            }
        }
        let truth = self.compute(camera)?;
        if let Some((image_path, edges_path)) = &paths {
            for (path, image) in [(image_path, &truth.image), (edges_path, &truth.edges.to_image())] {
                kage::imageio::write(path, image, 1.0)
                    .with_context(|| format!("keeping the reference in {}", path.display()))?;
            }
        }
        self.computed += 1;
        Ok(truth)
    }

    fn load(&self, image_path: &Path, edges_path: &Path) -> Result<Truth> {
        let image = kage::imageio::read_exr(image_path)?;
        let edges = EdgeTies::from_image(&kage::imageio::read_exr(edges_path)?)
            .with_context(|| format!("in {}", edges_path.display()))?;
        let size = (self.size, self.size);
        if (image.width, image.height) != size || (edges.width, edges.height) != size {
            anyhow::bail!("{} or its edges have the wrong size", image_path.display());
        }
        Ok(Truth { image, edges })
    }

    /// The image's file and its edge ties' beside it.
    fn paths(&self, dir: &Path, camera: &Camera) -> (PathBuf, PathBuf) {
        let mut key = Fnv64::new();
        key.write(&self.key.finish().to_le_bytes());
        key.write(format!("{camera:?}").as_bytes());
        // The name only helps a reader: its first 40 characters keep the file name short.
        let name: String = self
            .scene
            .name
            .chars()
            .take(40)
            .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
            .collect();
        let stem = format!("{name}-{:016x}-{}", key.finish(), self.size);
        (dir.join(format!("{stem}.exr")), dir.join(format!("{stem}-edges.exr")))
    }

    fn compute(&mut self, camera: &Camera) -> Result<Truth> {
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
        Ok(Truth { image: renderer.image()?, edges: renderer.edge_ties()? })
    }
}
