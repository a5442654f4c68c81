//! The parallel-lights baseline (the paper's Fig. 3): q regions as directional lights with
//! binary shadow maps.
use glam::Vec3;
use kage::frame::regions::Regions;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{shapes, Camera, EnvMap, Scene};
use kage::techniques::description::TechniqueDesc;
use kage_tests::{single_mesh_scene, Validated};

fn parallel(regions: usize) -> TechniqueDesc {
    TechniqueDesc::ParallelLights { regions, shadow_map_size: 512 }
}

fn render(ctx: &Validated, scene: &Scene, size: u32, technique: TechniqueDesc) -> Vec<[f32; 4]> {
    let mut r =
        Renderer::new(ctx, scene, &RenderOptions { width: size, height: size, technique, transfer: None })
            .unwrap();
    r.render().unwrap();
    r.image().unwrap().pixels
}

/// The primary ray through the centre of pixel (x, y), as the renderer's camera casts it.
fn pixel_ray(camera: &Camera, x: u32, y: u32, size: u32) -> Vec3 {
    let inv = (camera.projection(1.0) * camera.view()).inverse();
    let ndc = glam::Vec2::new(
        (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
        (y as f32 + 0.5) / size as f32 * 2.0 - 1.0,
    );
    let far = inv.project_point3(ndc.extend(1.0));
    (far - camera.position).normalize()
}

/// A convex sphere alone under a constant environment: nothing occludes a point from a light
/// it faces, so every pixel is albedo/π · Σ B_i max(n·ω_i, 0) with the regions' own B_i and ω_i.
/// The tolerance (1.5%) covers the tessellated sphere's interpolated normals against the
/// analytic ones and the lights that graze a point, where a binary map may call a lit point
/// shadowed (their weight n·ω_i is then near zero); a missing region costs about 1/q ≈ 6%.
#[test]
fn unoccluded_sphere_gets_the_sum_over_regions() {
    let ctx = Validated::new();
    let (rho, q) = (0.6f32, 16);
    let camera =
        Camera { position: Vec3::new(0.0, 0.5, 4.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
    let environment = EnvMap::constant([1.0; 3]);
    let regions = Regions::new(&environment, q).unwrap();
    let scene = single_mesh_scene(shapes::sphere("sphere", 1.0, 64, [rho; 3]).unwrap(), environment, camera);
    let size = 64;
    let image = render(&ctx, &scene, size, parallel(q));
    let mut checked = 0;
    for (x, y) in [(32, 32), (24, 28), (40, 36), (30, 20), (36, 44), (22, 40), (42, 24)] {
        let dir = pixel_ray(&camera, x, y, size);
        // Ray-sphere intersection (unit sphere at the origin); the normal is the hit point.
        let (o, d) = (camera.position, dir);
        let b = o.dot(d);
        let disc = b * b - (o.length_squared() - 1.0);
        assert!(disc > 0.1, "pixel ({x}, {y}) is not well inside the sphere");
        let n = (o + d * (-b - disc.sqrt())).as_dvec3().normalize();
        let sum: f64 = regions.regions.iter().map(|r| r.energy[0] * n.dot(r.direction).max(0.0)).sum();
        let expected = rho as f64 / std::f64::consts::PI * sum;
        let got = image[(y * size + x) as usize];
        for k in 0..3 {
            assert!(
                (got[k] as f64 - expected).abs() <= 0.015 * expected,
                "pixel ({x}, {y}), n = {n:?}: {got:?}, expected {expected}"
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 7);
}

fn luminance(p: [f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// The teapot's shadow: the floor right beside its base is darker than the same floor point with
/// the teapot group taken out of the scene. The default map's light comes mostly from behind the
/// teapot, so the point in front of it loses only part of it (measured: about 9% of the
/// luminance at q = 32); 5% is well clear of zero for a deterministic image.
#[test]
fn the_teapot_shadows_the_floor() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    assert_eq!(scene.groups[0].name, "teapot");
    let mut floor_only = scene.clone();
    floor_only.groups.remove(0);
    let size = 96;
    let with = render(&ctx, &scene, size, parallel(32));
    let without = render(&ctx, &floor_only, size, parallel(32));
    let view_proj = scene.camera.projection(1.0) * scene.camera.view();
    let clip = view_proj * Vec3::new(0.0, 0.0, 0.5).extend(1.0);
    let ndc = clip.truncate() / clip.w;
    let (x, y) = (((ndc.x + 1.0) * 0.5 * size as f32) as u32, ((ndc.y + 1.0) * 0.5 * size as f32) as u32);
    let near = (y * size + x) as usize;
    assert!(
        luminance(with[near]) < 0.95 * luminance(without[near]),
        "no shadow at ({x}, {y}): {:?} with the teapot, {:?} without",
        with[near],
        without[near]
    );
    assert!(with.iter().chain(&without).all(|p| p[..3].iter().all(|c| *c >= 0.0 && c.is_finite())));
}

/// q must be 1 to 128, and the shadow map a sensible size; the error says so.
#[test]
fn region_count_and_map_size_are_checked() {
    let ctx = Validated::new();
    let scene = Scene::builtin("teapot").unwrap();
    let attempt = |technique| match Renderer::new(
        &ctx,
        &scene,
        &RenderOptions { width: 16, height: 16, technique, transfer: None },
    ) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    for q in [0, 129] {
        let message = attempt(parallel(q));
        assert!(message.contains("1 to 128"), "q = {q}: {message}");
    }
    let message = attempt(TechniqueDesc::ParallelLights { regions: 8, shadow_map_size: 4 });
    assert!(message.contains("shadow map size"), "{message}");
}
