//! Helpers shared by Kage's integration tests: a validated context that fails the test on any
//! validation message, small scenes built in code, every technique at cheap settings, and
//! scratch folders.
use kage::backend::{Context, ContextDesc};
use kage::prt::{transfer, PrtParams, TransferSet};
use kage::renderer::RenderOptions;
use kage::scene::{Camera, EnvMap, Group, Mesh, Scene, Transform};
use kage::techniques::asm::AsmSettings;
use kage::techniques::description::{TechniqueDesc, TechniqueKind};
use kage::techniques::probes::{CaptureSettings, ProbePlacement, ProbeSettings};
use kage::techniques::tamura::technique::OcclusionSettings;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A context with validation on. Dropping it asserts that validation reported nothing, so a
/// test cannot forget the check.
pub struct Validated(pub Arc<Context>);

impl Validated {
    pub fn new() -> Validated {
        let ctx = Context::new(&ContextDesc { validation: true, device: None })
            .expect("a Vulkan device with validation layers (run scripts/deps.sh)");
        Validated(ctx)
    }
}

impl Default for Validated {
    fn default() -> Self {
        Validated::new()
    }
}

impl std::ops::Deref for Validated {
    type Target = Arc<Context>;
    fn deref(&self) -> &Arc<Context> {
        &self.0
    }
}

impl Drop for Validated {
    fn drop(&mut self) {
        let messages = self.0.take_validation_messages();
        if !std::thread::panicking() {
            assert!(messages.is_empty(), "validation reported:\n{}", messages.join("\n"));
        }
    }
}

/// A scene of one group holding `mesh`, under `environment`, seen by `camera`.
pub fn single_mesh_scene(mesh: Mesh, environment: EnvMap, camera: Camera) -> Scene {
    Scene::new("test", vec![Group::new("object", vec![mesh], Transform::default())], environment, camera)
}

/// A fresh, empty folder under the system temp folder, unique per call: tests of one binary run
/// in parallel, so two calls with the same name must not share (and wipe) one folder.
pub fn scratch_dir(test: &str) -> PathBuf {
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("kage-tests-{}-{test}-{call}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp folder");
    dir
}

/// The first fenced block of `lang` in README.md after the line `after` (a heading), without
/// its fences: the tests that run README's commands and compile its example read them here, so
/// README shows what the tests execute.
pub fn readme_block(after: &str, lang: &str) -> String {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"))
        .expect("README.md");
    let section =
        readme.find(&format!("\n{after}\n")).unwrap_or_else(|| panic!("README has no line '{after}'"));
    let fence = format!("```{lang}\n");
    let start = section
        + readme[section..]
            .find(&fence)
            .unwrap_or_else(|| panic!("README has no {lang} block after '{after}'"))
        + fence.len();
    let len = readme[start..].find("```").expect("the block's closing fence");
    readme[start..start + len].to_string()
}

/// Every technique (each [`TechniqueKind`]) at its cheapest settings, with the PRT transfer it
/// needs computed for `scene` (once per kind of visibility); the callers set the image size.
pub fn every_technique(ctx: &Arc<Context>, scene: &Scene) -> Vec<(TechniqueKind, RenderOptions)> {
    let prt = PrtParams { bands: 3, rays: 16, ..PrtParams::DEFAULT };
    let occlusion = OcclusionSettings { regions: 4, mask_size: 16, ..Default::default() };
    let mut transfers: Vec<Arc<TransferSet>> = Vec::new();
    let kinds = (0..=u8::MAX as u32).filter_map(TechniqueKind::from_repr);
    kinds
        .map(|kind| {
            let technique = match TechniqueDesc::new(kind) {
                TechniqueDesc::Unshadowed => TechniqueDesc::Unshadowed,
                TechniqueDesc::SloanSelf { .. } => TechniqueDesc::SloanSelf { prt },
                TechniqueDesc::SloanScene { .. } => TechniqueDesc::SloanScene { prt },
                TechniqueDesc::Tamura { .. } => TechniqueDesc::Tamura { prt, occlusion },
                TechniqueDesc::TamuraPaper { .. } => {
                    TechniqueDesc::TamuraPaper { prt, regions: 4, mask_size: 16 }
                }
                TechniqueDesc::ParallelLights { .. } => {
                    TechniqueDesc::ParallelLights { regions: 4, shadow_map_size: 16 }
                }
                TechniqueDesc::ShadowMap { .. } => TechniqueDesc::ShadowMap { size: 16 },
                TechniqueDesc::Probes { .. } => TechniqueDesc::Probes {
                    probes: ProbeSettings {
                        placement: ProbePlacement::Grid([2, 2, 2]),
                        capture: CaptureSettings { cube_size: 8, samples: 16, ..Default::default() },
                        ..Default::default()
                    },
                    prt,
                },
                TechniqueDesc::Asm(_) => {
                    TechniqueDesc::Asm(AsmSettings { budget_mb: 1.0, ..AsmSettings::default() })
                }
            };
            let transfer = technique.precomputation().map(|params| {
                if let Some(done) = transfers.iter().find(|t| t.params == params) {
                    return done.clone();
                }
                let made =
                    transfer::precompute(ctx, scene, params, &mut kage::progress::silent).expect("transfer");
                transfers.push(Arc::new(made));
                transfers.last().unwrap().clone()
            });
            (kind, RenderOptions { width: 0, height: 0, technique, transfer })
        })
        .collect()
}

