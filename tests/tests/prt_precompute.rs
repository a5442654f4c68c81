//! PRT precomputation: the GPU transfer against closed forms, under rotation, and the
//! cache's detection of every kind of stale file.
use glam::{DVec3, Quat, Vec3};
use kage::prt::cache::{self, CacheKey, Stale};
use kage::prt::{lobe, transfer, PrtParams, TransferSet};
use kage::scene::{shapes, Camera, EnvMap, Group, Mesh, Scene, Transform};
use kage::sh;
use kage_tests::{scratch_dir, single_mesh_scene, Validated};

fn scene_of(groups: Vec<Vec<Mesh>>) -> Scene {
    let mut scene = single_mesh_scene(
        shapes::sphere("unused", 1.0, 3, [0.5; 3]).unwrap(),
        EnvMap::constant([1.0; 3]),
        Camera { position: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 },
    );
    scene.groups = groups
        .into_iter()
        .enumerate()
        .map(|(i, meshes)| Group::new(format!("group{i}"), meshes, Transform::default()))
        .collect();
    scene
}

fn precompute(ctx: &Validated, scene: &Scene, bands: u32, rays: u32) -> TransferSet {
    transfer::precompute(
        ctx,
        scene,
        PrtParams { bands, rays, ..PrtParams::DEFAULT },
        &mut kage::progress::silent,
    )
    .unwrap()
}

