//! Validity of tetrahedralizations and lookups on random, grid (cospherical) and degenerate sets,
//! checked with the exact predicates against every point (small sets) or a sample (large ones).
use super::predicates::{in_sphere, orient};
use super::rng::XorShift;
use super::*;
use glam::DVec3;

fn random_points(count: usize, seed: u32, lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let mut rng = XorShift::new(seed);
    let mut unit = move || rng.next_u32() as f64 / 4_294_967_296.0;
    (0..count).map(|_| lo + (hi - lo) * DVec3::new(unit(), unit(), unit())).collect()
}

fn grid(n: [u32; 3], spacing: f64) -> Vec<DVec3> {
    let mut points = Vec::new();
    for x in 0..n[0] {
        for y in 0..n[1] {
            for z in 0..n[2] {
                points.push(DVec3::new(x as f64, y as f64, z as f64) * spacing);
            }
        }
    }
    points
}

fn volume(v: [DVec3; 4]) -> f64 {
    (v[1] - v[0]).dot((v[2] - v[0]).cross(v[3] - v[0])) / 6.0
}

fn corners(mesh: &TetMesh, tet: [u32; 4]) -> [DVec3; 4] {
    tet.map(|i| mesh.positions()[i as usize])
}

/// Checks everything a valid Delaunay tetrahedralization of the mesh's positions satisfies and
/// returns its volume. The empty-sphere test runs against every point for `sphere_tets` tets
/// spread over the mesh.
fn check_valid(mesh: &TetMesh, sphere_tets: usize) -> f64 {
    let p = mesh.positions();
    let merged: Vec<u32> = mesh.merged().iter().map(|m| m.index).collect();
    let distinct: Vec<usize> = (0..p.len()).filter(|i| !merged.contains(&(*i as u32))).collect();
    let mut used = vec![false; p.len()];
    let mut total = 0.0;
    for (t, &tet) in mesh.tets().iter().enumerate() {
        let v = corners(mesh, tet);
        assert!(orient(v[0], v[1], v[2], v[3]) > 0.0, "tet {t} {tet:?} is not positively oriented");
        total += volume(v);
        tet.iter().for_each(|&i| used[i as usize] = true);
        for (slot, across) in mesh.neighbours()[t].iter().enumerate() {
            let mut face = super::delaunay::opposite(tet, slot);
            face.sort_unstable();
            match *across {
                Across::Tet(n) => {
                    let back = mesh.neighbours()[n as usize].iter().position(|&a| a == Across::Tet(t as u32));
                    let back = back.unwrap_or_else(|| panic!("tet {n} does not point back to {t}"));
                    let mut other = super::delaunay::opposite(mesh.tets()[n as usize], back);
                    other.sort_unstable();
                    assert_eq!(face, other, "tets {t} and {n} do not share the face between them");
                }
                // A hull face has every point on its inner side (or in its plane).
                Across::Hull(_) => {
                    for &i in &distinct {
                        let mut q = v;
                        q[slot] = p[i];
                        assert!(
                            orient(q[0], q[1], q[2], q[3]) >= 0.0,
                            "point {i} is beyond hull face {face:?}"
                        );
                    }
                }
            }
        }
    }
    for &i in &distinct {
        assert!(used[i], "point {i} is in no tetrahedron");
    }
    let stride = (mesh.tets().len() / sphere_tets.max(1)).max(1);
    for &tet in mesh.tets().iter().step_by(stride) {
        let v = corners(mesh, tet);
        for &i in &distinct {
            assert!(
                in_sphere(v[0], v[1], v[2], v[3], p[i]) <= 0.0,
                "point {i} is inside the circumsphere of {tet:?}"
            );
        }
    }
    let hull = hull_volume(mesh);
    assert!((total - hull).abs() <= 1e-9 * hull, "tets add up to {total}, the hull faces enclose {hull}");
    total
}

