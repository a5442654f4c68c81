//! The GPU BVH (bvh.glsl through shaders-glsl/raycast.comp) against brute force on the CPU:
//! every triangle, the same watertight test, straight from the scene.
//!
//! Tolerances: hit distances agree to 1e-4 relative (the two sides round the ray transform
//! differently, a few ulps; packets' hits, tested in another form, within what rounding the
//! corners allows, `packet_hit_close`); rays passing within 1e-5 of any triangle edge are left out, since
//! there rounding decides legitimately which neighbour (or, at a silhouette, whether anything)
//! is hit.
use glam::{Mat4, Quat, Vec3};
use kage::layouts::{constants, CastRay, CastResult};
use kage::raycast::{
    closest_hit_brute_force, edge_distance, occluded_object_space_brute_force, offset_ray_origin, GpuBvh,
    GpuRays, Query, RayCaster, SceneBvh, TriangleOrigin,
};
use kage::scene::{Camera, EnvMap, Group, Mesh, Scene, Transform};
use kage_tests::Validated;

const EDGE_MARGIN: f64 = 1e-5;
const T_TOLERANCE: f32 = 1e-4;
const INFINITE: f32 = 1e30;

/// A small deterministic generator (PCG32), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let x = (((self.0 >> 18) ^ self.0) >> 27) as u32;
        let x = x.rotate_right((self.0 >> 59) as u32);
        (x >> 8) as f32 / (1 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }

    fn vec(&mut self, half: f32) -> Vec3 {
        Vec3::new(self.range(-half, half), self.range(-half, half), self.range(-half, half))
    }

    fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.vec(1.0);
            if (0.01..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}

fn scene(groups: Vec<Group>) -> Scene {
    Scene::new(
        "bvh-test",
        groups,
        EnvMap::constant([1.0; 3]),
        Camera { position: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 },
    )
}

fn random_transform(rng: &mut Rng) -> Transform {
    Transform {
        translation: rng.vec(3.0),
        rotation: Quat::from_axis_angle(rng.direction(), rng.range(0.0, std::f32::consts::TAU)),
        scale: rng.range(0.5, 2.0),
    }
}

/// Groups of scattered random triangles (one or two meshes each) under random transforms.
fn random_scene(rng: &mut Rng, groups: usize, triangles: usize) -> Scene {
    let groups = (0..groups)
        .map(|g| {
            Group::new(
                format!("group{g}"),
                (0..1 + g % 2)
                    .map(|m| {
                        let positions: Vec<[f32; 3]> = (0..triangles)
                            .flat_map(|_| {
                                let centre = rng.vec(1.0);
                                [0; 3].map(|_| (centre + rng.vec(0.3)).to_array())
                            })
                            .collect();
                        let indices = (0..3 * triangles as u32).collect();
                        Mesh::new(format!("mesh{m}"), positions, None, indices, [0.5; 3]).unwrap()
                    })
                    .collect(),
                random_transform(rng),
            )
        })
        .collect();
    scene(groups)
}

/// Half of the rays aim at a random point of a random triangle, so that many hit; the others
/// start anywhere and go anywhere.
fn random_rays(rng: &mut Rng, scene: &Scene, count: usize) -> Vec<(Vec3, Vec3)> {
    let triangles: Vec<[Vec3; 3]> = scene
        .meshes()
        .flat_map(|(g, m)| {
            let to_world = g.transform.matrix();
            m.indices.chunks_exact(3).map(move |t| {
                t.iter()
                    .map(|&i| to_world.transform_point3(m.positions[i as usize].into()))
                    .collect::<Vec<_>>()
                    .try_into()
                    .unwrap()
            })
        })
        .collect();
    (0..count)
        .map(|i| {
            let origin = rng.vec(6.0);
            if i % 2 == 0 && !triangles.is_empty() {
                let t = triangles[(rng.next() * triangles.len() as f32) as usize % triangles.len()];
                let (a, b) = (rng.next(), rng.next());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let target = t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]);
                (origin, (target - origin).normalize())
            } else {
                (origin, rng.direction())
            }
        })
        .collect()
}

fn cast(
    ctx: &Validated,
    caster: &mut RayCaster,
    bvh: &GpuBvh,
    rays: &[(Vec3, Vec3, f32)],
    query: Query,
) -> Vec<CastResult> {
    let rays: Vec<CastRay> = rays
        .iter()
        .map(|(o, d, tmax)| CastRay {
            origin: o.extend(*tmax).to_array(),
            direction: d.extend(0.0).to_array(),
        })
        .collect();
    let gpu = GpuRays::new(ctx, &rays).unwrap();
    caster.cast(bvh, &gpu, query).unwrap();
    gpu.read().unwrap()
}

