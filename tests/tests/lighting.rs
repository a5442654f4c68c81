//! SH projection on the GPU and the first rendering, checked against what the maths says.
use glam::{Mat4, Vec2, Vec3, Vec4};
use kage::frame::sh_projection;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{shapes, uv_to_direction, Camera, EnvMap, Scene};
use kage_tests::{render_once, single_mesh_scene, Validated};
use std::f32::consts::PI;

/// Sums over texels in f32 on the GPU: relative error of a few 1e-6 per coefficient, far below
/// these bounds.
const SH_TOLERANCE: f32 = 1e-4;

#[test]
fn constant_map_projects_to_the_first_coefficient_only() {
    let ctx = Validated::new();
    let c = 0.75;
    // Real maps' size: the basis is evaluated at texel centres, an error that falls as 1/h^2
    // (about 5e-4 of c0 in band 2 at h = 32, 2e-6 at h = 512).
    let map = EnvMap::from_pixels(1024, 512, vec![[c, 2.0 * c, 3.0 * c]; 1024 * 512]).unwrap();
    let sh = sh_projection::project(&ctx, &map).unwrap();
    for k in 0..3 {
        let expected = 2.0 * PI.sqrt() * c * (k + 1) as f32;
        assert!(
            (sh.c[0][k] - expected).abs() < SH_TOLERANCE * expected,
            "c0[{k}] = {} vs {expected}",
            sh.c[0][k]
        );
        for i in 1..9 {
            assert!(sh.c[i][k].abs() < SH_TOLERANCE * expected, "c{i}[{k}] = {}", sh.c[i][k]);
        }
    }
}

/// Maps of a few texels: the GPU projects each texel as cells (constants::SH_MIN_ROWS rows in
/// all). Before, a 2×1 map of radiance 1 gave irradiance 1.18 at +Y and 7.07 at +X,
/// a 4×2 map 4.12 and 2.65, against π. Tolerance: the sub-texels' midpoint rule errs by about
/// 4e-5 and the f32 sums by a few 1e-6; 1e-3 relative leaves room for both.
#[test]
fn tiny_constant_maps_give_irradiance_pi_everywhere() {
    let ctx = Validated::new();
    for (w, h) in [(2u32, 1u32), (4, 2), (16, 8)] {
        let map = EnvMap::from_pixels(w, h, vec![[1.0; 3]; (w * h) as usize]).unwrap();
        let sh = sh_projection::project(&ctx, &map).unwrap();
        for n in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::new(0.6, 0.48, 0.64)] {
            let e = sh.irradiance(n)[0];
            assert!((e / PI - 1.0).abs() < 1e-3, "{w}x{h} at {n}: irradiance {e}, not π");
        }
    }
}

#[test]
fn linear_map_projects_to_bands_0_and_1() {
    let ctx = Validated::new();
    let (w, h) = (256u32, 128u32);
    let coefficients = Vec3::new(0.5, 0.25, -0.3); // radiance 1 + a.x x + a.y y + a.z z
    let pixels = (0..w * h)
        .map(|p| {
            let uv = Vec2::new(((p % w) as f32 + 0.5) / w as f32, ((p / w) as f32 + 0.5) / h as f32);
            [1.0 + coefficients.dot(uv_to_direction(uv)); 3]
        })
        .collect();
    let sh = sh_projection::project(&ctx, &EnvMap::from_pixels(w, h, pixels).unwrap()).unwrap();
    let band1 = (4.0 * PI / 3.0).sqrt();
    // Index order: y00, y1-1 (y), y10 (z), y11 (x), then band 2.
    let expected = [
        2.0 * PI.sqrt(),
        coefficients.y * band1,
        coefficients.z * band1,
        coefficients.x * band1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ];
    // Pixel-centre quadrature on a 256x128 map: errors below 1e-3 of c0.
    for (i, e) in expected.iter().enumerate() {
        assert!((sh.c[i][0] - e).abs() < 1e-3 * expected[0], "c{i} = {} vs {e}", sh.c[i][0]);
    }
}

#[test]
fn gpu_projection_matches_the_cpu_reference_on_a_real_map() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    let map = &scene.environment;
    let gpu = sh_projection::project(&ctx, map).unwrap();
    let cpu = kage::sh::project_equirect(map.width(), map.height(), map.pixels(), 3).unwrap();
    let scale = cpu[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (i, (g, c)) in gpu.c.iter().zip(&cpu).enumerate() {
        for k in 0..3 {
            let diff = (g[k] as f64 - c[k]).abs();
            assert!(diff < SH_TOLERANCE as f64 * scale, "c{i}[{k}]: gpu {} cpu {}", g[k], c[k]);
        }
    }
}

/// The world-space ray through the centre of pixel (x, y), from the same matrices the renderer
/// uses (row 0 at the top).
fn pixel_ray(camera: &Camera, x: u32, y: u32, size: u32) -> Vec3 {
    let inv: Mat4 = (camera.projection(1.0) * camera.view()).inverse();
    let ndc =
        Vec2::new((x as f32 + 0.5) / size as f32 * 2.0 - 1.0, (y as f32 + 0.5) / size as f32 * 2.0 - 1.0);
    let p = inv * Vec4::new(ndc.x, ndc.y, 0.5, 1.0);
    (p.truncate() / p.w - camera.position).normalize()
}

