//! The shadowmap technique (the conventional baseline of adaptive shadow maps) against the
//! ray-traced local-light reference, pixel by pixel.
use glam::Vec3;
use kage::reference::{shadow_mismatch, LightMode, ReferenceOptions, ReferenceRenderer, SHADOW_THRESHOLD};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{shapes, Camera, EnvMap, Group, Light, Scene, Transform};
use kage::techniques::asm::technique::{AsmTimeBudget, MAX_TIME_SHARE};
use kage::techniques::asm::AsmSettings;
use kage::techniques::description::TechniqueDesc;
use kage_tests::Validated;

const SIZE: u32 = 128;
/// The spot light's cone, degrees: also its map's field of view.
const FOV_DEG: f32 = 90.0;
const LIGHT: Vec3 = Vec3::new(0.3, 3.0, 0.2);

/// A box (1 × 0.5 × 1, floating 0.5 above the floor) over a 6 × 6 floor, one spot light straight
/// down from 3 above the floor, no environment light (the reference's local mode has none).
fn box_over_floor() -> Scene {
    box_over_floor_lit_from(LIGHT)
}

fn spot_at(position: Vec3) -> Light {
    Light::Spot { position, direction: Vec3::NEG_Y, fov_deg: FOV_DEG, intensity: [8.0; 3] }
}

fn box_over_floor_lit_from(light: Vec3) -> Scene {
    let cube = shapes::boxes("box", &[([-0.5, 0.5, -0.5], [0.5, 1.0, 0.5])], [0.8; 3]).unwrap();
    let floor = shapes::plane("floor", [6.0, 6.0], [2, 2], [0.6; 3]).unwrap();
    let group = |name: &str, mesh| Group::new(name, vec![mesh], Transform::default());
    Scene {
        lights: vec![spot_at(light)],
        ..Scene::new(
            "box-over-floor",
            vec![group("box", cube), group("floor", floor)],
            EnvMap::constant([0.0; 3]),
            Camera { position: Vec3::new(0.0, 2.5, 3.5), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 },
        )
    }
}

fn render(ctx: &Validated, scene: &Scene, technique: TechniqueDesc) -> kage::imageio::RgbaF32Image {
    let mut r =
        Renderer::new(ctx, scene, &RenderOptions { width: SIZE, height: SIZE, technique, transfer: None })
            .unwrap();
    r.render().unwrap();
    r.image().unwrap()
}

fn reference(ctx: &Validated, scene: &Scene) -> kage::imageio::RgbaF32Image {
    let options = ReferenceOptions { width: SIZE, height: SIZE, light: LightMode::Local, seed: 1 };
    let mut r = ReferenceRenderer::new(ctx, scene, &options).unwrap();
    r.run_batch(1).unwrap();
    r.image().unwrap()
}

/// Pixels of the reference whose lit state differs from a 4-neighbour's: the boundaries
/// between lit and unlit (shadow edges, and where surfaces turn away from the light).
fn boundary_pixels(image: &kage::imageio::RgbaF32Image, threshold: f64) -> usize {
    let lit = |x: u32, y: u32| f64::from(image.pixels[(y * image.width + x) as usize][1]) > threshold;
    let (w, h) = (image.width, image.height);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let n = [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)];
            n.iter().any(|&(i, j)| i < w && j < h && lit(i, j) != lit(x, y))
        })
        .count()
}

