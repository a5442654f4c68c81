//! The Monte Carlo reference checked against cases with known answers: exact constants,
//! analytic occlusion, direct integration over the map on the CPU, and its own convergence rate.
//!
//! Monte Carlo tolerances are stated in standard errors measured by the reference itself
//! (4 σ: a 6e-5 chance per check of a false failure for a normal error; the seeds are fixed, so
//! a passing test stays passing).
use glam::{Quat, Vec3};
use kage::imageio::RgbaF32Image;
use kage::reference::irradiance::Point;
use kage::reference::{
    compare, IrradianceReference, LightMode, ReferenceOptions, ReferenceRenderer, Statistics,
};
use kage::scene::{shapes, Camera, EnvMap, Group, Light, Mesh, Scene, Transform};
use kage::sh::{equirect_direction, equirect_texel_solid_angle};
use kage_tests::{single_mesh_scene, Validated};
use std::f64::consts::PI;

const RHO: f32 = 0.6;

fn plane(size: f32) -> Mesh {
    shapes::plane("plane", [size, size], [2, 2], [RHO; 3]).unwrap()
}

fn group(name: &str, mesh: Mesh, transform: Transform) -> Group {
    Group::new(name, vec![mesh], transform)
}

/// Low and to the side, aimed at the origin: the centre pixel of an odd-sized image looks
/// straight at (0, 0, 0), under any blocker of half-size 1 at height 0.5 or more.
fn side_camera() -> Camera {
    Camera { position: Vec3::new(3.0, 0.25, 0.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 20.0 }
}

fn render(ctx: &Validated, scene: &Scene, size: u32, light: LightMode, seed: u32, spp: u32) -> Statistics {
    let mut renderer =
        ReferenceRenderer::new(ctx, scene, &ReferenceOptions { width: size, height: size, light, seed })
            .unwrap();
    renderer.run_batch(spp).unwrap();
    renderer.statistics().unwrap()
}

/// The centre pixel's red value and standard error.
fn centre(stats: &Statistics, size: u32) -> (f64, f64) {
    let i = ((size / 2) * size + size / 2) as usize;
    let se = stats.standard_error.as_ref().map_or(0.0, |e| f64::from(e[i][0]));
    (f64::from(stats.mean[i][0]), se)
}

/// Mean of the red channel over all pixels and its standard error (pixels are independent).
fn mean_over_pixels(stats: &Statistics) -> (f64, f64) {
    let n = stats.mean.len() as f64;
    let mean = stats.mean.iter().map(|p| f64::from(p[0])).sum::<f64>() / n;
    let errors = stats.standard_error.as_ref().unwrap();
    let variance = errors.iter().map(|e| f64::from(e[0]).powi(2)).sum::<f64>();
    (mean, variance.sqrt() / n)
}

fn image(stats: &Statistics, size: u32) -> RgbaF32Image {
    RgbaF32Image {
        width: size,
        height: size,
        pixels: stats.mean.iter().map(|&[r, g, b]| [r, g, b, 1.0]).collect(),
    }
}

/// E(n) = Σ L max(n·ω, 0) Ω over the texels, in f64: the map as the reference sees it
/// (constant per texel), with the cosine taken at texel centres.
fn cpu_irradiance(map: &EnvMap, n: Vec3) -> [f64; 3] {
    let (w, h) = (map.width(), map.height());
    let mut e = [0.0f64; 3];
    for j in 0..h {
        let omega = equirect_texel_solid_angle(w, h, j);
        let v = (f64::from(j) + 0.5) / f64::from(h);
        for i in 0..w {
            let d = equirect_direction((f64::from(i) + 0.5) / f64::from(w), v);
            let cos = d.dot(n.as_dvec3()).max(0.0);
            let p = map.pixels()[(j * w + i) as usize];
            for k in 0..3 {
                e[k] += f64::from(p[k]) * cos * omega;
            }
        }
    }
    e
}

#[test]
fn plane_under_a_constant_sky_has_radiance_albedo() {
    let ctx = Validated::new();
    let camera =
        Camera { position: Vec3::new(0.0, 2.0, 0.5), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 30.0 };
    let scene = single_mesh_scene(plane(20.0), EnvMap::constant([1.0; 3]), camera);
    let stats = render(&ctx, &scene, 16, LightMode::Environment, 1, 64);
    // Every pixel sees the plane: E = π, L = ρ/π · π = ρ.
    let (mean, se) = mean_over_pixels(&stats);
    // 4 σ of the mean of 256 pixels, plus f32 rounding of the sums.
    assert!((mean - f64::from(RHO)).abs() <= 4.0 * se + 1e-5, "{mean} ± {se} vs {RHO}");
    // MIS of the map (uniform here) with cosine sampling is nearly exact on a plane.
    assert!(se < 2e-3, "standard error {se}");
}

#[test]
fn tilted_planes_under_a_real_map_match_cpu_integration() {
    let ctx = Validated::new();
    let map = Scene::builtin("teapot").unwrap().environment;
    for (k, normal) in
        [Vec3::Y, Vec3::new(1.0, 0.3, -0.5), Vec3::new(-0.2, -0.4, 1.0)].into_iter().enumerate()
    {
        let n = normal.normalize();
        let transform = Transform { rotation: Quat::from_rotation_arc(Vec3::Y, n), ..Transform::default() };
        let up = if n.y.abs() > 0.9 { Vec3::Z } else { Vec3::Y };
        let scene = Scene::new(
            "tilted",
            vec![group("plane", plane(4.0), transform)],
            map.clone(),
            Camera { position: 2.0 * n, target: Vec3::ZERO, up, fov_y_deg: 40.0 },
        );
        let stats = render(&ctx, &scene, 16, LightMode::Environment, 10 + k as u32, 256);
        let expected = f64::from(RHO) / PI * cpu_irradiance(&map, n)[0];
        let (mean, se) = mean_over_pixels(&stats);
        // 4 σ, plus 0.1 % for the CPU sum's texel-centre cosine (its error is O(texel²),
        // about 1e-5 here) and f32 sums.
        assert!(
            (mean - expected).abs() <= 4.0 * se + 1e-3 * expected,
            "normal {n}: {mean} ± {se} vs {expected}"
        );
    }
}

#[test]
fn irradiance_on_a_lone_sphere_matches_cpu_integration() {
    let ctx = Validated::new();
    let map = Scene::builtin("teapot").unwrap().environment;
    let sphere = shapes::sphere("sphere", 1.0, 32, [RHO; 3]).unwrap();
    let scene = single_mesh_scene(sphere, map.clone(), side_camera());
    let normals = [Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::new(0.3, 0.5, -0.8).normalize()];
    // On the analytic sphere, which circumscribes the mesh: nothing above the tangent plane.
    let points: Vec<Point> =
        normals.iter().map(|n| Point { position: n.to_array(), normal: n.to_array() }).collect();
    let mut reference = IrradianceReference::new(&ctx, &scene, &points, 3).unwrap();
    // Four points cost nothing: many samples, in several batches to exercise their merging.
    for _ in 0..8 {
        reference.run_batch(1024).unwrap();
    }
    let stats = reference.statistics().unwrap();
    assert_eq!(stats.samples, 8192);
    let errors = stats.standard_error.as_ref().unwrap();
    for (i, n) in normals.iter().enumerate() {
        let expected = cpu_irradiance(&map, *n);
        for k in 0..3 {
            let (got, se) = (f64::from(stats.mean[i][k]), f64::from(errors[i][k]));
            // 4 σ plus 0.1 % (texel-centre cosine on the CPU, f32 sums on the GPU).
            assert!(
                (got - expected[k]).abs() <= 4.0 * se + 1e-3 * expected[k],
                "n = {n}, channel {k}: {got} ± {se} vs {expected:?}"
            );
        }
    }
}

/// Point-to-parallel-square form factor from below the centre: the cosine-weighted fraction
/// of the hemisphere that a square of half-size s at height h hides (four corner rectangles,
/// each 1/(2π) [A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))] with A = B = s/h).
fn square_blocked_fraction(s: f64, h: f64) -> f64 {
    let x = s / h;
    let r = (1.0 + x * x).sqrt();
    4.0 / PI * x / r * (x / r).atan()
}

#[test]
fn a_blocker_darkens_the_floor_by_its_form_factor() {
    let ctx = Validated::new();
    let (s, h) = (0.5f32, 0.5f32);
    let blocker = Transform { translation: Vec3::new(0.0, h, 0.0), ..Transform::default() };
    let scene = Scene::new(
        "blocker",
        vec![group("floor", plane(20.0), Transform::default()), group("blocker", plane(2.0 * s), blocker)],
        EnvMap::constant([1.0; 3]),
        side_camera(),
    );
    let size = 33;
    let stats = render(&ctx, &scene, size, LightMode::Environment, 5, 2048);
    let (got, se) = centre(&stats, size);
    let fraction = square_blocked_fraction(f64::from(s), f64::from(h));
    let expected = f64::from(RHO) * (1.0 - fraction);
    // 4 σ of one pixel, plus f32 rounding.
    assert!((got - expected).abs() <= 4.0 * se + 1e-5, "{got} ± {se} vs ρ(1 − {fraction}) = {expected}");
    assert!(se < 0.01, "standard error {se}");
}

#[test]
fn local_point_light_is_exact_and_a_blocker_makes_it_zero() {
    let ctx = Validated::new();
    let (height, intensity) = (2.0f32, [5.0f32, 2.0, 1.0]);
    let lights = vec![Light::Point { position: Vec3::new(0.0, height, 0.0), intensity }];
    // The environment is ignored in local mode: it contributes nothing.
    let floor = vec![group("floor", plane(20.0), Transform::default())];
    let mut scene =
        Scene { lights, ..Scene::new("point light", floor, EnvMap::constant([1.0; 3]), side_camera()) };
    let size = 33;
    let centre_rgb = |stats: &Statistics| stats.mean[((size / 2) * size + size / 2) as usize];
    let lit = render(&ctx, &scene, size, LightMode::Local, 0, 1);
    for (k, (got, i)) in centre_rgb(&lit).into_iter().zip(intensity).enumerate() {
        let expected = RHO / std::f32::consts::PI * i / (height * height);
        // Deterministic: only f32 rounding (a few ulps) separates it from the formula.
        assert!((got - expected).abs() <= 1e-6 * expected, "channel {k}: {got} vs {expected}");
    }
    // Background is black: the top-left pixel sees the sky above the horizon, and no surface
    // (coverage 0, the image's alpha), where the centre sees the floor.
    assert_eq!(lit.mean[0], [0.0; 3]);
    let centre = ((size / 2) * size + size / 2) as usize;
    assert_eq!((lit.local_coverage[0], lit.local_coverage[centre]), (0.0, 1.0));

    scene.groups.push(group(
        "blocker",
        plane(0.5),
        Transform { translation: Vec3::new(0.0, 0.5 * height, 0.0), ..Transform::default() },
    ));
    let shadowed = render(&ctx, &scene, size, LightMode::Local, 0, 1);
    assert_eq!(centre_rgb(&shadowed), [0.0; 3]);
    // Black there too, but a surface in shadow, not the sky.
    assert_eq!(shadowed.local_coverage[centre], 1.0);
}

#[test]
fn spot_light_lights_only_inside_its_cone() {
    let ctx = Validated::new();
    let spot = |direction: Vec3| Light::Spot {
        position: Vec3::new(0.0, 2.0, 0.0),
        direction,
        fov_deg: 60.0,
        intensity: [4.0; 3],
    };
    let size = 33;
    let mut values = Vec::new();
    for direction in [Vec3::NEG_Y, Vec3::X] {
        let scene = Scene {
            lights: vec![spot(direction).validated().unwrap()],
            ..Scene::new(
                "spot",
                vec![group("floor", plane(20.0), Transform::default())],
                EnvMap::constant([1.0; 3]),
                side_camera(),
            )
        };
        let stats = render(&ctx, &scene, size, LightMode::Local, 0, 1);
        values.push(centre(&stats, size).0);
    }
    let expected = f64::from(RHO) / PI * 4.0 / 4.0;
    assert!((values[0] - expected).abs() <= 1e-6 * expected, "{values:?}");
    assert_eq!(values[1], 0.0);
}

#[test]
fn black_map_renders_black_without_nan() {
    let ctx = Validated::new();
    let mut scene = Scene::builtin("teapot").unwrap();
    scene.environment = EnvMap::constant([0.0; 3]);
    let stats = render(&ctx, &scene, 16, LightMode::Environment, 0, 4);
    assert!(stats.mean.iter().flatten().all(|&v| v == 0.0));
    assert!(stats.standard_error.unwrap().iter().flatten().all(|&v| v == 0.0));
}

#[test]
fn default_scene_error_halves_when_samples_quadruple() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    let size = 32;
    let n = 8;
    // Independent seeds: the error between renders at N and 4N has variance σ²(1/N + 1/4N),
    // that between 4N and 16N σ²(1/4N + 1/16N), a quarter of it; so the ratio of relative
    // RMSEs is 2 in expectation.
    let images: Vec<RgbaF32Image> = [(1, n), (2, 4 * n), (3, 16 * n)]
        .into_iter()
        .map(|(seed, spp)| image(&render(&ctx, &scene, size, LightMode::Environment, seed, spp), size))
        .collect();
    let coarse = compare(&images[0], &images[1]).unwrap().relative_rmse;
    let fine = compare(&images[1], &images[2]).unwrap().relative_rmse;
    let ratio = coarse / fine;
    // Each RMSE is estimated from 32×32×3 values, but a few bright, noisy pixels (the sunlit
    // teapot rim) dominate, so the ratio scatters by roughly ±20 % around 2 from seed to seed.
    assert!((1.5..2.7).contains(&ratio), "relative RMSE {coarse} at N = {n}, {fine} at 4N: ratio {ratio}");
}
