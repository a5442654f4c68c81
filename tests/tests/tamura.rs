//! The Tamura–Johan–Nishita technique and Sloan's PRT on the real driver.
use glam::{Mat3, Mat4, Vec3};
use kage::backend::{vk, Binding, BindingKind, Buffer, ComputePipeline, Image, ImageDesc};
use kage::layouts::{bytes_of, bytes_of_slice, spirv, BlurPush, OcclusionLayer};
use kage::pass::{FrameExecutor, Pass};
use kage::renderer::{GpuScene, RenderOptions, Renderer, TechniqueChoice};
use kage::scene::animation::pose;
use kage::scene::Scene;
use kage::techniques::prt::{transfer, PrtParams, TransferSet};
use kage::techniques::tamura::occlusion::{group_bounds, Occlusion};
use kage::techniques::tamura::regions::Regions;
use kage::techniques::tamura::technique::{OcclusionSettings, Penumbra};
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

/// Runs the two 1D passes of the occlusion filter (mode 0: box of `width` texels; mode 1:
/// prefix sums) over one `size`² layer of (coverage, coverage × height) texels.
fn filter_layer(ctx: &Validated, size: u32, width: u32, mode: u32, texels: &[[f32; 2]]) -> Vec<[f32; 2]> {
    let image = |name: &str| {
        let usage = vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let desc = ImageDesc {
            name,
            width: size,
            height: size,
            layers: 1,
            array: true,
            format: vk::Format::R32G32_SFLOAT,
            usage,
        };
        Image::new(ctx, &desc).unwrap()
    };
    let (mask, temp, filtered) = (image("mask"), image("temp"), image("filtered"));
    mask.upload(&texels.iter().flatten().flat_map(|t| t.to_ne_bytes()).collect::<Vec<u8>>()).unwrap();
    let layer = OcclusionLayer { axis_u: [1.0, 0.0, 0.0, width as f32], ..Default::default() };
    let layers =
        Buffer::with_data(ctx, "layers", vk::BufferUsageFlags::STORAGE_BUFFER, bytes_of_slice(&[layer]))
            .unwrap();
    let kinds = [BindingKind::StorageBuffer, BindingKind::StorageImage, BindingKind::StorageImage];
    let blur = ComputePipeline::new(
        ctx,
        "occlusion_blur",
        spirv::OCCLUSION_BLUR_COMP,
        &kinds,
        size_of::<BlurPush>() as u32,
    )
    .unwrap();
    let filter = |cmd, direction: u32, from: &Image, to: &Image| {
        let push = BlurPush { params: [direction, size, 1, mode] };
        let bindings = [Binding::Storage(&layers), Binding::StorageImage(from), Binding::StorageImage(to)];
        blur.dispatch(cmd, &bindings, bytes_of(&push), [1, 1, 1])
    };
    let mut executor = FrameExecutor::new(ctx, "filter").unwrap();
    let passes = vec![
        Pass::new("horizontal", &[], &["half"], |cmd| filter(cmd, 0, &mask, &temp)),
        Pass::new("vertical", &["half"], &[], |cmd| filter(cmd, 1, &temp, &filtered)),
    ];
    executor.run(&[], passes).unwrap();
    let floats: Vec<f32> = filtered
        .read()
        .unwrap()
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    floats.chunks_exact(2).map(|c| [c[0], c[1]]).collect()
}

/// The paper's filter on one texel: a w×w box of 1/w² in both channels (sliding sums of zeros
/// and one value are exact; rounding only in the final scale).
#[test]
fn box_filter_of_a_point_is_a_box() {
    let ctx = Validated::new();
    let (size, width) = (16u32, 5u32);
    let mut texels = vec![[0.0f32; 2]; (size * size) as usize];
    texels[(7 * size + 9) as usize] = [1.0, 2.5];
    let out = filter_layer(&ctx, size, width, 0, &texels);
    let scale = 1.0f32 / (width * width) as f32;
    for (i, got) in out.iter().enumerate() {
        let (x, y) = (i as i32 % size as i32, i as i32 / size as i32);
        let inside = (x - 9).abs() <= 2 && (y - 7).abs() <= 2;
        let expected = if inside { [scale, 2.5 * scale] } else { [0.0, 0.0] };
        assert!(
            (got[0] - expected[0]).abs() < 1e-7 && (got[1] - expected[1]).abs() < 1e-6,
            "({x}, {y}): {got:?}"
        );
    }
}

