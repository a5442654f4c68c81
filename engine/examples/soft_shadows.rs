//! The engine from Rust in one page: renders the default scene with Tamura's soft shadows and
//! writes soft_shadows.png. `cargo run --release -p kage --example soft_shadows`
//! (`cargo test` builds it, so it cannot fall behind the API).
use kage::backend::{Context, ContextDesc};
use kage::prt::{transfer, PrtParams};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::Scene;
use kage::techniques::description::TechniqueDesc;
use kage::techniques::tamura::technique::OcclusionSettings;
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Validation on reports every Vulkan usage error (it needs the validation layers).
    let ctx = Context::new(&ContextDesc { validation: false, device: None })?;
    let scene = Scene::builtin("teapot")?;
    // Each vertex's self-shadowed transfer, computed on the device once (`kage precompute`
    // caches it on disk; `kage::prt::cache` reads and writes that cache).
    let prt = PrtParams::DEFAULT;
    let transfer = transfer::precompute(&ctx, &scene, prt, &mut |done, total| {
        eprint!("\rtransfer: {done} of {total} vertices");
        true // go on
    })?;
    eprintln!();
    let technique = TechniqueDesc::Tamura { prt, occlusion: OcclusionSettings::default() };
    let options = RenderOptions { width: 512, height: 512, technique, transfer: Some(Arc::new(transfer)) };
    let mut renderer = Renderer::new(&ctx, &scene, &options)?;
    // Move the teapot (group 0) up a little; each frame returns its passes' GPU times.
    renderer.set_group_transform(
        0,
        glam::Mat4::from_translation(glam::Vec3::new(0.0, 0.2, 0.0)) * scene.groups[0].transform.matrix(),
    )?;
    for pass in renderer.render()? {
        println!("{:<16} {:?} ms", pass.name, pass.gpu_ms);
    }
    kage::imageio::write("soft_shadows.png", &renderer.image()?, 1.0)?;
    Ok(())
}