/// The bound on misclassified pixels, derived from the map's texel size: the lookup blends the
/// tests of the four texels around the point and thresholds at 1/2, so its shadow edge runs
/// through the cells between texel centres that the ray-traced edge also crosses (only there
/// do the centres' tests differ), at most a cell diagonal (√2 texels) away from it. On the floor, at view depth d below the light, a texel spans
/// d · 2 tan(fov/2) / S in world units (the floor faces the light: no stretching); seen from
/// the camera at distance D with a vertical field of view φ over H pixels, a floor segment
/// spans at most its length / (D · 2 tan(φ/2) / H) pixels. So every misclassified pixel lies
/// within t = √2 · texel / pixel of a reference boundary, and their number is at most
/// B · (2t + 1) for B boundary pixels (a band 2t wide plus the pixel the edge crosses). The
/// boundary count B also holds the box's own lit/unlit face edges and the cone's edge, where
/// both images agree, so the bound is loose (measured: 9 pixels at S = 512 against a bound of
/// 1510, 252 against 14519 at S = 32; the nearest texel's lookup, bound by √½ texel, also
/// misclassified 9 and 252 here: the box's edges run along the texel rows).
fn texel_bound(scene: &Scene, map_size: u32, boundary: usize) -> usize {
    let Light::Spot { position: light, .. } = scene.lights[0] else { unreachable!("a spot light") };
    let depth = light.y; // the floor is y = 0, the light looks straight down
    let texel = depth * 2.0 * (0.5 * FOV_DEG.to_radians()).tan() / map_size as f32;
    // The camera's nearest point of the shadow region is the closest, where a pixel is smallest
    // and a texel spans the most pixels: the shadow lies within the rectangle around the box's
    // corners projected from the light onto the floor, so the rectangle's nearest point is at
    // most as far.
    let corners = [-0.5f32, 0.5].into_iter().flat_map(|x| {
        [-0.5f32, 0.5].into_iter().flat_map(move |z| [0.5f32, 1.0].map(|y| Vec3::new(x, y, z)))
    });
    let on_floor: Vec<Vec3> = corners.map(|c| light + (c - light) * (light.y / (light.y - c.y))).collect();
    let lo = on_floor.iter().copied().reduce(Vec3::min).unwrap();
    let hi = on_floor.iter().copied().reduce(Vec3::max).unwrap();
    let nearest = scene.camera.position.distance(scene.camera.position.clamp(lo, hi));
    let pixel = nearest * 2.0 * (0.5 * scene.camera.fov_y_deg.to_radians()).tan() / SIZE as f32;
    let t = std::f32::consts::SQRT_2 * texel / pixel;
    (boundary as f32 * (2.0 * t + 1.0)).ceil() as usize
}

#[test]
fn shadows_match_the_reference_within_the_texel_bound() {
    let ctx = Validated::new();
    let scene = box_over_floor();
    let truth = reference(&ctx, &scene);
    let max = truth.pixels.iter().map(|p| f64::from(p[1])).fold(0.0, f64::max);
    let boundary = boundary_pixels(&truth, SHADOW_THRESHOLD * max);
    assert!(boundary > 100, "the scene should show a shadow edge: {boundary} boundary pixels");
    let mut previous = None;
    for map_size in [32, 512] {
        let image = render(&ctx, &scene, TechniqueDesc::ShadowMap { size: map_size });
        let m = shadow_mismatch(&image, &truth, SHADOW_THRESHOLD, None).unwrap();
        let bound = texel_bound(&scene, map_size, boundary);
        eprintln!("map {map_size}: {} pixels misclassified ({:.5}), bound {bound}", m.differing, m.fraction);
        assert!(m.differing <= bound, "map {map_size}: {} pixels misclassified, bound {bound}", m.differing);
        if let Some(coarser) = previous {
            assert!(m.differing < coarser, "a finer map should misclassify fewer pixels");
        }
        previous = Some(m.differing);
    }
    // Lit pixels get the reference's radiance: the same falloff and BRDF.
    let image = render(&ctx, &scene, TechniqueDesc::ShadowMap { size: 512 });
    for (a, b) in image.pixels.iter().zip(&truth.pixels) {
        if a[1] > 0.0 && b[1] > 0.0 {
            assert!((a[1] - b[1]).abs() <= 1e-3 * b[1].max(1e-3), "{a:?} against {b:?}");
        }
    }
}