/// The volume enclosed by the hull faces (the faces without a neighbour), by the divergence
/// theorem from the centroid of the points.
fn hull_volume(mesh: &TetMesh) -> f64 {
    let p = mesh.positions();
    let centre = p.iter().sum::<DVec3>() / p.len() as f64;
    let mut enclosed = 0.0;
    for (t, &tet) in mesh.tets().iter().enumerate() {
        for (slot, across) in mesh.neighbours()[t].iter().enumerate() {
            if let Across::Hull(_) = across {
                let mut v = corners(mesh, tet);
                v[slot] = centre;
                enclosed += volume(v);
            }
        }
    }
    enclosed
}

/// The convex hull's volume found independently, for points in general position: a triple is a
/// hull face when every other point lies strictly on one side of it.
fn brute_force_hull_volume(p: &[DVec3]) -> f64 {
    let centre = p.iter().sum::<DVec3>() / p.len() as f64;
    let mut enclosed = 0.0;
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            for k in j + 1..p.len() {
                let side = |m: usize| orient(p[i], p[j], p[k], p[m]).signum();
                let mut others = (0..p.len()).filter(|&m| m != i && m != j && m != k);
                let first = others.next().map_or(0.0, side);
                if others.all(|m| side(m) == first) {
                    enclosed += volume([centre, p[i], p[j], p[k]]).abs();
                }
            }
        }
    }
    enclosed
}

