//! Where light probes are known to fail, each case tested: a tiny bright sun rings the nine
//! coefficients' irradiance negative (clamped in the shading, or removed by a deringing
//! window).
use glam::{DVec3, Vec3};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::{shapes, Camera, EnvMap, Group, Scene, Transform};
use kage::sh::ShRgb9;
use kage::techniques::description::TechniqueDesc;
use kage::techniques::probes::{CaptureSettings, CapturedLight, Dering, ProbePlacement, ProbeSettings};
use kage_tests::Validated;
use std::sync::Arc;

/// A black 64×32 map with one texel of radiance 20,000 about 25° from the zenith: a sun.
fn sun_map() -> EnvMap {
    let (w, h) = (64u32, 32u32);
    let mut pixels = vec![[0.0f32; 3]; (w * h) as usize];
    pixels[(4 * w + 40) as usize] = [20_000.0; 3];
    EnvMap::from_pixels(w, h, pixels).unwrap()
}

/// A small sphere over a floor, under the sun. No group has keyframes, so the first, the sphere,
/// is the moving one the probes light (`ProbeGroups`' fallback).
fn sun_scene() -> Scene {
    let group = |name: &str, mesh, y: f32| {
        Group::new(
            name,
            vec![mesh],
            Transform { translation: Vec3::new(0.0, y, 0.0), ..Transform::default() },
        )
    };
    Scene::new(
        "sun",
        vec![
            group("ball", shapes::sphere("ball", 0.5, 16, [0.8; 3]).unwrap(), 1.0),
            group("floor", shapes::plane("floor", [4.0, 4.0], [3, 3], [0.5; 3]).unwrap(), 0.0),
        ],
        sun_map(),
        Camera { position: Vec3::new(0.0, 1.0, 3.0), target: Vec3::Y, up: Vec3::Y, fov_y_deg: 40.0 },
    )
}

/// Probes around the ball: a tetrahedron's corners and its centre.
fn probes(dering: Dering) -> ProbeSettings {
    let positions: Vec<DVec3> =
        [[0.0, 2.0, 0.0], [1.0, 0.5, 1.0], [-1.0, 0.5, 1.0], [0.0, 0.5, -1.4], [0.0, 1.0, 0.2]]
            .into_iter()
            .map(DVec3::from)
            .collect();
    ProbeSettings {
        placement: ProbePlacement::Positions(Arc::from(positions)),
        capture: CaptureSettings { cube_size: 16, light: CapturedLight::Sky, dering, ..Default::default() },
        ..Default::default()
    }
}

/// The least and the largest irradiance (red) over 2,000 normals spread over the sphere
/// (a Fibonacci lattice).
fn irradiance_range(sh: &ShRgb9) -> (f32, f32) {
    let n = 2000;
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let phi = i as f32 * std::f32::consts::PI * (3.0 - 5f32.sqrt());
            let r = (1.0 - y * y).sqrt();
            sh.irradiance(Vec3::new(r * phi.cos(), y, r * phi.sin()))[0]
        })
        .fold((f32::MAX, f32::MIN), |(lo, hi), e| (lo.min(e), hi.max(e)))
}