/// A light moved at run time (`Renderer::set_light`) re-renders its map: the frame after the move
/// matches the reference of the moved light within the texel bound, and is the frame a renderer
/// built with the light there from the start draws. The shadow moves far enough that the old
/// reference would not pass (so the test can fail). Bad light updates are clear errors. The
/// renderer reports the map's bytes (what `kage bench asm` compares techniques' memory by).
#[test]
fn a_moved_light_re_renders_its_shadow() {
    let ctx = Validated::new();
    let moved = Vec3::new(-1.0, 2.5, -0.6);
    let (before, after) = (box_over_floor(), box_over_floor_lit_from(moved));
    let mut renderer = Renderer::new(
        &ctx,
        &before,
        &RenderOptions {
            width: SIZE,
            height: SIZE,
            technique: TechniqueDesc::ShadowMap { size: 512 },
            transfer: None,
        },
    )
    .unwrap();
    renderer.render().unwrap();
    renderer.set_light(0, spot_at(moved)).unwrap();
    renderer.render().unwrap();
    let image = renderer.image().unwrap();

    let truth = reference(&ctx, &after);
    let max = truth.pixels.iter().map(|p| f64::from(p[1])).fold(0.0, f64::max);
    let bound = texel_bound(&after, 512, boundary_pixels(&truth, SHADOW_THRESHOLD * max));
    let m = shadow_mismatch(&image, &truth, SHADOW_THRESHOLD, None).unwrap();
    let stale = shadow_mismatch(&image, &reference(&ctx, &before), SHADOW_THRESHOLD, None).unwrap();
    eprintln!(
        "moved light: {} pixels misclassified (bound {bound}), {} against the old light",
        m.differing, stale.differing
    );
    assert!(m.differing <= bound, "{} pixels misclassified, bound {bound}", m.differing);
    assert!(stale.differing > bound, "the light should have moved the shadow: {}", stale.differing);
    let fresh = render(&ctx, &after, TechniqueDesc::ShadowMap { size: 512 });
    assert_eq!(shadow_mismatch(&image, &fresh, SHADOW_THRESHOLD, None).unwrap().differing, 0);

    // One D32 map of 512² texels for the one light; a technique without shadow maps has none.
    assert_eq!(renderer.stats().shadow_memory_bytes, Some(512 * 512 * 4));
    let unshadowed =
        Renderer::new(&ctx, &after, &RenderOptions { width: 16, height: 16, ..Default::default() });
    assert_eq!(unshadowed.unwrap().stats().shadow_memory_bytes, None);

    let err = renderer.set_light(1, spot_at(moved)).unwrap_err().to_string();
    assert!(err.contains("light 1 does not exist (the scene has 1)"), "{err}");
    let err = renderer.set_light(0, spot_at(Vec3::new(f32::NAN, 1.0, 0.0))).unwrap_err().to_string();
    assert!(err.contains("light 0") && err.contains("not finite"), "{err}");
}

#[test]
fn needs_local_lights_and_a_map_size_in_range() {
    let ctx = Validated::new();
    let attempt = |scene: &Scene, size| {
        let options = RenderOptions {
            width: 16,
            height: 16,
            technique: TechniqueDesc::ShadowMap { size },
            transfer: None,
        };
        match Renderer::new(&ctx, scene, &options) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        }
    };
    let mut dark = box_over_floor();
    dark.lights.clear();
    assert!(attempt(&dark, 512).contains("1 to 8 point or spot lights"));
    for size in [8, 16384] {
        assert!(attempt(&box_over_floor(), size).contains("shadow map size"), "{size}");
    }
}

/// The built-in `asm` scene renders through its walkthrough with no validation message, and a
/// close-up of the grating's shadow shows it: most of the floor under the grating is lit, and
/// a good part of it is in shadow.
#[test]
fn the_asm_walkthrough_renders_cleanly() {
    let ctx = Validated::new();
    let scene = Scene::builtin("asm").unwrap();
    let options = RenderOptions {
        width: 48,
        height: 48,
        technique: TechniqueDesc::ShadowMap { size: 1024 },
        transfer: None,
    };
    let mut renderer = Renderer::new(&ctx, &scene, &options).unwrap();
    for t in [0.0, 0.2] {
        renderer.set_camera(kage::scene::animation::camera_at(&scene.walkthrough, t).unwrap()).unwrap();
        renderer.render().unwrap();
    }
    let image = renderer.image().unwrap();
    let lit = image.pixels.iter().filter(|p| p[1] > 0.0).count() as f32 / image.pixels.len() as f32;
    assert!((0.3..0.9).contains(&lit), "lit fraction of the grating close-up: {lit}");
}

