//! The reference the BVH is tested against: every triangle of the scene, straight from the
//! [`Scene`] (no BVH data), with the same watertight test.
use super::{TriangleOrigin, WatertightRay};
use crate::scene::Scene;
use glam::{DVec3, Vec3};

/// The closest hit along a world-space unit ray within (0, tmax): its t and triangle. Each
/// group is tested in its object space, the ray moved as the shaders move it.
pub fn closest_hit_brute_force(
    scene: &Scene,
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
) -> Option<(f32, TriangleOrigin)> {
    let mut best = None;
    let mut tmax = tmax;
    for (g, group) in scene.groups.iter().enumerate() {
        let to_object = group.transform.matrix().inverse();
        let ray = WatertightRay::new(to_object.transform_point3(origin), to_object.transform_vector3(dir));
        for_each_triangle(scene, g, |mesh, triangle, v| {
            if let Some((t, _)) = ray.intersect(v, tmax) {
                tmax = t;
                best = Some((t, TriangleOrigin { group: g as u32, mesh, triangle }));
            }
        });
    }
    best
}

/// Whether a triangle of group `group` lies along the ray (in the group's object space)
/// within (0, tmax).
pub fn occluded_object_space_brute_force(
    scene: &Scene,
    group: usize,
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
) -> bool {
    let ray = WatertightRay::new(origin, dir);
    let mut hit = false;
    for_each_triangle(scene, group, |_, _, v| hit |= ray.intersect(v, tmax).is_some());
    hit
}

/// The smallest world-space distance between the ray's segment [0, tmax] and any triangle edge
/// of the scene, in double precision. Rays closer to an edge than float rounding may legitimately
/// hit either neighbour, or (at a silhouette) hit or miss, so tests leave them out.
pub fn edge_distance(scene: &Scene, origin: Vec3, dir: Vec3, tmax: f32) -> f64 {
    let (o, d) = (origin.as_dvec3(), dir.as_dvec3().normalize());
    // Beyond the farthest vertex the ray can come no closer to an edge.
    let mut reach = 0.0f64;
    let mut edges = Vec::new();
    for (g, group) in scene.groups.iter().enumerate() {
        let to_world = group.transform.matrix().as_dmat4();
        for_each_triangle(scene, g, |_, _, v| {
            let w = v.map(|p| to_world.transform_point3(p.as_dvec3()));
            for p in w {
                reach = reach.max((p - o).length());
            }
            edges.extend([(w[0], w[1]), (w[1], w[2]), (w[2], w[0])]);
        });
    }
    let end = o + d * (tmax as f64).min(reach + 1.0);
    edges.iter().map(|&(a, b)| segment_distance(a, b, o, end)).fold(f64::INFINITY, f64::min)
}

fn for_each_triangle(scene: &Scene, group: usize, mut f: impl FnMut(u32, u32, [Vec3; 3])) {
    for (m, mesh) in scene.groups[group].meshes.iter().enumerate() {
        for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
            f(m as u32, t as u32, [0, 1, 2].map(|k| Vec3::from(mesh.positions[tri[k] as usize])));
        }
    }
}

/// Distance between segments p1q1 and p2q2 (Ericson, Real-Time Collision Detection, 5.1.9).
fn segment_distance(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (s, t) = if a == 0.0 && e == 0.0 {
        (0.0, 0.0)
    } else if a == 0.0 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e == 0.0 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_of_crossing_parallel_and_apart_segments() {
        let d =
            segment_distance(DVec3::ZERO, DVec3::X, DVec3::new(0.5, -1.0, 2.0), DVec3::new(0.5, 1.0, 2.0));
        assert!((d - 2.0).abs() < 1e-12);
        let d = segment_distance(DVec3::ZERO, DVec3::X, DVec3::new(0.0, 3.0, 0.0), DVec3::new(1.0, 3.0, 0.0));
        assert!((d - 3.0).abs() < 1e-12);
        let d = segment_distance(DVec3::ZERO, DVec3::X, DVec3::new(4.0, 0.0, 0.0), DVec3::new(5.0, 0.0, 0.0));
        assert!((d - 3.0).abs() < 1e-12);
    }
}
