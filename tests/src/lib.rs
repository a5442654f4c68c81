//! Helpers shared by Kage's integration tests: a validated context that fails the test on any
//! validation message, small scenes built in code, and scratch folders.
use kage::backend::{Context, ContextDesc};
use kage::scene::{Camera, EnvMap, Group, Mesh, Scene, Transform};
use std::path::PathBuf;
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
    Scene {
        name: "test".into(),
        groups: vec![Group { name: "object".into(), meshes: vec![mesh], transform: Transform::default() }],
        environment,
        lights: vec![],
        walkthrough: vec![],
        probes: Vec::new(),
        camera,
    }
}

/// A fresh, empty folder under the system temp folder, unique per test.
pub fn scratch_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("kage-tests-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp folder");
    dir
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
    Arc::new(transfer::precompute(ctx, scene, params, &mut |_, _| {}).expect("transfer"))
}
