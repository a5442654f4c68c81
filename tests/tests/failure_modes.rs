//! The failure-mode suite across the engine: each case feeds the engine something
//! hostile and asserts its documented behaviour, either a clear error naming what is wrong or a
//! finite picture, never a panic, a hang, a validation message or a silently wrong picture.
//!
//! Already covered elsewhere and not repeated here: scene files with NaN/∞ map texels, OBJ files
//! with no faces and `Mesh::new` without triangles (tests/scene_input.rs, scene::mesh's unit
//! tests); NULL handles, double destroys and most bad enumerations of the C ABI
//! (tests/c_host/arrays.c); Tamura's physical failure modes (tests/tamura_failures.rs).
//!
//! Costs: images of 16² or less, PRT at 16 rays per vertex and q = 4 (the cases look at
//! finiteness and error paths, not at accuracy), probes 2×2×2 with 8² cube faces.
use glam::{Mat4, Quat, Vec3};
use kage::backend::{Buffer, BufferDesc, BufferUsage, Context, MemoryLocation};
use kage::capi::{self, kage_result};
use kage::frame::MAX_SIZE;
use kage::imageio::RgbaF32Image;
use kage::layouts::{constants, CastRay};
use kage::prt::{transfer, PrtParams};
use kage::raycast::{closest_hit_brute_force, GpuBvh, GpuRays, Query, RayCaster, SceneBvh};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::envmap::MAX_RADIANCE;
use kage::scene::{shapes, Camera, EnvMap, Group, Light, Mesh, Scene, Transform};
use kage::techniques::description::{TechniqueDesc, TechniqueKind};
use kage::techniques::tamura::technique::OcclusionSettings;
use kage::Error;
use kage_tests::{every_technique, scratch_dir, Validated};
use std::ffi::c_char;
use std::ptr::{null, null_mut};
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// Scenes and techniques shared by the cases.

fn camera() -> Camera {
    Camera {
        position: Vec3::new(0.0, 2.0, 4.0),
        target: Vec3::new(0.0, 0.3, 0.0),
        up: Vec3::Y,
        fov_y_deg: 45.0,
    }
}

/// A spot light over the origin, for the shadowmap technique (the others ignore it).
fn spot() -> Light {
    Light::Spot {
        position: Vec3::new(0.0, 3.0, 0.0),
        direction: Vec3::NEG_Y,
        fov_deg: 90.0,
        intensity: [5.0; 3],
    }
}

fn scene(groups: Vec<Group>) -> Scene {
    Scene { lights: vec![spot()], ..Scene::new("failure", groups, EnvMap::constant([1.0; 3]), camera()) }
}

fn group(name: &str, meshes: Vec<Mesh>, translation: Vec3) -> Group {
    Group::new(name, meshes, Transform { translation, ..Transform::default() })
}

/// The static group: a floor and a box on it, so that the probe grid over it is 3D.
fn room() -> Group {
    let floor = shapes::plane("floor", [4.0, 4.0], [5, 5], [0.6; 3]).unwrap();
    let block = shapes::boxes("block", &[([1.2, 0.0, -1.2], [1.6, 0.8, -0.8])], [0.5; 3]).unwrap();
    group("room", vec![floor, block], Vec3::ZERO)
}

/// A quad drawn as two triangles that share no vertex (its diagonal's two vertices are there
/// twice), a triangle whose three corners are one point, a triangle on a line, and a triangle
/// that names one vertex twice. All at y = 0.2 to 0.6 above the origin.
fn degenerate_mesh() -> Mesh {
    let positions = vec![
        [-0.5, 0.2, -0.5],
        [-0.5, 0.2, 0.5],
        [0.5, 0.2, 0.5],
        [-0.5, 0.2, -0.5],
        [0.5, 0.2, 0.5],
        [0.5, 0.2, -0.5],
        [0.0, 0.6, 0.0],
        [0.0, 0.6, 0.0],
        [0.0, 0.6, 0.0],
        [-0.3, 0.4, 0.0],
        [0.0, 0.4, 0.0],
        [0.3, 0.4, 0.0],
    ];
    let indices = vec![0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0, 0, 1];
    Mesh::new("degenerate", positions, None, indices, [0.7; 3]).unwrap()
}

fn render(ctx: &Arc<Context>, scene: &Scene, options: RenderOptions) -> RgbaF32Image {
    let mut renderer = Renderer::new(ctx, scene, &options).unwrap();
    renderer.render().unwrap();
    renderer.image().unwrap()
}

#[track_caller]
fn assert_finite(image: &RgbaF32Image, what: &str) {
    if let Some((i, p)) =
        image.pixels.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite() && *c >= 0.0))
    {
        panic!("{what}: pixel {i} of {}x{} is {p:?}", image.width, image.height);
    }
}

/// Renders `scene` with every technique at `size`² and checks that each picture is finite.
fn every_technique_renders(ctx: &Arc<Context>, scene: &Scene, size: u32) {
    for (kind, options) in every_technique(ctx, scene) {
        let options = RenderOptions { width: size, height: size, ..options };
        assert_finite(&render(ctx, scene, options), &format!("{} with {kind:?}", scene.name));
    }
}