fn hit(r: &CastResult) -> Option<f32> {
    (r.ids[0] != constants::NO_HIT).then_some(r.hit[0])
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= T_TOLERANCE * a.abs().max(b.abs())
}

/// Whether a packet's hit distance `got` agrees with brute force's hit on `triangle`. The
/// packets' test (the Plücker form, `bvh_fan` in bvh.glsl) and brute force's (Woop's) round differently: each
/// rounds the corners relative to the origin, by about ε R (R: the farthest corner's distance),
/// which moves the triangle's plane along a ray at angle θ to its normal by about
/// ε R / |cos θ|, more than 1e-4 of t where the ray grazes the triangle. So `got` is checked
/// against the exact distance to that plane, within 1e-4 of t plus ε R / |cos θ|.
fn packet_hit_close(scene: &Scene, got: f32, triangle: TriangleOrigin, o: Vec3, d: Vec3) -> bool {
    let mesh = &scene.groups[triangle.group as usize].meshes[triangle.mesh as usize];
    let first = 3 * triangle.triangle as usize;
    let corners: [u32; 3] = [0, 1, 2].map(|k| mesh.indices[first + k]);
    let v = corners.map(|k| Vec3::from(mesh.positions[k as usize]).as_dvec3() - o.as_dvec3());
    let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    let d = d.as_dvec3();
    let exact = v[0].dot(normal) / d.dot(normal);
    let reach = v.iter().map(|c| c.length()).fold(0.0, f64::max);
    let bound =
        f64::from(T_TOLERANCE) * exact + f64::from(f32::EPSILON) * reach / d.normalize().dot(normal).abs();
    (f64::from(got) - exact).abs() <= bound
}

/// Checks closest hit and any hit on the GPU, and the CPU traversal, against brute force for
/// every ray not too close to an edge; returns how many rays were compared and how many hit.
fn check_world_rays(
    ctx: &Validated,
    caster: &mut RayCaster,
    scene: &Scene,
    cpu: &SceneBvh,
    gpu: &GpuBvh,
    rays: &[(Vec3, Vec3)],
) -> (usize, usize) {
    let infinite: Vec<(Vec3, Vec3, f32)> = rays.iter().map(|&(o, d)| (o, d, INFINITE)).collect();
    let closest = cast(ctx, caster, gpu, &infinite, Query::ClosestHit);
    let occluded = cast(ctx, caster, gpu, &infinite, Query::Occluded);
    let expected: Vec<Option<f32>> =
        rays.iter().map(|&(o, d)| closest_hit_brute_force(scene, o, d, INFINITE).map(|h| h.0)).collect();
    // Just short of the closest hit nothing may occlude; just beyond it something must.
    let short: Vec<(Vec3, Vec3, f32)> =
        rays.iter().zip(&expected).map(|(&(o, d), e)| (o, d, e.map_or(INFINITE, |t| t * 0.999))).collect();
    let long: Vec<(Vec3, Vec3, f32)> =
        rays.iter().zip(&expected).map(|(&(o, d), e)| (o, d, e.map_or(INFINITE, |t| t * 1.001))).collect();
    let occluded_short = cast(ctx, caster, gpu, &short, Query::Occluded);
    let occluded_long = cast(ctx, caster, gpu, &long, Query::Occluded);
    let (mut compared, mut hits) = (0, 0);
    for (i, &(o, d)) in rays.iter().enumerate() {
        if edge_distance(scene, o, d, INFINITE) < EDGE_MARGIN {
            continue;
        }
        compared += 1;
        let want = expected[i];
        hits += want.is_some() as usize;
        let got = hit(&closest[i]);
        assert!(
            match (got, want) {
                (Some(a), Some(b)) => close(a, b),
                (None, None) => true,
                _ => false,
            },
            "ray {i} from {o} along {d}: GPU closest hit {got:?}, brute force {want:?}"
        );
        let cpu_hit = cpu.closest_hit(o, d, INFINITE).map(|h| h.t);
        assert!(
            match (cpu_hit, want) {
                (Some(a), Some(b)) => close(a, b),
                (None, None) => true,
                _ => false,
            },
            "ray {i}: CPU BVH closest hit {cpu_hit:?}, brute force {want:?}"
        );
        assert_eq!(
            hit(&occluded[i]).is_some(),
            want.is_some(),
            "ray {i}: any hit disagrees with closest hit"
        );
        if want.is_some() {
            assert!(hit(&occluded_short[i]).is_none(), "ray {i}: occluded before its closest hit");
            assert!(hit(&occluded_long[i]).is_some(), "ray {i}: not occluded just past its closest hit");
        }
    }
    (compared, hits)
}