/// The local-light techniques shade over a depth prepass with the depth test EQUAL: every pixel
/// the scene covers must still be shaded, exactly the pixels the unshadowed technique (one
/// pass, depth test LESS) covers. A position computed differently in the two passes would
/// leave holes showing the background. The environment is a constant no shading reproduces,
/// so a pixel shows geometry exactly where it differs from it.
#[test]
fn the_depth_prepass_leaves_no_pixel_unshaded() {
    let ctx = Validated::new();
    let mut scene = box_over_floor();
    scene.environment = EnvMap::constant([2.0; 3]);
    let covered = |technique| {
        let image = render(&ctx, &scene, technique);
        image.pixels.iter().map(|p| p[..3] != [2.0; 3]).collect::<Vec<bool>>()
    };
    let expected = covered(TechniqueDesc::Unshadowed);
    let count = expected.iter().filter(|&&c| c).count();
    assert!(count > expected.len() / 4, "the scene covers {count} pixels");
    let asm = kage::techniques::asm::AsmSettings { budget_mb: 1.0, ..Default::default() };
    for technique in [TechniqueDesc::ShadowMap { size: 512 }, TechniqueDesc::Asm(asm)] {
        let name = format!("{technique:?}");
        let got = covered(technique);
        let holes = expected.iter().zip(&got).filter(|(e, g)| **e && !**g).count();
        let extra = expected.iter().zip(&got).filter(|(e, g)| !**e && **g).count();
        assert_eq!((holes, extra), (0, 0), "{name}: pixels unshaded, shaded outside the scene");
    }
}

/// The rasterizer and the reference shade the same point: the Blender export's 1000 W spot on
/// its ground alone (the crate and Suzanne removed), so the cone's edge is the only boundary
/// between lit and unlit. When the eye rays were unprojected through the inverse
/// view-projection in float, the reference's strayed by about 1/50 px from the pixel centre the
/// rasterizer samples (`Camera::eye_rays`), and 7 pixels along the edge differed at 512².
/// The reference's edge ties (pixels whose state changes when the primary ray moves by the
/// rasterizer's sub-pixel precision) lie on the boundary, and are a small part of it.
#[test]
fn the_render_shades_the_references_points_and_edge_ties_lie_on_edges() {
    const SIZE: u32 = 512;
    let ctx = Validated::new();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/gltf/blender-suzanne/scene.glb");
    let mut scene = Scene::load(std::path::Path::new(path)).unwrap();
    scene.groups.retain(|g| g.name == "Ground");
    assert_eq!(scene.groups.len(), 1, "the export's ground");
    scene.environment = EnvMap::constant([0.0; 3]);
    let options = ReferenceOptions { width: SIZE, height: SIZE, light: LightMode::Local, seed: 1 };
    let mut reference = ReferenceRenderer::new(&ctx, &scene, &options).unwrap();
    reference.run_batch(1).unwrap();
    let (truth, edges) = (reference.image().unwrap(), reference.edge_ties().unwrap());
    let technique = TechniqueDesc::ShadowMap { size: 512 };
    let mut r =
        Renderer::new(&ctx, &scene, &RenderOptions { width: SIZE, height: SIZE, technique, transfer: None })
            .unwrap();
    r.render().unwrap();
    let m = shadow_mismatch(&r.image().unwrap(), &truth, SHADOW_THRESHOLD, Some(&edges)).unwrap();
    let boundary = boundary_pixels(&truth, m.threshold);
    eprintln!(
        "cone edge: {boundary} boundary pixels, {} differ, {} edge ties differ",
        m.differing, m.at_edges
    );
    assert!(boundary > 500, "the cone's edge should cross the image: {boundary} boundary pixels");
    assert_eq!(m.differing, 0, "pixels lit in one image only away from edge ties");

    let ties: Vec<usize> =
        edges.ties(m.threshold).enumerate().filter(|&(_, tie)| tie).map(|(i, _)| i).collect();
    let lit = |i: usize| f64::from(truth.pixels[i][1]) > m.threshold;
    let w = SIZE as usize;
    let on_boundary = |i: usize| {
        let (x, y) = (i % w, i / w);
        [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)]
            .iter()
            .any(|&(a, b)| a < w && b < w && lit(b * w + a) != lit(i))
    };
    assert!(ties.iter().all(|&i| on_boundary(i)), "every edge tie lies on a lit/unlit boundary");
    // A boundary crossing a pixel row at a random offset passes within 1/256 px of its
    // centre with probability about 2/256 per pixel: a few, never most.
    assert!(
        !ties.is_empty() && ties.len() * 10 < boundary,
        "{} ties of {boundary} boundary pixels",
        ties.len()
    );
}