/// Lookups of points inside: weights in [0, 1] summing to 1 that reproduce the point, in a
/// tetrahedron that holds it by exact predicates.
fn check_lookups_inside(mesh: &TetMesh, points: &[DVec3]) {
    let mut walker = Walker::default();
    let scale = mesh.positions().iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    for &p in points {
        let at = walker.locate(mesh, p).unwrap();
        assert!(!at.extrapolated, "{p} is inside the hull");
        let v = corners(mesh, at.probes);
        for slot in 0..4 {
            let mut q = v;
            q[slot] = p;
            assert!(orient(q[0], q[1], q[2], q[3]) >= 0.0, "{p} is not in tet {}", at.tet);
        }
        assert!(at.weights.iter().all(|w| (0.0..=1.0).contains(w)), "{:?}", at.weights);
        assert!((at.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{:?}", at.weights);
        // The weights are as accurate as the tetrahedron is well shaped: rounding errors of
        // the coordinates' size are amplified by (longest edge)³ / volume.
        let longest = (0..4)
            .flat_map(|i| (0..i).map(move |j| (i, j)))
            .fold(0.0f64, |m, (i, j)| m.max(v[i].distance(v[j])));
        let aspect = longest.powi(3) / volume(v);
        let back: DVec3 = (0..4).map(|k| at.weights[k] * v[k]).sum();
        assert!(back.distance(p) <= 1e-14 * scale * aspect, "{p} comes back as {back}");
    }
}

/// Points inside the hull: convex combinations of random tetrahedra's corners.
fn inside_points(mesh: &TetMesh, count: usize, seed: u32) -> Vec<DVec3> {
    let mut rng = XorShift::new(seed);
    (0..count)
        .map(|_| {
            let v = corners(mesh, mesh.tets()[rng.below(mesh.tets().len() as u32) as usize]);
            let w = [0; 4].map(|_| rng.below(1000) as f64 + 1.0);
            (0..4).map(|k| w[k] * v[k]).sum::<DVec3>() / w.iter().sum::<f64>()
        })
        .collect()
}

#[test]
fn predicates_follow_the_right_hand_convention() {
    let [o, x, y, z] = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    assert!(orient(o, x, y, z) > 0.0 && orient(x, o, y, z) < 0.0);
    assert!(in_sphere(o, x, y, z, DVec3::splat(0.25)) > 0.0);
    assert!(in_sphere(o, x, y, z, DVec3::splat(2.0)) < 0.0);
    assert_eq!(in_sphere(o, x, y, z, DVec3::ONE), 0.0);
}

#[test]
fn random_sets_are_valid() {
    let points = random_points(40, 7, DVec3::ZERO, DVec3::ONE);
    let mesh = TetMesh::build(&points).unwrap();
    let total = check_valid(&mesh, usize::MAX);
    let hull = brute_force_hull_volume(&points);
    assert!((total - hull).abs() < 1e-12, "tets {total}, independent hull {hull}");

    let points = random_points(3000, 11, DVec3::new(-3.0, 0.0, 2.0), DVec3::new(5.0, 1.0, 4.0));
    let mesh = TetMesh::build(&points).unwrap();
    check_valid(&mesh, 300);
    check_lookups_inside(&mesh, &inside_points(&mesh, 2000, 3));
}

#[test]
fn grids_are_cospherical_and_still_valid() {
    for (n, spacing) in [([5, 5, 5], 1.0), ([4, 3, 6], 0.1), ([2, 2, 2], 1.0), ([9, 2, 3], 1e3)] {
        let points = grid(n, spacing);
        let mesh = TetMesh::build(&points).unwrap();
        let total = check_valid(&mesh, usize::MAX);
        let box_volume = n.iter().map(|&k| (k - 1) as f64 * spacing).product::<f64>();
        assert!((total - box_volume).abs() <= 1e-12 * box_volume, "{n:?}: {total} vs {box_volume}");
        check_lookups_inside(&mesh, &inside_points(&mesh, 500, 5));
        // Lattice points, edge midpoints and face centres lie on faces and edges of tetrahedra.
        check_lookups_inside(&mesh, &grid(n.map(|k| 2 * k - 1), spacing / 2.0));
    }
}

#[test]
fn points_on_one_sphere_with_its_centre() {
    let mut points = vec![DVec3::ZERO];
    for (a, b) in [(5.0, 0.0), (3.0, 4.0), (4.0, 3.0), (0.0, 5.0), (-3.0, 4.0), (-4.0, -3.0)] {
        for sign in [1.0, -1.0] {
            points.extend(
                [DVec3::new(a, b, 0.0), DVec3::new(0.0, a, b), DVec3::new(b, 0.0, a)].map(|p| sign * p),
            );
        }
    }
    let mesh = TetMesh::build(&points).unwrap();
    check_valid(&mesh, usize::MAX);
    check_lookups_inside(&mesh, &inside_points(&mesh, 300, 9));
}

#[test]
fn duplicates_are_merged_and_reported() {
    let mut points = grid([3, 3, 3], 1.0);
    points.extend([points[4], points[0], points[4]]);
    let mesh = TetMesh::build(&points).unwrap();
    let merged: Vec<(u32, u32)> = mesh.merged().iter().map(|m| (m.index, m.kept)).collect();
    assert_eq!(merged, [(27, 4), (28, 0), (29, 4)]);
    assert!(mesh.tets().iter().flatten().all(|&i| i < 27));
    check_valid(&mesh, usize::MAX);
}

#[test]
fn nearly_coplanar_points() {
    // A slab 1e-9 thick: every tetrahedron is a sliver.
    let points = random_points(300, 21, DVec3::ZERO, DVec3::new(1.0, 1.0, 1e-9));
    let mesh = TetMesh::build(&points).unwrap();
    check_valid(&mesh, usize::MAX);
    check_lookups_inside(&mesh, &inside_points(&mesh, 500, 4));
    // A plane grid with one point lifted by one unit in the last place.
    let mut points = grid([6, 6, 1], 1.0);
    points[14].z = f64::EPSILON;
    points.push(DVec3::new(2.5, 2.5, -1.0));
    let mesh = TetMesh::build(&points).unwrap();
    check_valid(&mesh, usize::MAX);
}

#[test]
fn coordinates_from_a_thousandth_to_ten_thousand() {
    let mut points = random_points(60, 31, DVec3::ZERO, DVec3::splat(1e-3));
    points.extend(grid([2, 2, 2], 1e4));
    points.extend(random_points(60, 32, DVec3::splat(-1e4), DVec3::splat(1e4)));
    points.extend(grid([3, 3, 3], 1e-3));
    let mesh = TetMesh::build(&points).unwrap();
    check_valid(&mesh, usize::MAX);
    let mut tiny = inside_points(&mesh, 300, 8);
    tiny.extend(random_points(300, 33, DVec3::ZERO, DVec3::splat(2e-3)));
    check_lookups_inside(&mesh, &tiny);
}

#[test]
fn degenerate_sets_are_clear_errors() {
    let cases: [(Vec<DVec3>, &str); 5] = [
        (vec![DVec3::ZERO, DVec3::X, DVec3::Y], "3 distinct"),
        (
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Y, DVec3::X],
            "3 distinct probe position(s) among the 5",
        ),
        (grid([4, 4, 1], 1.0), "in one plane"),
        ((0..6).map(|i| DVec3::splat(i as f64)).collect(), "on one line"),
        (vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.0, 0.0, f64::INFINITY)], "probe 3"),
    ];
    for (points, expected) in cases {
        let e = TetMesh::build(&points).err().expect("an error");
        assert!(e.to_string().contains(expected), "{e}");
    }
    let mesh = TetMesh::build(&grid([2, 2, 2], 1.0)).unwrap();
    let e = Walker::default().locate(&mesh, DVec3::new(f64::NAN, 0.0, 0.0)).err().unwrap();
    assert!(e.to_string().contains("finite"), "{e}");
}