/// bvh_surface at each hit against the scene's own triangle, found by brute force: the same
/// triangle, position on the ray, unit normals facing the ray, albedo. Tolerance 1e-4: float
/// rounding of unit vectors and of positions a few units from the origin.
fn check_surfaces(
    ctx: &Validated,
    caster: &mut RayCaster,
    scene: &Scene,
    cpu: &SceneBvh,
    gpu: &GpuBvh,
    rays: &[(Vec3, Vec3)],
) {
    let infinite: Vec<(Vec3, Vec3, f32)> = rays.iter().map(|&(o, d)| (o, d, INFINITE)).collect();
    let surfaces = cast(ctx, caster, gpu, &infinite, Query::Surface);
    let v3 = |v: [f32; 4]| Vec3::from_slice(&v[..3]);
    for (i, (&(o, d), s)) in rays.iter().zip(&surfaces).enumerate() {
        let Some((t, want)) = closest_hit_brute_force(scene, o, d, INFINITE) else {
            continue;
        };
        if edge_distance(scene, o, d, INFINITE) < EDGE_MARGIN {
            continue;
        }
        let origin = cpu.triangle_origin(s.ids[1]).unwrap();
        assert_eq!(origin, want, "ray {i}: GPU hit another triangle than brute force");
        let group = &scene.groups[origin.group as usize];
        let mesh = &group.meshes[origin.mesh as usize];
        let corners = &mesh.indices[3 * origin.triangle as usize..][..3];
        let to_world = group.transform.matrix();
        let p: Vec<Vec3> =
            corners.iter().map(|&c| to_world.transform_point3(mesh.positions[c as usize].into())).collect();
        let w = [1.0 - s.hit[1] - s.hit[2], s.hit[1], s.hit[2]];
        let facing = if (p[1] - p[0]).cross(p[2] - p[0]).dot(d) > 0.0 { -1.0 } else { 1.0 };
        let geometric = facing * (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        let shading = facing
            * to_world
                .transform_vector3((0..3).map(|k| w[k] * Vec3::from(mesh.normals[corners[k] as usize])).sum())
                .normalize();
        assert!(
            (v3(s.position) - (o + t * d)).length() < 1e-4 * (1.0 + o.length()),
            "ray {i}: position {:?}",
            s.position
        );
        assert!(
            v3(s.geometric_normal).dot(geometric) > 1.0 - 1e-4,
            "ray {i}: geometric normal {:?}, expected {geometric}",
            s.geometric_normal
        );
        assert!(
            v3(s.shading_normal).dot(shading) > 1.0 - 1e-4,
            "ray {i}: shading normal {:?}, expected {shading}",
            s.shading_normal
        );
        assert!((v3(s.albedo) - Vec3::from(mesh.albedo)).length() < 1e-6, "ray {i}: albedo");
    }
}

#[test]
fn random_groups_match_brute_force() {
    let ctx = Validated::new();
    let mut rng = Rng(1);
    let scene = random_scene(&mut rng, 4, 150);
    let bvh = SceneBvh::build(&scene).unwrap();
    let gpu = GpuBvh::new(&ctx, &bvh).unwrap();
    let mut caster = RayCaster::new(&ctx).unwrap();
    let rays = random_rays(&mut rng, &scene, 1500);
    let (compared, hits) = check_world_rays(&ctx, &mut caster, &scene, &bvh, &gpu, &rays);
    // The edge margin may skip a handful; the test is void if it skips many or nothing hits.
    assert!(compared > 1450 && hits > 500 && hits < compared, "{compared} rays compared, {hits} hit");
}

#[test]
fn mesh_scene_matches_brute_force_in_world_and_object_space() {
    let ctx = Validated::new();
    let mut rng = Rng(2);
    let scene = Scene::builtin("teapot").unwrap();
    let bvh = SceneBvh::build(&scene).unwrap();
    let gpu = GpuBvh::new(&ctx, &bvh).unwrap();
    let mut caster = RayCaster::new(&ctx).unwrap();
    // From around the scene towards it, as camera and light rays go.
    let rays: Vec<(Vec3, Vec3)> = (0..600)
        .map(|_| {
            let origin = rng.direction() * 4.0 + Vec3::Y;
            (origin, (rng.vec(1.0) - origin).normalize())
        })
        .collect();
    let (compared, hits) = check_world_rays(&ctx, &mut caster, &scene, &bvh, &gpu, &rays);
    assert!(compared > 550 && hits > 300, "{compared} rays compared, {hits} hit");
    check_surfaces(&ctx, &mut caster, &scene, &bvh, &gpu, &rays);

    // Self-visibility of the teapot in its object space, from its own surface (PRT's rays).
    let teapot = &scene.groups[0];
    let alone =
        Scene { groups: vec![Group { transform: Transform::default(), ..teapot.clone() }], ..scene.clone() };
    let mesh = &teapot.meshes[0];
    let rays: Vec<(Vec3, Vec3, f32)> = (0..600)
        .map(|_| {
            let t = (rng.next() * mesh.triangle_count() as f32) as usize % mesh.triangle_count();
            let v: Vec<Vec3> = mesh.indices[3 * t..3 * t + 3]
                .iter()
                .map(|&i| Vec3::from(mesh.positions[i as usize]))
                .collect();
            let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            let (a, b) = (rng.range(0.05, 0.45), rng.range(0.05, 0.45));
            let p = v[0] + a * (v[1] - v[0]) + b * (v[2] - v[0]);
            let dir = rng.direction();
            let side = if dir.dot(n) > 0.0 { n } else { -n };
            (offset_ray_origin(p, side), dir, INFINITE)
        })
        .collect();
    let occluded = cast(&ctx, &mut caster, &gpu, &rays, Query::OccludedObjectSpace { instance: 0 });
    let (mut compared, mut blocked) = (0, 0);
    for (i, &(o, d, tmax)) in rays.iter().enumerate() {
        if edge_distance(&alone, o, d, tmax) < EDGE_MARGIN {
            continue;
        }
        compared += 1;
        let want = occluded_object_space_brute_force(&scene, 0, o, d, tmax);
        blocked += want as usize;
        assert_eq!(hit(&occluded[i]).is_some(), want, "object-space ray {i} from {o} along {d}");
        assert_eq!(bvh.occluded_object_space(0, o, d, tmax), want, "CPU BVH, object-space ray {i}");
    }
    assert!(
        compared > 450 && blocked > 50 && blocked < compared,
        "{compared} rays compared, {blocked} occluded"
    );

    // The same rays by packets as the PRT casts them: 8 directions from each origin, closest
    // hits in object space, against brute force over the group alone. The last packet is
    // short: the shader casts its missing rays with a negative tmax, which must leave the
    // others' hits alone.
    let mut packets: Vec<(Vec3, Vec3, f32)> = rays
        .iter()
        .step_by(constants::BVH_PACKET as usize)
        .flat_map(|&(o, _, tmax)| {
            let dirs: Vec<Vec3> = (0..constants::BVH_PACKET).map(|_| rng.direction()).collect();
            dirs.into_iter().map(move |d| (o, d, tmax))
        })
        .collect();
    packets.truncate(packets.len() - 3);
    let hits = cast(&ctx, &mut caster, &gpu, &packets, Query::PacketObjectSpace { instance: 0 });
    let (mut compared, mut found) = (0, 0);
    for (i, &(o, d, tmax)) in packets.iter().enumerate() {
        if edge_distance(&alone, o, d, tmax) < EDGE_MARGIN {
            continue;
        }
        compared += 1;
        let want = closest_hit_brute_force(&alone, o, d, tmax);
        found += want.is_some() as usize;
        let got = hit(&hits[i]);
        assert!(
            got.is_some() == want.is_some()
                && got.zip(want).is_none_or(|(g, (_, triangle))| packet_hit_close(&alone, g, triangle, o, d)),
            "packet ray {i} from {o} along {d}: GPU {got:?}, brute force {want:?}"
        );
    }
    assert!(compared > 450 && found > 50 && found < compared, "{compared} packet rays compared, {found} hit");
}

/// Packets leak through no shared edge: rays from one origin aimed at every inner vertex of a
/// bumpy, jittered grid and at points along its inner edges (each within rounding of two or more
/// triangles' shared boundary, where a test that rounds a shared edge differently in its two
/// triangles lets a ray pass between them) all hit, through the packets' test (`bvh_fan`).
#[test]
fn packets_leak_through_no_shared_edge() {
    let ctx = Validated::new();
    let mut rng = Rng(5);
    const N: usize = 9;
    let positions: Vec<[f32; 3]> = (0..N * N)
        .map(|i| {
            let (x, z) =
                ((i % N) as f32 / (N - 1) as f32 * 2.0 - 1.0, (i / N) as f32 / (N - 1) as f32 * 2.0 - 1.0);
            let jitter =
                if i % N == 0 || i % N == N - 1 || i / N == 0 || i / N == N - 1 { 0.0 } else { 0.08 };
            [
                x + jitter * (rng.next() - 0.5),
                0.2 * (3.0 * x).sin() * (2.0 * z).cos(),
                z + jitter * (rng.next() - 0.5),
            ]
        })
        .collect();
    let indices: Vec<u32> = (0..(N - 1) * (N - 1))
        .flat_map(|c| {
            let v = (c / (N - 1) * N + c % (N - 1)) as u32;
            [v, v + N as u32, v + 1, v + 1, v + N as u32, v + N as u32 + 1]
        })
        .collect();
    let inner = |v: u32| {
        let (i, j) = (v as usize % N, v as usize / N);
        i > 0 && i < N - 1 && j > 0 && j < N - 1
    };
    let mut targets: Vec<Vec3> =
        (0..(N * N) as u32).filter(|&v| inner(v)).map(|v| Vec3::from(positions[v as usize])).collect();
    for tri in indices.chunks_exact(3) {
        for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
            if inner(a) || inner(b) {
                let (p, q) = (Vec3::from(positions[a as usize]), Vec3::from(positions[b as usize]));
                targets.extend([0.25, 0.5, 0.75].map(|s| p.lerp(q, s)));
            }
        }
    }
    let mesh = Mesh::new("grid", positions, None, indices, [0.5; 3]).unwrap();
    let scene = scene(vec![Group::new("grid", vec![mesh], Transform::default())]);
    let gpu = GpuBvh::new(&ctx, &SceneBvh::build(&scene).unwrap()).unwrap();
    let mut caster = RayCaster::new(&ctx).unwrap();
    let origin = Vec3::new(0.07, 2.0, -0.03);
    targets.truncate(targets.len() / constants::BVH_PACKET as usize * constants::BVH_PACKET as usize);
    let rays: Vec<(Vec3, Vec3, f32)> =
        targets.iter().map(|&p| (origin, (p - origin).normalize(), INFINITE)).collect();
    let results = cast(&ctx, &mut caster, &gpu, &rays, Query::PacketObjectSpace { instance: 0 });
    let leaks: Vec<Vec3> =
        targets.iter().zip(&results).filter(|(_, r)| hit(r).is_none()).map(|(&p, _)| p).collect();
    assert!(targets.len() > 500, "{} rays", targets.len());
    assert!(
        leaks.is_empty(),
        "{} of {} packet rays passed between triangles, towards {:?}",
        leaks.len(),
        targets.len(),
        leaks
    );
}

