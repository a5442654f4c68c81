//! Light probe capture on the GPU: cube maps of the scene projected to SH, checked against what
//! the maths says.
use glam::Vec3;
use kage::frame::GpuScene;
use kage::scene::{Camera, EnvMap, Light, Scene};
use kage::techniques::probes::{CaptureSettings, CapturedLight, ProbeCapture};
use kage_tests::Validated;
use std::f32::consts::PI;

/// Small faces keep the tests fast on lavapipe; the maths below holds at any size.
const SIDE: u32 = 16;

/// Cube faces of SIDE², the walls lit by the ray caster with few samples (these tests look at
/// the projection and the walls' colours, not the radiance's noise).
fn sky_and_walls() -> CaptureSettings {
    CaptureSettings { cube_size: SIDE, light: CapturedLight::SkyAndWalls, samples: 32, ..Default::default() }
}

#[test]
fn constant_environment_with_no_walls_captures_its_own_sh() {
    let ctx = Validated::new();
    let radiance = [0.5, 1.0, 2.0];
    let scene = Scene::new(
        "empty",
        vec![],
        EnvMap::constant(radiance),
        Camera { position: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 },
    );
    let gpu = GpuScene::new(&ctx, &scene).unwrap();
    let settings = sky_and_walls();
    let mut capture = ProbeCapture::new(&ctx, &scene, settings).unwrap();
    let sh = capture.capture(&gpu, |_| true, Vec3::new(0.3, -2.0, 7.0)).unwrap();
    // A constant L has c0 = L·Y0·4π = 2√π·L and nothing else. The texel solid angles telescope
    // (neighbours share their corner terms bit for bit), so they add up to 4π up to the f32
    // rounding of the sums; the bands above 0 cancel by the cube's symmetry (odd terms between
    // opposite texels, x², y², z² each a third of 4π). Left: f32 accumulation over 6·16² texels,
    // a few 1e-7 relative; the bound is 1e-5 of c0.
    for (k, l) in radiance.into_iter().enumerate() {
        let c0 = 2.0 * PI.sqrt() * l;
        let tolerance = 1e-5 * c0;
        assert!((sh.c[0][k] - c0).abs() < tolerance, "c0[{k}] = {} vs {c0}", sh.c[0][k]);
        for i in 1..9 {
            assert!(sh.c[i][k].abs() < tolerance, "c{i}[{k}] = {}", sh.c[i][k]);
        }
    }
}

#[test]
fn a_probe_near_the_red_wall_sees_red_on_its_side() {
    let ctx = Validated::new();
    let scene = Scene::builtin("probe-room").unwrap();
    let gpu = GpuScene::new(&ctx, &scene).unwrap();
    let settings = sky_and_walls();
    let mut capture = ProbeCapture::new(&ctx, &scene, settings).unwrap();
    // The bunny (group 0) moves: probes capture the room alone.
    let sh = capture.capture(&gpu, |group| group != 0, Vec3::new(-1.2, 1.2, 0.5)).unwrap();
    // The linear band (c1, c2, c3) ∝ (y, z, x) points where the light comes from, relative to
    // its channel's average (c0). The grey sky through the opening (up, towards +X from here)
    // outshines the walls, which it lights only through the opening; on it the red wall adds
    // red from −X, the green wall green from +X.
    let x = |channel: usize| sh.c[3][channel] / sh.c[0][channel];
    assert!(x(0) < x(1) && x(0) < x(2), "red {} green {} blue {}", x(0), x(1), x(2));
    assert!(x(1) > x(2), "green {} blue {}", x(1), x(2));

    // With black walls only the sky through the ceiling's opening is left: light from above
    // (c1 ∝ y).
    let settings = CaptureSettings { light: CapturedLight::Sky, ..settings };
    let sky = ProbeCapture::new(&ctx, &scene, settings).unwrap().capture(&gpu, |g| g != 0, Vec3::Y).unwrap();
    assert!((0..3).all(|k| sky.c[1][k] > 0.5 * sky.c[0][k]), "{:?} {:?}", sky.c[0], sky.c[1]);
}

