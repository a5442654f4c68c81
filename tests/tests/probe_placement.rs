//! Automatic probe placement and the trilinear grid baseline, end to end at a tiny size: real
//! captures (8² faces) in the built-in scenes.
use glam::Vec3;
use kage::frame::GpuScene;
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::Scene;
use kage::techniques::description::TechniqueDesc;
use kage::techniques::probes::{
    CaptureSettings, CapturedLight, Occluders, ProbeInterpolation, ProbePlacement, ProbeSet, ProbeSettings,
    Solids,
};
use kage_tests::Validated;

fn tiny(placement: ProbePlacement, interpolation: ProbeInterpolation) -> ProbeSettings {
    ProbeSettings {
        placement,
        capture: CaptureSettings { cube_size: 8, light: CapturedLight::Sky, ..Default::default() },
        interpolation,
        ..Default::default()
    }
}

#[test]
fn automatic_placement_drops_redundant_candidates_in_probe_room() {
    let ctx = Validated::new();
    let scene = Scene::builtin("probe-room").unwrap();
    let gpu = GpuScene::new(&ctx, &scene).unwrap();
    let auto = |tolerance| {
        let placement = ProbePlacement::Auto { tolerance, candidates: Some([3, 3, 3]) };
        ProbeSet::capture(
            &ctx,
            &scene,
            &gpu,
            &tiny(placement, ProbeInterpolation::Tetrahedral),
            &mut kage::progress::silent,
        )
        .unwrap()
    };
    // A loose tolerance keeps few of the 27 candidates (the room has no solid inside); a
    // tighter one keeps at least as many: the greedy pass only drops what it reproduces.
    let (loose, tight) = (auto(4.0), auto(0.05));
    assert_eq!((loose.candidates, tight.candidates), (27, 27));
    assert!(loose.probe_count() >= 4 && loose.probe_count() < 27, "{} kept", loose.probe_count());
    assert!(tight.probe_count() >= loose.probe_count(), "{} < {}", tight.probe_count(), loose.probe_count());
}

#[test]
fn candidates_inside_the_atriums_walls_and_columns_are_not_captured() {
    let scene = Scene::builtin("atrium").unwrap();
    let settings = tiny(
        ProbePlacement::Auto { tolerance: 0.1, candidates: Some([16, 5, 16]) },
        ProbeInterpolation::Tetrahedral,
    );
    let candidates = settings.positions(&scene, &Occluders::of_static(&scene).unwrap()).unwrap();
    let solids = Solids::of_static(&scene);
    // The walls, the columns and the arches' boxes hold a few of the 1,280 cell centres.
    assert!(candidates.len() < 16 * 5 * 16 && candidates.len() > 1000, "{}", candidates.len());
    assert!(candidates.iter().all(|p| !solids.contains(p.as_vec3())));
}

#[test]
fn trilinear_interpolation_needs_a_grid_and_lights_the_bunny() {
    let ctx = Validated::new();
    let auto = ProbePlacement::Auto { tolerance: 0.1, candidates: None };
    let error = tiny(auto, ProbeInterpolation::Trilinear).validated().unwrap_err().to_string();
    assert!(error.contains("trilinear probe interpolation needs a probe grid"), "{error}");
    let error =
        tiny(ProbePlacement::Auto { tolerance: -1.0, candidates: None }, ProbeInterpolation::Tetrahedral)
            .validated()
            .unwrap_err()
            .to_string();
    assert!(error.contains("tolerance -1 must be a positive number"), "{error}");

    let mut scene = Scene::builtin("probe-room").unwrap();
    scene.camera.position = Vec3::new(0.0, 0.35, 1.2);
    scene.camera.target = Vec3::new(0.0, 0.35, 0.0);
    let probes = tiny(ProbePlacement::Grid([2, 2, 2]), ProbeInterpolation::Trilinear);
    let options = RenderOptions {
        width: 24,
        height: 24,
        technique: TechniqueDesc::Probes { probes, prt: kage::prt::PrtParams::DEFAULT },
        transfer: None,
    };
    let mut renderer = Renderer::new(&ctx, &scene, &options).unwrap();
    renderer.render().unwrap();
    let image = renderer.image().unwrap();
    // The bunny in the middle of the image is lit (the sky through the opening reaches every
    // probe of the grid), and nothing is NaN.
    let middle = image.pixels[(12 * image.width + 12) as usize];
    assert!(image.pixels.iter().flatten().all(|v| v.is_finite()));
    assert!(middle.iter().take(3).any(|&v| v > 0.0), "{middle:?}");
}