/// The adaptive penumbra's prefix-sum mode: the two passes leave the summed-area table, checked
/// exactly (small integers sum without rounding in f32).
#[test]
fn prefix_passes_build_the_summed_area_table() {
    let ctx = Validated::new();
    let size = 16u32;
    let texels: Vec<[f32; 2]> = (0..size * size).map(|i| [(i % 3) as f32, ((i * 7) % 5) as f32]).collect();
    let out = filter_layer(&ctx, size, 1, 1, &texels);
    for y in 0..size {
        for x in 0..size {
            let mut expected = [0.0f32; 2];
            for j in 0..=y {
                for i in 0..=x {
                    let t = texels[(j * size + i) as usize];
                    expected[0] += t[0];
                    expected[1] += t[1];
                }
            }
            assert_eq!(out[(y * size + x) as usize], expected, "({x}, {y})");
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

/// More layers than fit: five teapots in a row on the floor ask for more (receiver, occluder,
/// region) layers than the 192 kept. The renderer says how many it left out, and the picture
/// stays finite and non-negative (the dropped regions are merely unshadowed between groups).
#[test]
fn layers_beyond_the_budget_are_dropped_and_counted() {
    let ctx = Validated::new();
    let mut scene = Scene::builtin("teapot").unwrap();
    let teapot = scene.groups[0].clone();
    for (i, x) in [-4.0f32, -2.0, 2.0, 4.0].into_iter().enumerate() {
        let mut copy = teapot.clone();
        copy.name = format!("teapot-{i}");
        copy.transform.translation.x += x;
        scene.groups.push(copy);
    }
    let transfer = transfer_of(&ctx, &scene);
    let mut renderer =
        Renderer::new(&ctx, &scene, &RenderOptions { width: 48, height: 48, technique: prt(&transfer, 32) })
            .unwrap();
    renderer.render().unwrap();
    let dropped = renderer.dropped_layers();
    println!("{dropped} layers dropped");
    assert!(dropped > 0, "five teapots at q = 32 should exceed the layer budget");
    let image = renderer.image().unwrap();
    assert!(image.pixels.iter().all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
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

/// The scene pass reads a layer only where a receiver point projects within the layer's
/// footprint (a circle around the occluder's centre: its bounding sphere, the box's half width
/// and one texel for bilinear reads). That skip is exact only if every texel a read outside the
/// circle can touch is 0: checked texel by texel on every layer of the default scene at four
/// poses of the animation (the teapot standing, sliding, hopping, turned). Texels whose centre
/// is within one texel of the circle may be touched from inside and are not checked. "0" up to
/// the rounding of the filter's running sums: a sum of at most 128 values ≤ 1, each addition
/// and removal off by half an ulp, stays within 128 ε of the exact zero.
#[test]
fn filtered_layers_are_zero_outside_their_footprint() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    let size = 128;
    let regions = Regions::new(&scene.environment, 32).unwrap();
    let mut occlusion =
        Occlusion::new(&ctx, regions, 3, group_bounds(&scene), size, 64, Penumbra::Fixed).unwrap();
    let mut executor = FrameExecutor::new(&ctx, "footprint").unwrap();
    let mut checked = 0usize;
    for t in [0.0, 0.1, 0.3, 0.6] {
        let mut transforms: Vec<Mat4> = scene.groups.iter().map(|g| g.transform.matrix()).collect();
        transforms[0] = pose(&scene.groups[0], t).matrix();
        occlusion.update(&transforms, Mat3::IDENTITY).unwrap();
        let layers = occlusion.layers_in_use().to_vec();
        assert!(!layers.is_empty(), "pose {t}: no occlusion layer");
        let mut moved = GpuScene::new(&ctx, &scene).unwrap();
        moved.transforms = transforms;
        executor.run(&[], occlusion.passes(&ctx, &moved)).unwrap();
        let texels = occlusion.filtered.read().unwrap();
        let layer_bytes = (size * size * 8) as usize;
        for (l, layer) in layers.iter().enumerate() {
            let [cx, cy, reach, _] = layer.footprint;
            for y in 0..size {
                for x in 0..size {
                    let (u, v) = ((x as f32 + 0.5) / size as f32, (y as f32 + 0.5) / size as f32);
                    let distance = ((u - cx).powi(2) + (v - cy).powi(2)).sqrt();
                    if distance <= reach + 1.0 / size as f32 {
                        continue;
                    }
                    let at = l * layer_bytes + ((y * size + x) * 8) as usize;
                    let value = f32::from_ne_bytes(texels[at..at + 4].try_into().unwrap());
                    assert!(
                        value.abs() <= size as f32 * f32::EPSILON,
                        "pose {t}, layer {l}, texel ({x}, {y}): {value} outside the footprint"
                    );
                    checked += 1;
                }
            }
        }
    }
    println!("{checked} texels outside footprints checked");
}