/// An open box (a cup) of half-width 1 and height `height` standing on y = 0, every face a
/// 5×5 grid with its own vertices and its flat normal pointing into the cup.
fn cup(height: f32) -> Mesh {
    const GRID: u32 = 5;
    // (corner, edge 1, edge 2) with edge 1 × edge 2 along the inward normal.
    let faces = [
        (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 2.0), Vec3::new(2.0, 0.0, 0.0)),
        (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, height, 0.0)),
        (Vec3::new(-1.0, 0.0, 1.0), Vec3::new(0.0, height, 0.0), Vec3::new(2.0, 0.0, 0.0)),
        (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(0.0, height, 0.0), Vec3::new(0.0, 0.0, 2.0)),
        (Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, height, 0.0)),
    ];
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for (corner, e1, e2) in faces {
        let first = positions.len() as u32;
        let n = e1.cross(e2).normalize();
        for j in 0..GRID {
            for i in 0..GRID {
                let (u, v) = (i as f32 / (GRID - 1) as f32, j as f32 / (GRID - 1) as f32);
                positions.push((corner + e1 * u + e2 * v).to_array());
                normals.push(n.to_array());
            }
        }
        let at = |i: u32, j: u32| first + j * GRID + i;
        for j in 0..GRID - 1 {
            for i in 0..GRID - 1 {
                indices.extend([at(i, j), at(i + 1, j), at(i, j + 1)]);
                indices.extend([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    Mesh::new("cup", positions, Some(normals), indices, [0.5; 3]).unwrap()
}

fn find_vertex(mesh: &Mesh, position: Vec3, normal: Vec3) -> usize {
    (0..mesh.vertex_count())
        .find(|&i| {
            Vec3::from(mesh.positions[i]).distance(position) < 1e-6
                && Vec3::from(mesh.normals[i]).distance(normal) < 1e-6
        })
        .expect("the cup has this vertex")
}

/// Cosine-weighted fraction of the hemisphere that a point sees through a parallel rectangle
/// [0, a] × [0, b] at distance c, with the point below one corner (the standard point-to-
/// rectangle form factor).
fn corner_form_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

#[test]
fn convex_object_matches_the_clamped_cosine_lobe() {
    let ctx = Validated::new();
    let mesh = shapes::sphere("ball", 1.0, 12, [0.5; 3]).unwrap();
    let scene = scene_of(vec![vec![mesh.clone()]]);
    for bands in [3, 5] {
        // No ray from a vertex of a convex mesh hits it, so only the quasi-Monte Carlo error of
        // the point set is left: about 1e-4 at 4096 rays, so 1e-3 (the bound) has
        // margin for the worst vertex.
        let set = precompute(&ctx, &scene, bands, 4096);
        let mut worst = 0.0f64;
        for (v, n) in mesh.normals.iter().enumerate() {
            let expected = lobe::clamped_cosine(bands as usize, Vec3::from(*n).as_dvec3());
            let got = set.vertex(0, 0, v).unwrap();
            assert_eq!(got.len(), expected.len());
            for (g, e) in got.iter().zip(&expected) {
                worst = worst.max((f64::from(*g) - e).abs());
            }
        }
        assert!(worst < 1e-3, "bands {bands}: worst coefficient error {worst}");
    }
}

#[test]
fn the_bottom_of_a_cup_gets_less_light_than_its_rim() {
    let ctx = Validated::new();
    let mesh = cup(2.0);
    let set = precompute(&ctx, &scene_of(vec![vec![mesh.clone()]]), 3, 4096);
    let bottom = find_vertex(&mesh, Vec3::ZERO, Vec3::Y);
    let rim = find_vertex(&mesh, Vec3::new(0.0, 2.0, -1.0), Vec3::Z);
    // T_00 = y_00 × the cosine-weighted visible fraction of the hemisphere.
    let y00 = 0.5 / std::f64::consts::PI.sqrt();
    let fraction = |v| f64::from(set.vertex(0, 0, v).unwrap()[0]) / y00;
    let (bottom, rim) = (fraction(bottom), fraction(rim));
    assert!(bottom < rim, "bottom {bottom} vs rim {rim}");
    // The bottom centre sees the 2×2 opening 2 above it (four corner rectangles); the rim sees
    // exactly its upper half. The edge of the opening makes the integrand discontinuous, so the
    // point set's error falls slower than 1/N: measured 0.01 at 1024 rays, 8e-4 at 8192; 0.01
    // leaves margin at 4096.
    let expected_bottom = 4.0 * corner_form_factor(1.0, 1.0, 2.0);
    assert!((bottom - expected_bottom).abs() < 0.01, "bottom {bottom} vs {expected_bottom}");
    assert!((rim - 0.5).abs() < 0.01, "rim {rim} vs 0.5");
}

#[test]
fn a_part_buried_in_another_takes_its_visible_neighbours_light() {
    // A ball of radius 0.6 piercing a ball of radius 1, one group (as a teapot's spout pierces
    // its body). The small ball's vertices inside the big one see only its inside; left at
    // zero, the rasterizer would spread that dark over the visible triangles they share.
    let ctx = Validated::new();
    let body = shapes::sphere("body", 1.0, 12, [0.5; 3]).unwrap();
    let mut spout = shapes::sphere("spout", 0.6, 12, [0.5; 3]).unwrap();
    for p in &mut spout.positions {
        p[0] += 1.0;
    }
    let set = precompute(&ctx, &scene_of(vec![vec![body, spout.clone()]]), 3, 1024);
    let y00 = 0.5 / std::f64::consts::PI.sqrt();
    let fraction = |v| f64::from(set.vertex(0, 1, v).unwrap()[0]) / y00;
    let inside: Vec<usize> =
        (0..spout.vertex_count()).filter(|&v| Vec3::from(spout.positions[v]).length() < 0.95).collect();
    assert!(inside.len() > 10, "{} spout vertices inside the body", inside.len());
    // Each takes the mean of its neighbours outside the body, ring by ring. The neighbours
    // nearest the crease see at least the half of their hemisphere facing away from the body
    // (its tangent plane at the crease bounds it): above 0.5 but for the cosine weighting and
    // the crease's angle, so 0.25 holds with margin, where a buried vertex has 0.
    for &v in &inside {
        assert!(fraction(v) > 0.25, "buried spout vertex {v} sees {}", fraction(v));
    }
    // The far side of the spout, seeing nothing of the body, keeps its own unshadowed transfer.
    let tip = (0..spout.vertex_count())
        .max_by(|&a, &b| spout.positions[a][0].total_cmp(&spout.positions[b][0]))
        .unwrap();
    assert!((fraction(tip) - 1.0).abs() < 1e-2, "tip sees {}", fraction(tip));
}

/// Evaluates a transfer vector as a function of direction: Σ T_i y_i(ω).
fn transfer_at(coeffs: &[f32], bands: usize, dir: DVec3) -> f64 {
    let mut y = [0.0; 25];
    let n = sh::eval_basis_f64(bands, dir, &mut y);
    coeffs.iter().zip(&y[..n]).map(|(c, y)| f64::from(*c) * y).sum()
}

#[test]
fn a_rotated_group_has_the_rotated_transfer() {
    let ctx = Validated::new();
    let original = cup(1.5);
    let rotation = Quat::from_euler(glam::EulerRot::YXZ, 0.7, -1.1, 0.4);
    let rotate = |v: &[f32; 3]| (rotation * Vec3::from(*v)).to_array();
    let rotated = Mesh::new(
        "rotated cup",
        original.positions.iter().map(rotate).collect(),
        Some(original.normals.iter().map(rotate).collect()),
        original.indices.clone(),
        [0.5; 3],
    )
    .unwrap();
    // Both in one scene, as two groups: visibility is tested within a group only, so they do
    // not see each other although they overlap.
    let set = precompute(&ctx, &scene_of(vec![vec![original.clone()], vec![rotated]]), 3, 4096);
    let rotation = rotation.as_dquat();
    // A vertex on a crease (where the floor meets a wall, or two walls meet) sends half its
    // rays exactly along the other face's plane, where rounding, not geometry, decides whether
    // they hit: rotating the mesh changes the rounding. Only the other vertices are compared.
    let on_crease = |v: usize| {
        (0..original.vertex_count()).any(|w| {
            Vec3::from(original.positions[w]).distance(Vec3::from(original.positions[v])) < 1e-6
                && original.normals[w] != original.normals[v]
        })
    };
    let mut worst = 0.0f64;
    let mut compared = 0;
    for v in (0..original.vertex_count()).filter(|&v| !on_crease(v)) {
        compared += 1;
        let a = set.vertex(0, 0, v).unwrap();
        let b = set.vertex(1, 0, v).unwrap();
        // The rotated vertex's transfer at R ω must be the original's at ω.
        for k in 0..64 {
            // A Fibonacci spiral: directions spread over the whole sphere.
            let z = 1.0 - (k as f64 + 0.5) / 32.0;
            let phi = k as f64 * 2.399963229728653;
            let r = (1.0 - z * z).sqrt();
            let dir = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let diff = transfer_at(a, 3, dir) - transfer_at(b, 3, rotation * dir);
            worst = worst.max(diff.abs());
        }
    }
    // Each coefficient carries an independent error of order 1e-3 at 4096 rays (binary
    // visibility near the cup's rim); nine of them summed with |y| < 1.1 stay below 0.01.
    assert!(compared > 40, "{compared} vertices compared");
    assert!(worst < 0.01, "worst difference {worst} over {compared} vertices");
}

#[test]
fn cache_round_trips_and_detects_every_kind_of_stale_file() {
    let ctx = Validated::new();
    let dir = scratch_dir("prt-cache");
    let scene = scene_of(vec![
        vec![shapes::sphere("ball", 1.0, 8, [0.5; 3]).unwrap()],
        vec![cup(1.0), shapes::sphere("small", 0.3, 6, [0.2; 3]).unwrap()],
    ]);
    let params = PrtParams { bands: 3, rays: 32, ..PrtParams::DEFAULT };
    let set = transfer::precompute(&ctx, &scene, params, &mut kage::progress::silent).unwrap();
    let key = CacheKey::new(&scene, params);
    let path = dir.join(key.file_name());
    assert_eq!(cache::load(&path, &key), Err(Stale::Missing));
    let bytes = cache::save(&path, &set, &key).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), bytes);
    assert_eq!(cache::load(&path, &key).unwrap(), set);

    // The transfer is in object space and leaves the albedo out: neither a new transform nor
    // a new albedo makes the file stale.
    let mut moved = scene.clone();
    moved.groups[1].transform.translation = Vec3::new(3.0, 0.0, 1.0);
    moved.groups[1].transform.rotation = Quat::from_rotation_y(1.0);
    moved.groups[0].meshes[0].albedo = [0.9, 0.1, 0.1];
    let moved_key = CacheKey::new(&moved, params);
    assert_eq!(moved_key, key);
    assert_eq!(cache::load(&path, &moved_key).unwrap(), set);

    let mut changed = scene.clone();
    changed.groups[1].meshes[0].positions[3][1] += 1e-3;
    assert_eq!(cache::load(&path, &CacheKey::new(&changed, params)), Err(Stale::Geometry));
    let mut regrouped = scene.clone();
    let small = regrouped.groups[1].meshes.pop().unwrap();
    regrouped.groups[0].meshes.push(small);
    assert_eq!(cache::load(&path, &CacheKey::new(&regrouped, params)), Err(Stale::Geometry));
    let other = |bands, rays| CacheKey::new(&scene, PrtParams { bands, rays, ..PrtParams::DEFAULT });
    assert_eq!(cache::load(&path, &other(4, 32)), Err(Stale::Bands { found: 3, wanted: 4 }));
    assert_eq!(cache::load(&path, &other(3, 64)), Err(Stale::Rays { found: 32, wanted: 64 }));

    let good = std::fs::read(&path).unwrap();
    let damaged = |edit: &dyn Fn(&mut Vec<u8>)| {
        let mut bytes = good.clone();
        edit(&mut bytes);
        let file = dir.join("damaged.kageprt");
        std::fs::write(&file, bytes).unwrap();
        cache::load(&file, &key).unwrap_err()
    };
    assert_eq!(damaged(&|b| b[8] ^= 1), Stale::Version { found: cache::FORMAT_VERSION ^ 1 });
    assert!(matches!(damaged(&|b| b.truncate(b.len() - 1)), Stale::Truncated { .. }));
    assert!(matches!(damaged(&|b| b.truncate(20)), Stale::Truncated { .. }));
    assert!(matches!(damaged(&|b| b.push(0)), Stale::TrailingBytes { .. }));
    let last = good.len() - 1;
    assert_eq!(damaged(&|b| b[last] ^= 0x40), Stale::Checksum);
    assert_eq!(damaged(&|b| *b = b"not a cache file at all".to_vec()), Stale::NotACacheFile);
    assert_eq!(damaged(&|b| b.clear()), Stale::NotACacheFile);
    // Every reason reads as a sentence for the CLI.
    assert!(Stale::Geometry.to_string().contains("geometry changed"));

    // A rebuilt file replaces the stale one in place (what `--force` and a rebuild do).
    std::fs::write(&path, b"garbage").unwrap();
    cache::save(&path, &set, &key).unwrap();
    assert_eq!(cache::load(&path, &key).unwrap(), set);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n.to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn bad_parameters_are_errors_not_panics() {
    let ctx = Validated::new();
    let scene = scene_of(vec![vec![shapes::sphere("ball", 1.0, 4, [0.5; 3]).unwrap()]]);
    for (bands, rays) in [(1, 64), (6, 64), (3, 0), (3, u32::MAX)] {
        let err = transfer::precompute(
            &ctx,
            &scene,
            PrtParams { bands, rays, ..PrtParams::DEFAULT },
            &mut kage::progress::silent,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("PRT with"), "{err}");
    }
}

/// The shader's lanes cast a vertex's rays in another order than the Hammersley index (eight
/// neighbouring points side by side); the sums must still be over every point once. On a
/// sphere nothing is occluded, so each coefficient is the mean of the basis over the shader's
/// directions, which `directions::direction` computes on the CPU in index order. A point
/// cast twice and another never moves a mean by about 1/rays (5e-4 at 2048), far beyond the
/// float rounding of 2048 terms (~1e-6, the bound 1e-5); 2048 rays are reordered, 100 (not a
/// power of two) are not.
#[test]
fn every_direction_is_cast_once_whatever_order_the_lanes_take() {
    let ctx = Validated::new();
    let sphere = shapes::sphere("sphere", 1.0, 6, [0.5; 3]).unwrap();
    let scene = scene_of(vec![vec![sphere.clone()]]);
    for rays in [2048, 100] {
        let set = precompute(&ctx, &scene, 3, rays);
        for vertex in [0, 7, sphere.vertex_count() / 2, sphere.vertex_count() - 1] {
            let n = Vec3::from(sphere.normals[vertex]).normalize();
            let mut want = [0.0f64; 9];
            for k in 0..rays {
                let mut y = [0.0f32; 9];
                sh::eval_basis(3, kage::prt::directions::direction(vertex as u32, n, k, rays), &mut y);
                for (w, y) in want.iter_mut().zip(y) {
                    *w += f64::from(y) / f64::from(rays);
                }
            }
            let got = set.vertex(0, 0, vertex).unwrap();
            for (i, (g, w)) in got.iter().zip(want).enumerate() {
                assert!(
                    (f64::from(*g) - w).abs() < 1e-5,
                    "{rays} rays, vertex {vertex}, coefficient {i}: GPU {g}, CPU mean over every point {w}"
                );
            }
        }
    }
}