#[test]
fn the_walk_from_any_start_finds_the_same_tetrahedron() {
    let points = random_points(60, 41, DVec3::ZERO, DVec3::ONE);
    let mesh = TetMesh::build(&points).unwrap();
    let targets = inside_points(&mesh, 20, 42);
    for start in 0..mesh.tets().len() as u32 + 1 {
        for &p in &targets {
            let at = Walker::starting_at(start).locate(&mesh, p).unwrap();
            let reference = Walker::default().locate(&mesh, p).unwrap();
            assert_eq!(at.tet, reference.tet, "from {start} to {p}");
        }
    }
}

#[test]
fn a_coherent_walk_takes_about_one_step() {
    let points = random_points(10_000, 51, DVec3::ZERO, DVec3::ONE);
    let mesh = TetMesh::build(&points).unwrap();
    let mut walker = Walker::default();
    let steps: u32 = (0..5000)
        .map(|i| {
            let t = i as f64 * 1e-3;
            let p = DVec3::new(0.5 + 0.3 * t.cos(), 0.5 + 0.3 * t.sin(), 0.5 + 0.2 * (3.0 * t).sin());
            walker.locate(&mesh, p).unwrap().steps
        })
        .sum();
    let mean = steps as f64 / 5000.0;
    assert!(mean < 1.0, "{mean} steps per lookup");
}