#[test]
fn moving_a_group_rewrites_only_the_top_level() {
    let ctx = Validated::new();
    let mut rng = Rng(3);
    let mut scene = random_scene(&mut rng, 3, 100);
    let mut bvh = SceneBvh::build(&scene).unwrap();
    let mut gpu = GpuBvh::new(&ctx, &bvh).unwrap();
    let mut caster = RayCaster::new(&ctx).unwrap();
    let blas_before = gpu.blas_node_buffer().read().unwrap();

    let moved = random_transform(&mut rng);
    scene.groups[1].transform = moved;
    bvh.set_transform(1, moved.matrix()).unwrap();
    gpu.update(&bvh).unwrap();

    assert_eq!(gpu.blas_node_buffer().read().unwrap(), blas_before, "update rewrote bottom-level nodes");
    let rays = random_rays(&mut rng, &scene, 800);
    let (compared, hits) = check_world_rays(&ctx, &mut caster, &scene, &bvh, &gpu, &rays);
    assert!(compared > 750 && hits > 250, "{compared} rays compared, {hits} hit");
}

#[test]
fn scenes_without_triangles_miss_everything() {
    let ctx = Validated::new();
    let mut caster = RayCaster::new(&ctx).unwrap();
    let mut rng = Rng(4);
    let rays: Vec<(Vec3, Vec3, f32)> = (0..64).map(|_| (rng.vec(2.0), rng.direction(), INFINITE)).collect();
    let empty_group = Group::new("empty", vec![], Transform::default());
    for groups in [vec![], vec![empty_group]] {
        let instances = groups.len() as u32;
        let mut bvh = SceneBvh::build(&scene(groups)).unwrap();
        let mut gpu = GpuBvh::new(&ctx, &bvh).unwrap();
        for query in [Query::ClosestHit, Query::Occluded] {
            assert!(cast(&ctx, &mut caster, &gpu, &rays, query).iter().all(|r| hit(r).is_none()));
        }
        if instances > 0 {
            bvh.set_transform(0, Mat4::from_translation(Vec3::X)).unwrap();
            gpu.update(&bvh).unwrap();
            let results = cast(&ctx, &mut caster, &gpu, &rays, Query::OccludedObjectSpace { instance: 0 });
            assert!(results.iter().all(|r| hit(r).is_none()));
        }
    }
}