#[track_caller]
fn assert_error_says(result: Result<impl Sized, impl std::fmt::Display>, parts: &[&str]) {
    let message = match result {
        Ok(_) => panic!("succeeded, but should fail naming {parts:?}"),
        Err(e) => e.to_string(),
    };
    for part in parts {
        assert!(message.contains(part), "{message:?} does not say {part:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// Environment maps.

/// NaN, ±∞ and radiance beyond `MAX_RADIANCE` are refused in memory (the file paths are in
/// scene_input.rs), naming the texel; so is an intensity that scales a finite map past it, from
/// code and from a scene file. At the limit itself every technique still gives a finite
/// picture: the limit is what keeps their 32-bit sums finite (at 1e38 the unshadowed picture is
/// NaN).
#[test]
fn env_maps_with_nan_infinite_or_huge_texels_are_rejected_naming_the_texel() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e38] {
        let mut pixels = vec![[1.0f32; 3]; 8 * 4];
        pixels[2 * 8 + 3] = [1.0, bad, 1.0];
        assert_error_says(EnvMap::from_pixels(8, 4, pixels), &["pixel (3, 2)", &format!("{bad:?}")]);
    }
    // The OpenEXR decoder in memory (the path of a host that holds the file's bytes).
    let dir = scratch_dir("failure-env");
    let path = dir.join("nan.exr");
    exr::prelude::write_rgb_file(&path, 4, 2, |x, y| {
        if (x, y) == (1, 1) {
            (1.0, f32::NAN, 1.0)
        } else {
            (1.0, 1.0, 1.0)
        }
    })
    .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_error_says(EnvMap::from_exr_bytes(&bytes), &["pixel (1, 1)", "NaN"]);

    assert_error_says(
        EnvMap::constant([10.0; 3]).scaled(1e37),
        &["environment intensity", "pixel (0, 0)", "exceeds"],
    );
    let scene_file = dir.join("bright.json");
    std::fs::write(
        &scene_file,
        r#"{"camera": {"position": [0, 2, 6], "target": [0, 0, 0], "fov_y_deg": 40},
            "environment": {"constant": [10, 10, 10], "intensity": 1e38},
            "groups": [{"name": "g", "meshes": [{"sphere": {"radius": 1, "segments": 8}, "albedo": [0.5, 0.5, 0.5]}]}]}"#,
    )
    .unwrap();
    assert_error_says(Scene::load(&scene_file), &["bright.json", "pixel (0, 0)"]);

    let ctx = Validated::new();
    let mut scene = scene(vec![group("object", vec![degenerate_mesh()], Vec3::ZERO), room()]);
    scene.environment = EnvMap::constant([MAX_RADIANCE; 3]);
    every_technique_renders(&ctx, &scene, 8);

    // A valid but tiny map has fewer texels than regions to split it into: an error (the
    // region split used to loop forever looking for a texel for each region).
    scene.environment = EnvMap::from_pixels(4, 2, vec![[1.0; 3]; 8]).unwrap();
    let tamura =
        every_technique(&ctx, &scene).into_iter().find(|(kind, _)| *kind == TechniqueKind::Tamura).unwrap().1;
    let occlusion = OcclusionSettings { regions: 9, mask_size: 16, ..Default::default() };
    let prt = tamura.transfer.as_ref().unwrap().params;
    for technique in [
        TechniqueDesc::Tamura { prt, occlusion },
        TechniqueDesc::ParallelLights { regions: 9, shadow_map_size: 16 },
    ] {
        let options = RenderOptions { width: 8, height: 8, technique, ..tamura.clone() };
        assert_error_says(Renderer::new(&ctx, &scene, &options), &["q = 9", "4x2", "8"]);
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate geometry.

/// Zero-area triangles (a point, a line, a repeated index) and duplicated vertices: every
/// technique renders finite pixels, and rays through the degenerate triangles pass them and hit
/// the quad beneath, on the GPU BVH as by brute force (the watertight test gives a zero
/// determinant no hit; the quad's diagonal, between two triangles with separate vertices,
/// leaks no ray).
#[test]
fn degenerate_triangles_and_duplicate_vertices_render_and_cast() {
    let ctx = Validated::new();
    let scene = scene(vec![group("object", vec![degenerate_mesh()], Vec3::ZERO), room()]);
    every_technique_renders(&ctx, &scene, 16);

    // Straight down from y = 1 over a 9×9 grid of the quad, its diagonal and the degenerate
    // triangles' point (0, 0) included: every ray hits the quad (group 0) at t = 0.8.
    let origins: Vec<Vec3> =
        (0..81).map(|i| Vec3::new(-0.4 + 0.1 * (i % 9) as f32, 1.0, -0.4 + 0.1 * (i / 9) as f32)).collect();
    let rays: Vec<CastRay> = origins
        .iter()
        .map(|o| CastRay { origin: o.extend(1e30).to_array(), direction: [0.0, -1.0, 0.0, 0.0] })
        .collect();
    let bvh = GpuBvh::new(&ctx, &SceneBvh::build(&scene).unwrap()).unwrap();
    let gpu_rays = GpuRays::new(&ctx, &rays).unwrap();
    RayCaster::new(&ctx).unwrap().cast(&bvh, &gpu_rays, Query::ClosestHit).unwrap();
    for (origin, result) in origins.iter().zip(gpu_rays.read().unwrap()) {
        // 0.8 is 1.0 − 0.2 in f32: the hit distance is exact up to the test's rounding.
        assert_eq!(
            result.ids[0],
            0,
            "ray from {origin} hit instance {} (NO_HIT = {})",
            result.ids[0],
            constants::NO_HIT
        );
        assert!((result.hit[0] - 0.8).abs() < 1e-6, "ray from {origin}: t = {}", result.hit[0]);
        let (t, hit) = closest_hit_brute_force(&scene, *origin, Vec3::NEG_Y, 1e30).expect("brute force hits");
        assert!(
            hit.group == 0 && (t - 0.8).abs() < 1e-6,
            "brute force from {origin}: {t} on group {}",
            hit.group
        );
    }
}

/// A mesh with no triangles cannot be made by `Mesh::new` or loaded, but a mesh's fields are
/// public: one emptied (or given an index out of range) in code is an error naming the group and
/// mesh wherever the scene enters the engine (renderer, PRT precomputation, BVH), not a panic or
/// a misleading driver error. A group with no meshes, or no groups at all, is allowed in code
/// (`Scene::validate`): nothing is drawn and every pixel is the environment's radiance. The
/// probe technique needs a static group to place its grid in and says so.
#[test]
fn meshes_without_triangles_are_errors_and_empty_groups_draw_nothing() {
    let ctx = Validated::new();
    let mut hollow = degenerate_mesh();
    hollow.indices.clear();
    let empty_mesh = scene(vec![room(), group("hollow", vec![hollow], Vec3::ZERO)]);
    let expected = ["group 1 (\"hollow\")", "mesh 0", "no triangles"];
    assert_error_says(Renderer::new(&ctx, &empty_mesh, &RenderOptions::default()), &expected);
    assert_error_says(
        transfer::precompute(
            &ctx,
            &empty_mesh,
            PrtParams { bands: 3, rays: 16, ..PrtParams::DEFAULT },
            &mut kage::progress::silent,
        ),
        &expected,
    );
    assert_error_says(SceneBvh::build(&empty_mesh), &expected);

    let mut stray = degenerate_mesh();
    stray.indices[4] = 99;
    let stray_index = scene(vec![group("stray", vec![stray], Vec3::ZERO)]);
    assert_error_says(
        SceneBvh::build(&stray_index),
        &["group 0 (\"stray\")", "vertex index 99", "out of range"],
    );
    assert_error_says(Renderer::new(&ctx, &stray_index, &RenderOptions::default()), &["vertex index 99"]);

    let nothing = Group::new("nothing", vec![], Transform::default());
    for scene in [scene(vec![]), scene(vec![nothing.clone()]), scene(vec![nothing, room()])] {
        let groups = scene.groups.len();
        for (kind, options) in every_technique(&ctx, &scene) {
            let made = Renderer::new(&ctx, &scene, &RenderOptions { width: 8, height: 8, ..options });
            if kind == TechniqueKind::Probes && !scene.groups.iter().skip(1).any(|g| !g.meshes.is_empty()) {
                assert_error_says(made, &["no static group"]);
                continue;
            }
            let mut renderer = made.unwrap();
            renderer.render().unwrap();
            let image = renderer.image().unwrap();
            assert_finite(&image, &format!("{groups} group(s) with {kind:?}"));
            if scene.groups.iter().all(|g| g.meshes.is_empty()) {
                // The constant map of radiance 1, sampled anywhere.
                let off = image.pixels.iter().find(|p| p[..3].iter().any(|c| (c - 1.0).abs() > 1e-5));
                assert!(off.is_none(), "{groups} empty group(s) with {kind:?}: background pixel {off:?}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Many groups.

/// 200 groups: a static room and 199 small spheres in a 1.6-unit cluster. Tamura's pairwise
/// occlusion wants far more layers than the 192 (`KAGE_MAX_OCCLUSION_LAYERS`) a frame can hold:
/// the overflow is reported by `Renderer::dropped_layers`, never silently. Spread 5 units apart
/// most pairs are culled (their shadows cannot reach each other) and fewer layers are dropped;
/// not all of them, since under a constant sky the regions near the horizon do reach across
/// (the penumbra widens with distance as fast as the spacing grows, √Ω_i per unit).
/// Every other technique renders the crowd, and each frame reports its pass timings.
#[test]
fn two_hundred_groups_report_dropped_layers_and_render() {
    let ctx = Validated::new();
    let sphere = shapes::sphere("ball", 0.05, 4, [0.8; 3]).unwrap();
    let cluster = |i: usize| {
        Vec3::new(-0.8 + 0.2 * (i % 9) as f32, 0.3 + 0.2 * (i / 81) as f32, -0.8 + 0.2 * (i / 9 % 9) as f32)
    };
    let spread = |i: usize| Vec3::new(5.0 * (i % 15) as f32 - 35.0, 0.3, 5.0 * (i / 15) as f32 - 35.0);
    let mut groups: Vec<Group> =
        (0..199).map(|i| group(&format!("ball{i}"), vec![sphere.clone()], cluster(i))).collect();
    groups.insert(1, room());
    let scene = scene(groups);
    assert_eq!(scene.groups.len(), 200);
    // Ball i is group i, or i + 1 past the room.
    let ball_groups = (0..200).filter(|g| *g != 1);

    for (kind, options) in every_technique(&ctx, &scene) {
        let start = std::time::Instant::now();
        let mut renderer =
            Renderer::new(&ctx, &scene, &RenderOptions { width: 16, height: 16, ..options }).unwrap();
        let timings = renderer.render().unwrap();
        assert!(
            !timings.is_empty()
                && timings.iter().all(|t| t.gpu_ms.is_none_or(|ms| ms.is_finite() && ms >= 0.0))
        );
        assert_finite(&renderer.image().unwrap(), &format!("200 groups with {kind:?}"));
        let dropped = renderer.stats().dropped_layers;
        if kind == TechniqueKind::Tamura {
            assert!(dropped > 0, "the crowd fits {} layers?", constants::MAX_OCCLUSION_LAYERS);
            for (i, g) in ball_groups.clone().enumerate() {
                renderer.set_group_transform(g, Mat4::from_translation(spread(i))).unwrap();
            }
            renderer.render().unwrap();
            let spread_dropped = renderer.stats().dropped_layers;
            println!(
                "200 groups, tamura: {dropped} layers dropped in a cluster, {spread_dropped} spread out"
            );
            assert!(
                spread_dropped < dropped,
                "spread out, fewer pairs should reach each other: {spread_dropped}"
            );
            assert_finite(&renderer.image().unwrap(), "200 spread groups with tamura");
        } else if kind != TechniqueKind::TamuraPaper {
            assert_eq!(dropped, 0, "{kind:?} has no layers to drop");
        }
        println!(
            "200 groups, {kind:?}: {dropped} layers dropped, set-up and frames {:.2} s",
            start.elapsed().as_secs_f64()
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Image sizes.

/// 1×1 renders finite pixels with every technique. The largest side, `MAX_SIZE`, renders (as
/// 8192×1 and 1×8192: the full 8192² frame takes about 20 s on lavapipe, see
/// `the_largest_image_renders`), and an 8192² renderer is created (its targets allocated:
/// 1 GiB colour, 1 GiB readback, 256 MiB depth). 0 and `MAX_SIZE` + 1 are errors naming the
/// size and the limit.
#[test]
fn one_pixel_and_the_largest_sizes_render_and_beyond_is_an_error() {
    let ctx = Validated::new();
    let scene = scene(vec![group("object", vec![degenerate_mesh()], Vec3::ZERO), room()]);
    every_technique_renders(&ctx, &scene, 1);
    for (width, height) in [(MAX_SIZE, 1), (1, MAX_SIZE)] {
        let image = render(&ctx, &scene, RenderOptions { width, height, ..Default::default() });
        assert_eq!(image.pixels.len(), MAX_SIZE as usize);
        assert_finite(&image, &format!("{width}x{height}"));
    }
    let largest = RenderOptions {
        width: MAX_SIZE,
        height: MAX_SIZE,
        technique: TechniqueDesc::Unshadowed,
        transfer: None,
    };
    drop(Renderer::new(&ctx, &scene, &largest).unwrap());
    for (width, height) in [(MAX_SIZE + 1, 1), (1, MAX_SIZE + 1), (0, 16)] {
        let options = RenderOptions { width, height, technique: TechniqueDesc::Unshadowed, transfer: None };
        assert_error_says(
            Renderer::new(&ctx, &scene, &options),
            &[&format!("{width}x{height}"), "1 to 8192"],
        );
    }
}

/// The full 8192² frame (about 20 s and 4.5 GB of host memory on lavapipe, hence ignored; run
/// by hand, result in vendor-notes.md).
#[test]
#[ignore]
fn the_largest_image_renders() {
    let ctx = Validated::new();
    let scene = scene(vec![group("object", vec![degenerate_mesh()], Vec3::ZERO), room()]);
    let start = std::time::Instant::now();
    let image =
        render(&ctx, &scene, RenderOptions { width: MAX_SIZE, height: MAX_SIZE, ..Default::default() });
    println!("8192² unshadowed frame and readback: {:.1} s", start.elapsed().as_secs_f64());
    assert_finite(&image, "8192²");
}

// ---------------------------------------------------------------------------------------------
// Out of memory and device loss.

fn is_out_of_memory(e: &Error) -> bool {
    matches!(
        e,
        Error::OutOfDeviceMemory { .. } | Error::OutOfHostMemory { .. } | Error::OutOfDeviceMemoryFor { .. }
    )
}

fn on_lavapipe(ctx: &Context) -> bool {
    ctx.info().name.contains("llvmpipe")
}

/// Requests that cannot fit are out-of-memory errors, with no validation message (which a
/// request beyond the device's limits used to cause) and no abort: a 1 TiB buffer; Tamura's
/// occlusion masks at 2048² × 128 layers (4 GiB per image: beyond lavapipe's largest image of
/// 4 GiB − 1, `maxResourceSize`; a GPU with more may create it); and the same through the C ABI,
/// as `KAGE_RESULT_OUT_OF_MEMORY`. The context is usable afterwards.
#[test]
fn requests_that_cannot_fit_are_out_of_memory_errors() {
    let ctx = Validated::new();
    let huge = BufferDesc {
        name: "huge",
        size: 1 << 40,
        usage: BufferUsage::STORAGE,
        location: MemoryLocation::GpuOnly,
    };
    let error = Buffer::new(&ctx, &huge).err().expect("a 1 TiB buffer");
    assert!(is_out_of_memory(&error), "{error}");

    let scene = scene(vec![group("object", vec![degenerate_mesh()], Vec3::ZERO), room()]);
    let transfer = Arc::new(
        transfer::precompute(
            &ctx,
            &scene,
            PrtParams { bands: 3, rays: 16, ..PrtParams::DEFAULT },
            &mut kage::progress::silent,
        )
        .unwrap(),
    );
    let occlusion = OcclusionSettings { regions: 64, mask_size: 2048, ..Default::default() };
    let technique = TechniqueDesc::Tamura { prt: transfer.params, occlusion };
    match Renderer::new(
        &ctx,
        &scene,
        &RenderOptions { width: 16, height: 16, technique, transfer: Some(transfer) },
    ) {
        Err(e) => {
            assert!(is_out_of_memory(&e), "{e}");
            assert!(e.to_string().contains("occlusion.mask"), "{e}");
        }
        Ok(_) => assert!(!on_lavapipe(&ctx), "lavapipe created an image beyond its maxResourceSize"),
    }
    every_technique_renders(&ctx, &scene, 4);

    // The C ABI: the same masks, KAGE_RESULT_OUT_OF_MEMORY (not KAGE_RESULT_VALIDATION).
    let c = CHost::new();
    let mut technique = c.technique(2);
    technique.regions = 64;
    technique.mask_size = 2048;
    // SAFETY: live handles and a valid desc.
    assert_eq!(unsafe { capi::technique::kage_precompute(c.context, c.scene, &technique) }, kage_result::Ok);
    let desc = capi::renderer::kage_renderer_desc {
        size: size_of::<capi::renderer::kage_renderer_desc>() as u32,
        width: 16,
        height: 16,
        technique,
    };
    let mut renderer = null_mut();
    // SAFETY: as above; `renderer` is writable.
    let code = unsafe { capi::renderer::kage_renderer_create(c.context, c.scene, &desc, &mut renderer) };
    if on_lavapipe(&ctx) {
        assert_eq!(code, kage_result::OutOfMemory, "{}", last_error());
        assert!(last_error().contains("occlusion.mask"), "{}", last_error());
    }
    capi::renderer::kage_renderer_destroy(renderer);
}

// ---------------------------------------------------------------------------------------------
// Long runs.

/// Resident set size of this process, bytes.
fn rss_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").expect("/proc/self/statm");
    let pages: u64 = statm.split_whitespace().nth(1).and_then(|p| p.parse().ok()).expect("resident pages");
    pages * 4096
}

/// Renders `frames` animated frames at 16² with the unshadowed and the shadowmap technique and
/// checks that memory stays flat: device memory (`Context::allocated_bytes`) exactly, resident
/// host memory within `RSS_SLACK` after a warm-up of 1,000 frames (allocator pools and the
/// validation layer's first-use tables settle there). A leak of one 16² readback per frame
/// (4 KiB) would add 12 MiB in 3,000 frames, three times the slack. The resident size is the
/// whole process's, so this runs only in a process of its own (`in_a_process_of_its_own`).
fn memory_stays_flat(frames: usize) {
    const RSS_SLACK: u64 = 4 << 20;
    const WARM_UP: usize = 1000;
    let ctx = Validated::new();
    let scene = scene(vec![group("object", vec![degenerate_mesh()], Vec3::ZERO), room()]);
    for (name, technique) in
        [("unshadowed", TechniqueDesc::Unshadowed), ("shadowmap", TechniqueDesc::ShadowMap { size: 16 })]
    {
        let mut renderer =
            Renderer::new(&ctx, &scene, &RenderOptions { width: 16, height: 16, technique, transfer: None })
                .unwrap();
        let mut frame = |i: usize| {
            let turn = Quat::from_rotation_y(i as f32 * 0.01);
            renderer.set_group_transform(0, Mat4::from_rotation_translation(turn, Vec3::ZERO)).unwrap();
            renderer.render().unwrap();
        };
        (0..WARM_UP).for_each(&mut frame);
        let (device, rss) = (ctx.allocated_bytes(), rss_bytes());
        let start = std::time::Instant::now();
        (WARM_UP..WARM_UP + frames).for_each(&mut frame);
        let seconds = start.elapsed().as_secs_f64();
        let (device_after, rss_after) = (ctx.allocated_bytes(), rss_bytes());
        println!(
            "{name}: {frames} frames in {seconds:.1} s ({:.2} ms each); device memory {device} -> {device_after} bytes, \
             RSS {:.1} -> {:.1} MiB",
            1e3 * seconds / frames as f64,
            rss as f64 / 1048576.0,
            rss_after as f64 / 1048576.0
        );
        assert_eq!(device_after, device, "{name}: device memory grew over {frames} frames");
        assert!(
            rss_after <= rss + RSS_SLACK,
            "{name}: RSS grew by {} bytes over {frames} frames",
            rss_after - rss
        );
        assert_finite(&renderer.image().unwrap(), name);
    }
}

/// The variable that tells `memory_flat_in_this_process` how many frames to measure.
const FRAMES_VAR: &str = "KAGE_TEST_MEMORY_FRAMES";

/// Runs `memory_flat_in_this_process` for `frames` frames in a child process (this test binary
/// again, with that one test), so the resident size it measures holds no other test's memory:
/// the other cases of this binary run in parallel threads here. While the child measures, this
/// process allocates and touches up to 64 MiB (16× the slack) that the child must not see.
fn in_a_process_of_its_own(frames: usize) {
    let exe = std::env::current_exe().expect("the test binary's path");
    let child = std::process::Command::new(exe)
        .args(["--exact", "memory_flat_in_this_process", "--ignored", "--nocapture", "--test-threads=1"])
        .env(FRAMES_VAR, frames.to_string())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the child test process");
    let waiter = std::thread::spawn(move || child.wait_with_output());
    // 2 MiB more every half second, touched, up to 64 MiB: allocations made while the child
    // measures, as a parallel test's would be.
    let mut ballast: Vec<Vec<u8>> = Vec::new();
    while !waiter.is_finished() {
        if ballast.len() < 32 {
            ballast.push(vec![1u8; 2 << 20]);
        }
        std::thread::sleep(std::time::Duration::from_millis(500));
    }
    let output = waiter.join().expect("the waiting thread").expect("the child test's output");
    println!("this process held {} MiB of ballast while the child measured", 2 * ballast.len());
    let text =
        String::from_utf8_lossy(&output.stdout).into_owned() + &String::from_utf8_lossy(&output.stderr);
    println!("{text}");
    assert!(output.status.success(), "the memory measurement failed in its own process:\n{text}");
    assert!(text.contains("1 passed"), "the child process ran no measurement:\n{text}");
}

/// 3,000 frames per technique fit the test budget (about 1.1 and 1.6 ms a frame on lavapipe);
/// the 10,000 of the issue are `ten_thousand_frames_keep_memory_flat`.
#[test]
fn thousands_of_frames_keep_memory_flat() {
    in_a_process_of_its_own(3_000);
}

/// The issue's 10,000 frames (about 30 s on lavapipe, hence ignored; result in vendor-notes.md).
#[test]
#[ignore]
fn ten_thousand_frames_keep_memory_flat() {
    in_a_process_of_its_own(10_000);
}

/// The measurement itself, run by the two tests above in a child process; run by hand it
/// measures 3,000 frames in whatever process runs it.
#[test]
#[ignore = "run in a child process by thousands_of_frames_keep_memory_flat"]
fn memory_flat_in_this_process() {
    let frames = std::env::var(FRAMES_VAR).ok().and_then(|f| f.parse().ok()).unwrap_or(3_000);
    memory_stays_flat(frames);
}

// ---------------------------------------------------------------------------------------------
// The C ABI.

/// A validated context and a one-triangle scene made through the C ABI.
struct CHost {
    context: *mut capi::context::kage_context,
    scene: *mut capi::scene::kage_scene,
}

const TRIANGLE: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0];
const INDICES: [u32; 3] = [0, 1, 2];

/// Sky texels along each side: 128 texels, enough for Tamura's 64 regions.
const SKY: (u32, u32) = (16, 8);

fn scene_desc(
    mesh: &capi::scene::kage_mesh_desc,
    groups: &mut [capi::scene::kage_group_desc; 2],
    sky: &[f32],
) -> capi::scene::kage_scene_desc {
    assert_eq!(sky.len(), 3 * (SKY.0 * SKY.1) as usize);
    for group in groups.iter_mut() {
        group.meshes = mesh;
    }
    capi::scene::kage_scene_desc {
        size: size_of::<capi::scene::kage_scene_desc>() as u32,
        groups: groups.as_ptr(),
        group_count: 2,
        environment: capi::scene::kage_environment_desc { pixels: sky.as_ptr(), width: SKY.0, height: SKY.1 },
        camera: capi::scene::kage_camera_desc {
            position: [0.0, 1.0, 2.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 60.0,
        },
        lights: std::ptr::null(),
        light_count: 0,
    }
}

fn triangle_mesh() -> capi::scene::kage_mesh_desc {
    capi::scene::kage_mesh_desc {
        positions: TRIANGLE.as_ptr(),
        normals: null(),
        vertex_count: 3,
        indices: INDICES.as_ptr(),
        index_count: 3,
        albedo: [0.5; 3],
    }
}

/// The triangle twice, the second half a unit above the first (so Tamura has a pair).
fn triangle_groups() -> [capi::scene::kage_group_desc; 2] {
    [0.0, 0.5].map(|y| capi::scene::kage_group_desc {
        name: null(),
        transform: capi::scene::kage_transform {
            translation: [0.0, y, 0.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
            scale: 1.0,
        },
        meshes: null(),
        mesh_count: 1,
    })
}

fn create_scene(sky: &[f32]) -> (kage_result, *mut capi::scene::kage_scene) {
    let mesh = triangle_mesh();
    let mut groups = triangle_groups();
    let desc = scene_desc(&mesh, &mut groups, sky);
    let mut scene = null_mut();
    // SAFETY: the desc's arrays hold the counts it states and outlive the call.
    let code = unsafe { capi::scene::kage_scene_create(&desc, &mut scene) };
    (code, scene)
}

impl CHost {
    fn new() -> CHost {
        let desc = capi::context::kage_context_desc {
            size: size_of::<capi::context::kage_context_desc>() as u32,
            device_name: null(),
            validation: true,
        };
        let mut context = null_mut();
        // SAFETY: a valid desc and a writable out-handle.
        assert_eq!(unsafe { capi::context::kage_context_create(&desc, &mut context) }, kage_result::Ok);
        let (code, scene) = create_scene(&vec![1.0; 3 * (SKY.0 * SKY.1) as usize]);
        assert_eq!(code, kage_result::Ok, "{}", last_error());
        CHost { context, scene }
    }

    fn technique(&self, technique: u32) -> capi::technique::kage_technique_desc {
        let mut desc = std::mem::MaybeUninit::uninit();
        // SAFETY: a writable desc.
        assert_eq!(
            unsafe { capi::technique::kage_technique_desc_default(technique, desc.as_mut_ptr()) },
            kage_result::Ok
        );
        // SAFETY: filled by the successful call.
        let mut desc = unsafe { desc.assume_init() };
        desc.prt_rays = 16;
        desc.mask_size = 16;
        desc.shadow_map_size = 16;
        desc
    }
}

impl Drop for CHost {
    fn drop(&mut self) {
        // Handles this host made (destroying an already destroyed one is caught).
        capi::scene::kage_scene_destroy(self.scene);
        capi::context::kage_context_destroy(self.context);
    }
}

fn last_error() -> String {
    let mut buffer = [0 as c_char; 1024];
    let mut length = 0;
    // SAFETY: a local buffer of the stated size.
    unsafe { capi::kage_last_error_message(buffer.as_mut_ptr(), buffer.len(), &mut length) };
    String::from_utf8_lossy(
        &buffer[..length.min(buffer.len() - 1)].iter().map(|c| *c as u8).collect::<Vec<_>>(),
    )
    .into_owned()
}

/// What tests/c_host/arrays.c leaves out: an environment texel that is NaN (named), the last
/// enumeration (`probe_light`) out of range, sizes just beyond their limits, and calls after
/// free: a destroyed context or scene is caught as an invalid handle, while a renderer outlives
/// both (it holds the device; kage.h promises it) and, once destroyed, is caught itself. (The
/// ABI has no self-sized structs to get wrong: kage.h's structs carry no size field, and buffer
/// sizes, the one size a host passes, are checked in arrays.c.)
#[test]
fn c_abi_catches_bad_values_and_calls_after_free() {
    let mut sky = vec![1.0f32; 3 * (SKY.0 * SKY.1) as usize];
    sky[3 * (2 * SKY.0 as usize + 5) + 1] = f32::NAN;
    let (code, scene) = create_scene(&sky);
    assert_eq!((code, scene), (kage_result::InvalidValue, null_mut()));
    assert!(last_error().contains("pixel (5, 2)"), "{}", last_error());

    let c = CHost::new();
    let create = |desc: &capi::renderer::kage_renderer_desc, context| {
        let mut renderer = null_mut();
        // SAFETY: handles are NULL, live or destroyed (caught); `renderer` is writable.
        let code = unsafe { capi::renderer::kage_renderer_create(context, c.scene, desc, &mut renderer) };
        (code, renderer)
    };
    let unshadowed = c.technique(0);
    for (width, height, probe_light, shadow_map_size, technique, named) in [
        (16, 16, 2, 16, 4, "probe_light"),
        (MAX_SIZE + 1, 16, 0, 16, 0, "8193x16"),
        (16, 16, 0, 2049, 3, "shadow map size 2049"),
    ] {
        let technique =
            capi::technique::kage_technique_desc { probe_light, shadow_map_size, technique, ..unshadowed };
        let desc = capi::renderer::kage_renderer_desc {
            size: size_of::<capi::renderer::kage_renderer_desc>() as u32,
            width,
            height,
            technique,
        };
        assert_eq!(create(&desc, c.context).0, kage_result::InvalidValue);
        assert!(last_error().contains(named), "{} does not name {named}", last_error());
    }

    let desc = capi::renderer::kage_renderer_desc {
        size: size_of::<capi::renderer::kage_renderer_desc>() as u32,
        width: 4,
        height: 4,
        technique: unshadowed,
    };
    let (code, renderer) = create(&desc, c.context);
    assert_eq!(code, kage_result::Ok, "{}", last_error());
    let mut pixels = [0u8; 4 * 4 * 16];
    let mut name = [0 as c_char; 64];
    // SAFETY: every handle below is live, destroyed or NULL (the ABI catches the latter two);
    // buffers are local with their stated sizes.
    unsafe {
        assert_eq!(capi::context::kage_context_destroy(c.context), kage_result::Ok);
        assert_eq!(capi::scene::kage_scene_destroy(c.scene), kage_result::Ok);
        assert_eq!(create(&desc, c.context).0, kage_result::InvalidHandle);
        let length = null_mut();
        assert_eq!(
            capi::context::kage_context_device_name(c.context, name.as_mut_ptr(), name.len(), length),
            kage_result::InvalidHandle
        );
        let technique = c.technique(1);
        assert_eq!(
            capi::technique::kage_precompute(c.context, c.scene, &technique),
            kage_result::InvalidHandle
        );
        // The renderer lives on.
        assert_eq!(capi::renderer::kage_renderer_render(renderer), kage_result::Ok, "{}", last_error());
        assert_eq!(
            capi::renderer::kage_renderer_read_pixels(renderer, 1, 1.0, pixels.as_mut_ptr(), pixels.len()),
            kage_result::Ok
        );
        assert_eq!(capi::renderer::kage_renderer_destroy(renderer), kage_result::Ok);
        assert_eq!(capi::renderer::kage_renderer_render(renderer), kage_result::InvalidHandle);
        assert_eq!(
            capi::renderer::kage_renderer_read_pixels(renderer, 1, 1.0, pixels.as_mut_ptr(), pixels.len()),
            kage_result::InvalidHandle
        );
        let transform =
            capi::scene::kage_transform { translation: [0.0; 3], rotation: [0.0, 0.0, 0.0, 1.0], scale: 1.0 };
        assert_eq!(
            capi::renderer::kage_renderer_set_group_transform(renderer, 0, &transform),
            kage_result::InvalidHandle
        );
        let mut count = 0;
        assert_eq!(
            capi::renderer::kage_renderer_timings(renderer, null_mut(), 0, &mut count),
            kage_result::InvalidHandle
        );
    }
    let linear: Vec<f32> =
        pixels.chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect();
    assert!(linear.iter().all(|c| c.is_finite() && *c >= 0.0), "{linear:?}");
}

/// The probe technique through the C ABI, as a host drives it: probes at positions it passes,
/// counted back by `kage_renderer_get_stats`; bad probe values are errors naming the field.
#[test]
fn c_abi_places_probes_and_reports_them() {
    use capi::technique::{kage_probe_dering, kage_probe_placement};
    use kage::techniques::description::TechniqueKind;
    use kage::techniques::probes::{CapturedLight, ProbeInterpolation, ProbeVisibility, StaticLighting};
    let c = CHost::new();
    // Around the triangles (the scene's static group is the upper one): a tetrahedralization
    // needs probes in 3D.
    let positions: [f32; 15] =
        [-1.0, 0.2, 0.5, 1.5, 0.2, 0.5, 0.2, 0.2, -1.5, 0.2, 1.2, -0.3, 0.2, -0.6, -0.3];
    let probes = capi::technique::kage_technique_desc {
        probe_placement: kage_probe_placement::Positions as u32,
        probe_positions: positions.as_ptr(),
        probe_position_count: 5,
        probe_cube_size: 8,
        probe_light: CapturedLight::Sky as u32,
        ..c.technique(TechniqueKind::Probes as u32)
    };
    let create = |technique| {
        let desc = capi::renderer::kage_renderer_desc {
            size: size_of::<capi::renderer::kage_renderer_desc>() as u32,
            width: 8,
            height: 8,
            technique,
        };
        let mut renderer = null_mut();
        // SAFETY: live handles, a desc whose positions hold the count it states, a writable out.
        let code = unsafe { capi::renderer::kage_renderer_create(c.context, c.scene, &desc, &mut renderer) };
        (code, renderer)
    };
    let (code, renderer) = create(probes);
    assert_eq!(code, kage_result::Ok, "{}", last_error());
    let mut stats = capi::renderer::kage_renderer_stats::default();
    // SAFETY: a live renderer and a local stats struct.
    unsafe {
        assert_eq!(capi::renderer::kage_renderer_render(renderer), kage_result::Ok, "{}", last_error());
        assert_eq!(capi::renderer::kage_renderer_get_stats(renderer, &mut stats), kage_result::Ok);
        assert_eq!(capi::renderer::kage_renderer_destroy(renderer), kage_result::Ok);
    }
    assert_eq!((stats.probes, stats.probe_candidates, stats.probes_inside_geometry), (5, 5, 0));
    // Lookups weigh probes by visibility unless the host turns it off.
    assert_eq!(probes.probe_visibility, ProbeVisibility::Rays as u32);
    let off = ProbeVisibility::Off as u32;
    let (code, renderer) = create(capi::technique::kage_technique_desc { probe_visibility: off, ..probes });
    assert_eq!(code, kage_result::Ok, "{}", last_error());
    assert_eq!(capi::renderer::kage_renderer_destroy(renderer), kage_result::Ok);

    let hanning = kage_probe_dering::Hanning as u32;
    let trilinear = ProbeInterpolation::Trilinear as u32;
    for (technique, expected, named) in [
        (
            capi::technique::kage_technique_desc { probe_placement: 3, ..probes },
            kage_result::InvalidValue,
            "probe_placement",
        ),
        (
            capi::technique::kage_technique_desc { probe_positions: null(), ..probes },
            kage_result::NullArgument,
            "probe_positions",
        ),
        (
            capi::technique::kage_technique_desc { probe_interpolation: trilinear, ..probes },
            kage_result::InvalidValue,
            "trilinear",
        ),
        (
            capi::technique::kage_technique_desc { probe_dering: hanning, ..probes },
            kage_result::InvalidValue,
            "window width 0",
        ),
        (
            capi::technique::kage_technique_desc {
                probe_placement: kage_probe_placement::Auto as u32,
                probe_tolerance: -1.0,
                ..probes
            },
            kage_result::InvalidValue,
            "tolerance -1",
        ),
        (
            capi::technique::kage_technique_desc { probe_statics: 7, ..probes },
            kage_result::InvalidValue,
            "probe_statics",
        ),
        (
            capi::technique::kage_technique_desc { probe_visibility: 2, ..probes },
            kage_result::InvalidValue,
            "probe_visibility",
        ),
        (
            capi::technique::kage_technique_desc { probe_statics: StaticLighting::Sloan as u32, ..probes },
            kage_result::InvalidValue,
            "precompute it first",
        ),
    ] {
        let (code, renderer) = create(technique);
        assert_eq!((code, renderer), (expected, null_mut()), "{named}: {}", last_error());
        assert!(last_error().contains(named), "{} does not name {named}", last_error());
    }
}