/// Contact: a cube resting on a floor, lit from above at 45° by a spot on the camera's side, so
/// that the lit front faces meet the lit floor along the cube's base. Neither the conventional
/// map nor ASM may mark a pixel along that base differently from the reference (edge ties
/// apart): the dotted line of floor pixels shadowed by the cube's own depth, which a depth
/// bias too small for the texel leaves. Counted within 2 px of the base's outline on screen.
/// (Measured at 256²: 0 of the 914 pixels for both; with the depth bias set to 0 the map marks
/// 148 of them.)
#[test]
fn a_cube_resting_on_the_floor_has_no_dotted_line_along_its_base() {
    const SIZE: u32 = 256;
    let ctx = Validated::new();
    let cube = shapes::boxes("cube", &[([-0.5, 0.0, -0.5], [0.5, 1.0, 0.5])], [0.7; 3]).unwrap();
    let floor = shapes::plane("floor", [8.0, 8.0], [2, 2], [0.6; 3]).unwrap();
    let turn = glam::Quat::from_rotation_y(20f32.to_radians());
    let light = Vec3::new(0.5, 3.2, 3.5);
    let scene = Scene {
        lights: vec![Light::Spot {
            position: light,
            direction: Vec3::new(-0.15, -0.707, -0.707),
            fov_deg: 70.0,
            intensity: [20.0; 3],
        }],
        ..Scene::new(
            "contact",
            vec![
                Group::new("cube", vec![cube], Transform { rotation: turn, ..Transform::default() }),
                Group::new("floor", vec![floor], Transform::default()),
            ],
            EnvMap::constant([0.0; 3]),
            Camera {
                position: Vec3::new(1.2, 2.2, 4.5),
                target: Vec3::new(0.0, 0.3, 0.0),
                up: Vec3::Y,
                fov_y_deg: 35.0,
            },
        )
    };
    let options = ReferenceOptions { width: SIZE, height: SIZE, light: LightMode::Local, seed: 1 };
    let mut reference = ReferenceRenderer::new(&ctx, &scene, &options).unwrap();
    reference.run_batch(1).unwrap();
    let (truth, edges) = (reference.image().unwrap(), reference.edge_ties().unwrap());

    // The base's corners on screen, and the pixels within 2 px of its outline.
    let view_proj = scene.camera.projection(1.0) * scene.camera.view();
    let corners: Vec<glam::Vec2> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
        .map(|(x, z)| {
            let clip = view_proj * (turn * Vec3::new(x, 0.0, z)).extend(1.0);
            let ndc = clip.truncate() / clip.w;
            glam::Vec2::new((ndc.x * 0.5 + 0.5) * SIZE as f32, (ndc.y * 0.5 + 0.5) * SIZE as f32)
        })
        .to_vec();
    let near_base = |x: u32, y: u32| {
        let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        (0..4).any(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + (b - a) * t) <= 2.0
        })
    };
    let band: Vec<usize> =
        (0..SIZE * SIZE).filter(|&i| near_base(i % SIZE, i / SIZE)).map(|i| i as usize).collect();
    assert!(band.len() > 400, "the base's outline should cross the image: {} pixels", band.len());

    let threshold = 1e-4 * truth.pixels.iter().map(|p| f64::from(p[1])).fold(0.0, f64::max);
    let lit = |p: &[f32; 4]| f64::from(p[1]) > threshold;
    let ties: Vec<bool> = edges.ties(threshold).collect();
    let time = AsmTimeBudget { time_ms: 1000.0, time_share: MAX_TIME_SHARE };
    let asm = AsmSettings { budget_mb: 16.0, time, ..AsmSettings::default() };
    for (name, technique, frames) in [
        ("shadowmap 2048²", TechniqueDesc::ShadowMap { size: 2048 }, 1),
        ("asm 16 MiB", TechniqueDesc::Asm(asm), 12),
    ] {
        let mut r = Renderer::new(
            &ctx,
            &scene,
            &RenderOptions { width: SIZE, height: SIZE, technique, transfer: None },
        )
        .unwrap();
        for _ in 0..frames {
            r.render().unwrap();
        }
        let image = r.image().unwrap();
        let dots: Vec<(usize, usize)> = band
            .iter()
            .filter(|&&i| lit(&image.pixels[i]) != lit(&truth.pixels[i]) && !ties[i])
            .map(|&i| (i % SIZE as usize, i / SIZE as usize))
            .collect();
        eprintln!("{name}: {} of {} pixels along the base differ: {dots:?}", dots.len(), band.len());
        assert!(dots.is_empty(), "{name}: a dotted line along the cube's base: {dots:?}");
    }
}
