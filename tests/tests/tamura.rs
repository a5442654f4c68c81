//! The Tamura–Johan–Nishita technique and Sloan's PRT on the real driver.
use glam::Vec3;
use kage::backend::{vk, Binding, BindingKind, Buffer, ComputePipeline, Image, ImageDesc};
use kage::layouts::{bytes_of, bytes_of_slice, spirv, BlurPush, OcclusionLayer};
use kage::pass::{FrameExecutor, Pass};
use kage::renderer::{RenderOptions, Renderer, TechniqueChoice};
use kage::scene::Scene;
use kage::techniques::prt::{transfer, PrtParams, TransferSet};
use kage::techniques::tamura::technique::OcclusionSettings;
use kage_tests::Validated;
use std::sync::Arc;

/// Few rays: these tests look at where shadows fall, not at the transfer's last digits.
fn transfer_of(ctx: &Validated, scene: &Scene) -> Arc<TransferSet> {
    Arc::new(transfer::precompute(ctx, scene, PrtParams { bands: 3, rays: 128 }, &mut |_, _| {}).unwrap())
}

fn prt(transfer: &Arc<TransferSet>, regions: usize) -> TechniqueChoice {
    TechniqueChoice::Prt {
        transfer: transfer.clone(),
        occlusion: OcclusionSettings { regions, ..Default::default() },
    }
}

/// The two 1D passes of the box filter on one texel: the result is a w×w box of 1/w², exactly
/// what sliding sums of zeros and a single one give (rounding only in the final scale).
#[test]
fn box_filter_of_a_point_is_a_box() {
    let ctx = Validated::new();
    let (size, width) = (16u32, 5u32);
    let image = |name: &str| {
        Image::new(
            &ctx,
            &ImageDesc {
                name,
                width: size,
                height: size,
                layers: 1,
                array: true,
                format: vk::Format::R32_SFLOAT,
                usage: vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::TRANSFER_DST
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            },
        )
        .unwrap()
    };
    let (mask, temp, filtered) = (image("mask"), image("temp"), image("filtered"));
    let mut texels = vec![0.0f32; (size * size) as usize];
    texels[(7 * size + 9) as usize] = 1.0;
    mask.upload(&texels.iter().flat_map(|t| t.to_ne_bytes()).collect::<Vec<u8>>()).unwrap();
    let layer = OcclusionLayer { axis_u: [1.0, 0.0, 0.0, width as f32], ..Default::default() };
    let layers =
        Buffer::with_data(&ctx, "layers", vk::BufferUsageFlags::STORAGE_BUFFER, bytes_of_slice(&[layer]))
            .unwrap();
    let blur = ComputePipeline::new(
        &ctx,
        "occlusion_blur",
        spirv::OCCLUSION_BLUR_COMP,
        &[BindingKind::StorageBuffer, BindingKind::StorageImage, BindingKind::StorageImage],
        size_of::<BlurPush>() as u32,
    )
    .unwrap();
    let mut executor = FrameExecutor::new(&ctx, "blur").unwrap();
    let filter = |cmd, direction: u32, from: &Image, to: &Image| {
        let push = BlurPush { params: [direction, size, 1, 0] };
        let bindings = [Binding::Storage(&layers), Binding::StorageImage(from), Binding::StorageImage(to)];
        blur.dispatch(cmd, &bindings, bytes_of(&push), [1, 1, 1])
    };
    executor
        .run(
            &[],
            vec![
                Pass::new("horizontal", &[], &["half"], |cmd| filter(cmd, 0, &mask, &temp)),
                Pass::new("vertical", &["half"], &[], |cmd| filter(cmd, 1, &temp, &filtered)),
            ],
        )
        .unwrap();
    let out: Vec<f32> = filtered
        .read()
        .unwrap()
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let scale = 1.0f32 / width as f32;
    for y in 0..size {
        for x in 0..size {
            let inside = (x as i32 - 9).abs() <= 2 && (y as i32 - 7).abs() <= 2;
            let expected = if inside { scale * scale } else { 0.0 };
            assert!(
                (out[(y * size + x) as usize] - expected).abs() < 1e-7,
                "({x}, {y}): {}",
                out[(y * size + x) as usize]
            );
        }
    }
}

/// A group alone casts on nobody: the technique must not run any occlusion pass, and with no
/// other group its picture is Sloan's exactly.
#[test]
fn a_group_alone_runs_no_occlusion_pass() {
    let ctx = Validated::new();
    let mut scene = Scene::builtin("teapot").unwrap();
    scene.groups.truncate(1);
    let transfer = transfer_of(&ctx, &scene);
    let mut tamura =
        Renderer::new(&ctx, &scene, &RenderOptions { width: 48, height: 48, technique: prt(&transfer, 32) })
            .unwrap();
    let names: Vec<&str> = tamura.render().unwrap().iter().map(|t| t.name).collect();
    assert!(!names.iter().any(|n| n.contains("mask") || n.contains("blur")), "{names:?}");
    let mut sloan =
        Renderer::new(&ctx, &scene, &RenderOptions { width: 48, height: 48, technique: prt(&transfer, 0) })
            .unwrap();
    sloan.render().unwrap();
    assert!(tamura.image().unwrap().pixels == sloan.image().unwrap().pixels);
}

fn luminance(p: [f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// The teapot's contact shadow: the floor right beside the teapot's base is darker with Tamura's
/// other-group occlusion than with Sloan's PRT (which has none), and no pixel goes negative.
/// Pixels found by projecting world points with the scene's camera. (How far the shadow reaches
/// is measured against the reference in BENCHMARKS.md, not asserted here.)
#[test]
fn the_teapot_casts_a_contact_shadow_on_the_floor() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    let transfer = transfer_of(&ctx, &scene);
    let size = 96;
    let render = |regions| {
        let options = RenderOptions { width: size, height: size, technique: prt(&transfer, regions) };
        let mut r = Renderer::new(&ctx, &scene, &options).unwrap();
        r.render().unwrap();
        r.image().unwrap()
    };
    let (sloan, tamura) = (render(0), render(32));
    let view_proj = scene.camera.projection(1.0) * scene.camera.view();
    let pixel = |world: Vec3| {
        let clip = view_proj * world.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let (x, y) = (((ndc.x + 1.0) * 0.5 * size as f32) as u32, ((ndc.y + 1.0) * 0.5 * size as f32) as u32);
        (y * size + x) as usize
    };
    let near = pixel(Vec3::new(0.0, 0.0, 0.5));
    assert!(luminance(tamura.pixels[near]) < 0.9 * luminance(sloan.pixels[near]), "no contact shadow");
    assert!(tamura.pixels.iter().all(|p| p[..3].iter().all(|c| *c >= 0.0 && c.is_finite())));
}