/// Distance from the line through `origin` along `dir` to the world origin.
fn miss_distance(origin: Vec3, dir: Vec3) -> f32 {
    (origin - dir * origin.dot(dir)).length()
}

/// A sphere of albedo rho under radiance 1 from every direction receives irradiance pi
/// everywhere, so it reflects rho/pi * pi = rho. Nine SH coefficients represent a constant map
/// exactly, so the only error is the projection's float sum: well under the 1% asked.
#[test]
fn sphere_under_constant_light_has_radiance_albedo() {
    let ctx = Validated::new();
    let rho = 0.6;
    let camera =
        Camera { position: Vec3::new(0.0, 0.5, 4.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
    let sphere = shapes::sphere("sphere", 1.0, 64, [rho; 3]).unwrap();
    let scene = single_mesh_scene(sphere, EnvMap::constant([1.0; 3]), camera);
    let size = 96;
    let image = render_once(&ctx, &scene, size, size);
    let (mut on_sphere, mut on_background) = (0, 0);
    for y in 0..size {
        for x in 0..size {
            let pixel = image.pixels[(y * size + x) as usize];
            // Stay clear of the silhouette, where the tessellated sphere and the ideal one differ.
            let d = miss_distance(camera.position, pixel_ray(&camera, x, y, size));
            if d < 0.97 {
                on_sphere += 1;
                for k in 0..3 {
                    assert!(
                        (pixel[k] - rho).abs() <= 0.01 * rho,
                        "pixel ({x}, {y}) = {pixel:?}, expected {rho}"
                    );
                }
            } else if d > 1.03 {
                on_background += 1;
                for k in 0..3 {
                    assert!((pixel[k] - 1.0).abs() < 1e-5, "background ({x}, {y}) = {pixel:?}");
                }
            }
        }
    }
    assert!(
        on_sphere > 1000 && on_background > 1000,
        "{on_sphere} sphere and {on_background} background pixels"
    );
}

/// One bright texel must appear exactly where the camera looks along that texel's direction:
/// this pins down the documented equirectangular mapping end to end.
#[test]
fn bright_texel_is_seen_in_its_direction() {
    let ctx = Validated::new();
    let (w, h) = (64u32, 32u32);
    let (i, j) = (10u32, 9u32);
    let mut pixels = vec![[0.0f32; 3]; (w * h) as usize];
    pixels[(j * w + i) as usize] = [100.0, 50.0, 25.0];
    let direction = uv_to_direction(Vec2::new((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32));
    let camera = Camera { position: Vec3::ZERO, target: direction, up: Vec3::Y, fov_y_deg: 20.0 };
    let scene = Scene {
        groups: vec![],
        ..single_mesh_scene(
            shapes::sphere("unused", 1.0, 8, [0.5; 3]).unwrap(),
            EnvMap::from_pixels(w, h, pixels).unwrap(),
            camera,
        )
    };
    let size = 33; // odd: the centre pixel's ray is exactly the camera's axis
    let image = render_once(&ctx, &scene, size, size);
    let centre = image.pixels[(size / 2 * size + size / 2) as usize];
    // Bilinear filtering at the texel's exact centre returns the texel itself.
    for (k, expected) in [100.0f32, 50.0, 25.0].iter().enumerate() {
        assert!((centre[k] - expected).abs() < 1e-2 * expected, "centre {centre:?}");
    }
    let brightest =
        image.pixels.iter().enumerate().max_by(|a, b| a.1[0].total_cmp(&b.1[0])).unwrap().0 as u32;
    assert_eq!((brightest % size, brightest / size), (size / 2, size / 2));
    assert_eq!(image.pixels[0], [0.0, 0.0, 0.0, 1.0], "a corner 10 degrees away sees black");
}

#[test]
fn every_pass_reports_gpu_time() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    let mut renderer =
        Renderer::new(&ctx, &scene, &RenderOptions { width: 64, height: 64, ..Default::default() }).unwrap();
    let first = renderer.render().unwrap();
    let names: Vec<&str> = first.iter().map(|t| t.name).collect();
    assert_eq!(names, ["sh_project", "sh_reduce", "background", "scene", "readback"]);
    let second = renderer.render().unwrap();
    assert_eq!(second.len(), 3, "the SH projection runs only when the environment changes");
    for t in first.iter().chain(&second) {
        assert!(t.gpu_ms.is_some_and(|ms| ms > 0.0), "{t:?}");
    }
}

#[test]
fn bad_render_arguments_are_errors() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    for (w, h) in [(0, 64), (64, 0), (9000, 64)] {
        let err = Renderer::new(&ctx, &scene, &RenderOptions { width: w, height: h, ..Default::default() })
            .err()
            .unwrap();
        assert!(err.to_string().contains("image size"), "{err}");
    }
    let mut renderer =
        Renderer::new(&ctx, &scene, &RenderOptions { width: 8, height: 8, ..Default::default() }).unwrap();
    assert!(renderer.set_group_transform(7, Mat4::IDENTITY).unwrap_err().to_string().contains("group 7"));
    assert!(renderer.set_group_transform(0, Mat4::from_translation(Vec3::NAN)).is_err());
}