#[test]
fn a_probe_millimetres_from_a_wall_does_not_see_through_it() {
    let ctx = Validated::new();
    let scene = Scene::builtin("probe-room").unwrap();
    let gpu = GpuScene::new(&ctx, &scene).unwrap();
    let settings = CaptureSettings { cube_size: 128, light: CapturedLight::Sky, ..Default::default() };
    let mut capture = ProbeCapture::new(&ctx, &scene, settings).unwrap();
    // The red wall is the plane x = −2, single-sided, with the bright sky behind it. 3 mm from
    // it the wall must still hide that sky: the probe sees what one 3 cm away sees, less the
    // change in the opening's solid angle over those 27 mm (about 2.2 m away: a few %; 2.8 %
    // measured at 128² faces, where the opening's edges cost under 1 % in texels). A near plane
    // of 1 cm clipped the wall and let the sky behind it in (c0 about 450 times as large).
    let mut at = |d: f32| capture.capture(&gpu, |g| g != 0, Vec3::new(-2.0 + d, 1.2, 0.5)).unwrap();
    let (near, far) = (at(0.003), at(0.03));
    for k in 0..3 {
        let c0 = (near.c[0][k], far.c[0][k]);
        assert!((c0.0 - c0.1).abs() < 0.05 * c0.1, "channel {k}: c0 {} at 3 mm, {} at 3 cm", c0.0, c0.1);
    }
}

#[test]
fn bad_cube_sizes_are_named() {
    for size in [0, 7, 257] {
        let error = CaptureSettings { cube_size: size, ..Default::default() }.validated().unwrap_err();
        assert!(error.to_string().contains(&format!("cube map size {size} must be 8 to 256")), "{error}");
    }
}

/// A point light is added to a probe's SH as the delta of radiance it is, (I / d²) y_i(l), where
/// the probe sees it, and not at all where the static groups hide it: above probe-room's ceiling
/// it reaches the probe only through the opening.
#[test]
fn a_point_light_is_captured_where_the_probe_sees_it() {
    let ctx = Validated::new();
    let base = Scene::builtin("probe-room").unwrap();
    let gpu = GpuScene::new(&ctx, &base).unwrap();
    let settings = CaptureSettings { cube_size: 8, light: CapturedLight::Sky, ..Default::default() };
    let probe = Vec3::new(0.0, 1.0, 0.0);
    let capture = |light: Option<Vec3>| {
        let mut scene = base.clone();
        scene.lights.extend(light.map(|position| Light::Point { position, intensity: [2.0, 1.0, 0.5] }));
        ProbeCapture::new(&ctx, &scene, settings).unwrap().capture(&gpu, |g| g != 0, probe).unwrap()
    };
    let dark = capture(None);
    // Through the opening: the line to it crosses the ceiling's plane at x = 0.2, z = 0.15,
    // inside the opening's ±0.6.
    let seen = Vec3::new(0.4, 4.0, 0.3);
    let lit = capture(Some(seen));
    let to = seen - probe;
    let (d2, l) = (to.length_squared(), to.normalize());
    let y = [0.282095, 0.488603 * l.y, 0.488603 * l.z, 0.488603 * l.x];
    for (i, y) in y.into_iter().enumerate() {
        for (k, intensity) in [2.0, 1.0, 0.5].into_iter().enumerate() {
            let expected = dark.c[i][k] + intensity / d2 * y;
            // The same cube map both times: only f32 rounding of the sum differs.
            assert!((lit.c[i][k] - expected).abs() <= 1e-5 * expected.abs().max(1.0), "c{i}[{k}]");
        }
    }
    // Behind the ceiling: nothing added, bit for bit.
    assert_eq!(capture(Some(Vec3::new(1.5, 3.0, 1.5))), dark);
}