#[test]
fn a_tiny_sun_rings_negative_the_shading_clamps_it_and_deringing_removes_it() {
    let ctx = Validated::new();
    let scene = sun_scene();
    let options = |dering| RenderOptions {
        width: 32,
        height: 32,
        technique: TechniqueDesc::Probes { probes: probes(dering), prt: kage::prt::PrtParams::DEFAULT },
        transfer: None,
    };
    let mut renderer = Renderer::new(&ctx, &scene, &options(Dering::Off)).unwrap();
    renderer.render().unwrap();
    let image = renderer.image().unwrap();
    // The shading clamps E at 0: no pixel negative or NaN, though the probes' E is (below).
    assert!(image.pixels.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));

    // The probe at the ball's centre (index 4) sees the sun unblocked: its E(n) is the sun's
    // power times k₂(n·s), whose minimum is −0.0396 against a peak of 1.0625 (dering.rs): −3.7%.
    let capture = |dering| {
        let gpu = kage::frame::GpuScene::new(&ctx, &scene).unwrap();
        let set = kage::techniques::probes::ProbeSet::capture(
            &ctx,
            &scene,
            &gpu,
            &probes(dering),
            &mut kage::progress::silent,
        )
        .unwrap();
        irradiance_range(&set.sh[4])
    };
    let (raw_min, raw_max) = capture(Dering::Off);
    eprintln!("raw: min {raw_min} max {raw_max} ({:.2}%)", 100.0 * raw_min / raw_max);
    // The sun covers a texel, not a point, and the floor hides the lower half: the ratio is
    // near, not at, −3.7%; 3% is well outside the f32 noise of the projection.
    assert!(raw_min < -0.03 * raw_max, "no negative lobe: {raw_min} of {raw_max}");

    // A non-negative kernel gives a non-negative E for any light (dering.rs); left: f32
    // rounding of the projection, 1e-5 of the peak.
    let (min, max) = capture(Dering::NonNegative);
    eprintln!("nonnegative: min {min} max {max}");
    assert!(min > -1e-5 * max, "deringed minimum {min} of {max}");
    // Hanning at w = 4 shrinks the lobe to about 0.6 of the raw one (kernel minima −0.0226
    // against −0.0396), keeping band 2 at half weight.
    let (min, max) = capture(Dering::Hanning(4.0));
    eprintln!("hanning:4: min {min} max {max}");
    assert!(min < 0.0 && min > 0.7 * raw_min, "hanning minimum {min} against {raw_min}");
}

/// A probe inside a wall slab of probe-room is detected (it sees back faces all round), left
/// out of the tetrahedralization, and the moving group's lighting stays finite.
#[test]
fn a_probe_inside_a_wall_is_detected_and_left_out() {
    let ctx = Validated::new();
    let mut scene = Scene::builtin("probe-room").unwrap();
    // A partition slab 0.3 thick standing on the floor against the blue wall.
    let slab = shapes::boxes("slab", &[([-0.15, 0.0, -2.0], [0.15, 2.5, -0.8])], [0.6; 3]).unwrap();
    scene.groups[1].meshes.push(slab);
    let inside = DVec3::new(0.0, 1.2, -1.4);
    let mut positions: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -1.2 } else { 1.2 },
                if i & 2 == 0 { 0.5 } else { 2.0 },
                if i & 4 == 0 { -0.5 } else { 1.5 },
            )
        })
        .collect();
    positions.push(inside);
    let settings = ProbeSettings {
        placement: ProbePlacement::Positions(Arc::from(positions.clone())),
        capture: CaptureSettings { cube_size: 8, light: CapturedLight::Sky, ..Default::default() },
        ..Default::default()
    };
    let capture = kage::techniques::probes::ProbeCapture::new(&ctx, &scene, settings.capture).unwrap();
    // Inside the slab nearly every direction meets a back face first: not all, as its bottom
    // and back faces lie in the floor's and the blue wall's planes, whose front faces the rays
    // going down or back may meet first at the same distance (measured: 93%). In the room none
    // does (all of probe-room's panels and the slab's faces face into the room's air).
    let fraction = capture.back_faces(inside.as_vec3());
    assert!(fraction > 0.75, "{fraction}");
    assert!(positions[..8].iter().all(|p| capture.back_faces(p.as_vec3()) == 0.0));

    let gpu = kage::frame::GpuScene::new(&ctx, &scene).unwrap();
    let set = kage::techniques::probes::ProbeSet::capture(
        &ctx,
        &scene,
        &gpu,
        &settings,
        &mut kage::progress::silent,
    )
    .unwrap();
    assert_eq!(set.invalid.len(), 1);
    assert_eq!((set.invalid[0].index, set.invalid[0].position), (8, inside));
    assert_eq!(set.mesh.positions().len(), 8, "the probe in the slab is not tetrahedralized");

    let options = RenderOptions {
        width: 24,
        height: 24,
        technique: TechniqueDesc::Probes { probes: settings, prt: kage::prt::PrtParams::DEFAULT },
        transfer: None,
    };
    let mut renderer = Renderer::new(&ctx, &scene, &options).unwrap();
    renderer.render().unwrap();
    assert!(renderer.image().unwrap().pixels.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
}