/// The weights as a vector over all probes.
fn dense(mesh: &TetMesh, at: &Location) -> Vec<f64> {
    let mut w = vec![0.0; mesh.positions().len()];
    for k in 0..4 {
        w[at.probes[k] as usize] += at.weights[k];
    }
    w
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn extrapolation_is_continuous_at_the_hull_and_finite_far_away() {
    let points = random_points(200, 61, DVec3::ZERO, DVec3::ONE);
    let mesh = TetMesh::build(&points).unwrap();
    let lowest = mesh.tets().iter().fold(f64::INFINITY, |m, &tet| {
        let v = corners(&mesh, tet);
        let largest_face = (0..4).map(|k| {
            let [a, b, c] = super::delaunay::opposite(v, k);
            0.5 * (b - a).cross(c - a).length()
        });
        m.min(3.0 * volume(v) / largest_face.fold(0.0, f64::max))
    });
    let mut walker = Walker::default();
    // Just inside and just outside the centre, an edge point and a corner of each hull face.
    for (t, &tet) in mesh.tets().iter().enumerate() {
        for (slot, across) in mesh.neighbours()[t].iter().enumerate() {
            let Across::Hull(_) = across else { continue };
            let f = super::delaunay::opposite(tet, slot).map(|i| points[i as usize]);
            let normal = (f[1] - f[0]).cross(f[2] - f[0]).normalize();
            let outward = if normal.dot(f[0] - points[tet[slot] as usize]) > 0.0 { normal } else { -normal };
            for on in [(f[0] + f[1] + f[2]) / 3.0, (f[0] + f[1]) / 2.0, f[2]] {
                let inside = walker.locate(&mesh, on - 1e-9 * outward).unwrap();
                let outside = walker.locate(&mesh, on + 1e-9 * outward).unwrap();
                assert!(outside.extrapolated);
                // A weight's gradient is at most 1 / height in any tetrahedron (and less outside),
                // so a move by 2e-9 changes it by at most 2e-9 / (the smallest height).
                let jump = max_difference(&dense(&mesh, &inside), &dense(&mesh, &outside));
                assert!(jump <= 2e-9 / lowest + 1e-9, "weights jump by {jump} across hull face {f:?}");
            }
        }
    }
    for d in [DVec3::X, DVec3::NEG_Y, DVec3::new(1.0, -2.0, 3.0)] {
        let at = walker.locate(&mesh, 1e29 * d.normalize()).unwrap();
        assert!(at.extrapolated && at.weights.iter().all(|w| w.is_finite() && *w >= 0.0), "{at:?}");
        assert!((at.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}

/// A moving object: from tetrahedron to tetrahedron inside (no pop), out of the hull and back.
#[test]
fn leaving_the_hull_and_coming_back_is_continuous() {
    let mesh = TetMesh::build(&grid([4, 4, 4], 1.0)).unwrap();
    let mut walker = Walker::default();
    let path = |s: f64| DVec3::new(1.5, 1.2, 1.4) + s * DVec3::new(1.0, 0.6, -0.3);
    let mut last: Option<Vec<f64>> = None;
    let mut outside = 0;
    let step = 1e-3;
    for i in (0..=4000).chain((0..4000).rev()) {
        let at = walker.locate(&mesh, path(i as f64 * step)).unwrap();
        outside += usize::from(at.extrapolated);
        let w = dense(&mesh, &at);
        if let Some(last) = &last {
            // Barycentric weights in this grid change by at most about 2 per unit of motion.
            let jump = max_difference(last, &w);
            assert!(jump <= 3.0 * step * 1.2, "step {i}: weights jump by {jump}");
        }
        last = Some(w);
    }
    assert!(outside > 2000, "the path leaves the hull");
}

#[test]
fn highly_degenerate_sets() {
    // Every integer point on the sphere of radius 15, and its centre: 5 or more cospherical
    // points everywhere, many of them coplanar and cocircular on the hull.
    let mut sphere = vec![DVec3::ZERO];
    for x in -15i32..=15 {
        for y in -15i32..=15 {
            for z in -15i32..=15 {
                if x * x + y * y + z * z == 225 {
                    sphere.push(DVec3::new(x as f64, y as f64, z as f64));
                }
            }
        }
    }
    // A plane grid whose points are off the plane by at most 1e-12, and two points off it.
    let mut rng = XorShift::new(77);
    let mut sheet: Vec<DVec3> = grid([8, 8, 1], 1.0)
        .into_iter()
        .map(|p| p + DVec3::Z * (rng.below(3) as f64 - 1.0) * 1e-12)
        .collect();
    sheet.extend([DVec3::new(3.5, 3.5, 1.0), DVec3::new(2.0, 5.0, -1.0)]);
    // Stacked layers of a grid, offset by half a cell every other layer.
    let layers: Vec<DVec3> = grid([6, 6, 4], 1.0)
        .into_iter()
        .map(|p| if p.z as u32 % 2 == 1 { p + DVec3::new(0.5, 0.5, 0.0) } else { p })
        .collect();
    for (name, points) in
        [("sphere", sphere), ("sheet", sheet), ("layers", layers), ("grid", grid([10, 10, 10], 0.5))]
    {
        let mesh = TetMesh::build(&points).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_valid(&mesh, 200);
        check_lookups_inside(&mesh, &inside_points(&mesh, 300, 6));
    }
}

/// Random subsets of a small integer lattice, in random order: four or more coplanar and five or
/// more cospherical points nearly everywhere, on the hull and inside.
#[test]
fn random_subsets_of_a_lattice() {
    let lattice = grid([4, 3, 3], 1.0);
    let mut rng = XorShift::new(91);
    let mut built = 0;
    for _ in 0..400 {
        let mut points: Vec<DVec3> = lattice.iter().copied().filter(|_| rng.below(3) == 0).collect();
        for i in (1..points.len()).rev() {
            points.swap(i, rng.below(i as u32 + 1) as usize);
        }
        let Ok(mesh) = TetMesh::build(&points) else { continue };
        check_valid(&mesh, usize::MAX);
        check_lookups_inside(&mesh, &inside_points(&mesh, 20, rng.next_u32()));
        built += 1;
    }
    assert!(built > 300, "{built} sets were not flat");
}

#[test]
fn extreme_scales_stay_exact() {
    for scale in [1e-25, 1e29] {
        let mut points = random_points(50, 101, DVec3::ZERO, DVec3::splat(scale));
        points.extend(grid([3, 3, 3], scale / 2.0));
        let mesh = TetMesh::build(&points).unwrap();
        check_valid(&mesh, usize::MAX);
        check_lookups_inside(&mesh, &inside_points(&mesh, 100, 102));
    }
}

/// Random subsets of the cell centres of a 6³ lattice over the unit cube, as automatic
/// placement's candidates are: 1/12 + k/6 is not a binary fraction, so the coplanar lattice
/// points are off their planes by a rounding, and the Delaunay tetrahedra between them are
/// slivers whose volume a floating-point determinant puts at 0. Lookups in them, and at the
/// lattice points in their planes, still give finite weights that reproduce the point.
#[test]
fn slivers_between_cell_centres_give_finite_weights() {
    let lattice = Lattice::cell_centres(glam::Vec3::ZERO, glam::Vec3::ONE, [6; 3]).positions();
    let mut rng = XorShift::new(17);
    let mut slivers = 0;
    for _ in 0..150 {
        let points: Vec<DVec3> = lattice.iter().copied().filter(|_| rng.below(8) == 0).collect();
        let Ok(mesh) = TetMesh::build(&points) else { continue };
        check_valid(&mesh, usize::MAX);
        slivers += mesh
            .tets()
            .iter()
            .filter(|&&t| {
                let v = corners(&mesh, t);
                volume(v) == 0.0
            })
            .count();
        let mut walker = Walker::default();
        for p in inside_points(&mesh, 20, rng.next_u32()).into_iter().chain(lattice.iter().copied()) {
            let at = walker.locate(&mesh, p).unwrap();
            assert!(at.weights.iter().all(|w| (0.0..=1.0).contains(w)), "{p}: {:?}", at.weights);
            assert!((at.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{p}: {:?}", at.weights);
            if !at.extrapolated {
                let v = corners(&mesh, at.probes);
                let back: DVec3 = (0..4).map(|k| at.weights[k] * v[k]).sum();
                assert!(back.distance(p) < 1e-9, "{p} comes back as {back} from {:?}", at.weights);
            }
        }
    }
    assert!(slivers > 0, "no sliver was built: the test does not test them");
}