/// Renders one frame of `scene` at `width`x`height` and reads it back.
pub fn render_once(
    ctx: &Arc<Context>,
    scene: &Scene,
    width: u32,
    height: u32,
) -> kage::imageio::RgbaF32Image {
    let options = kage::renderer::RenderOptions { width, height, ..Default::default() };
    let mut renderer = kage::renderer::Renderer::new(ctx, scene, &options).expect("renderer");
    renderer.render().expect("frame");
    renderer.image().expect("readback")
}

/// Each group's own PRT transfer of `scene` at 3 bands with few rays (128): for tests that look
/// at where shadows fall, not at the transfer's last digits.
pub fn shadow_test_transfer(ctx: &Arc<Context>, scene: &Scene) -> Arc<kage::prt::TransferSet> {
    use kage::prt::{transfer, PrtParams};
    let params = PrtParams { bands: 3, rays: 128, ..PrtParams::DEFAULT };
    Arc::new(transfer::precompute(ctx, scene, params, &mut kage::progress::silent).expect("transfer"))
}

/// A valid 2 × 1 OpenEXR file whose header then claims `width` × `height` pixels: its
/// `dataWindow` attribute (box2i: xMin, yMin, xMax, yMax) and `chunkCount` (one block per row,
/// uncompressed) patched to agree, the pixels left as they were.
pub fn exr_declaring(path: &Path, width: i32, height: i32) {
    use exr::prelude::{Encoding, Image, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage};
    let channels = SpecificChannels::rgb(|_: Vec2<usize>| (1.0f32, 1.0f32, 1.0f32));
    let layer = Layer::new((2, 1), LayerAttributes::default(), Encoding::UNCOMPRESSED, channels);
    let mut bytes = Vec::new();
    Image::from_layer(layer).write().to_buffered(std::io::Cursor::new(&mut bytes)).unwrap();
    let mut patch = |attribute: &[u8], values: &[i32]| {
        let at = bytes.windows(attribute.len()).position(|w| w == attribute).unwrap() + attribute.len();
        assert_eq!(bytes[at..at + 4], (4 * values.len() as i32).to_le_bytes(), "the attribute's size");
        for (i, value) in values.iter().enumerate() {
            bytes[at + 4 + 4 * i..at + 8 + 4 * i].copy_from_slice(&value.to_le_bytes());
        }
    };
    patch(b"dataWindow\0box2i\0", &[0, 0, width - 1, height - 1]);
    patch(b"chunkCount\0int\0", &[height]);
    std::fs::write(path, bytes).unwrap();
}

/// A Radiance HDR header claiming `width` × `height` pixels, followed by one pixel.
pub fn hdr_declaring(path: &Path, width: u32, height: u32) {
    let mut bytes = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n").into_bytes();
    bytes.extend([128, 128, 128, 129]);
    std::fs::write(path, bytes).unwrap();
}

/// A named pipe at `path` (a reader opening it waits for a writer forever).
pub fn fifo(path: &Path) {
    let made = std::process::Command::new("mkfifo").arg(path).status().unwrap();
    assert!(made.success(), "mkfifo {}", path.display());
}
