//! CPU traversal of the scene BVH, step for step what bvh.glsl does (front-to-back, explicit
//! stack), for hosts that cast a few rays and for checking the tree against brute force.
use super::sah::{node_bounds, node_range};
use super::{SceneBvh, WatertightRay};
use crate::layouts::BvhNode;
use glam::{Mat4, Vec3};

/// A ray's closest hit, as bvh.glsl's RayHit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// The scene group.
    pub instance: u32,
    /// Index into the BVH triangle buffer ([`SceneBvh::triangle_origin`] maps it to the scene).
    pub triangle: u32,
    /// Weights of the triangle's v1 and v2.
    pub barycentric: [f32; 2],
}

impl SceneBvh {
    /// The closest hit along a world-space ray within (0, tmax), over every group.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        let mut best = None;
        let mut tmax = tmax;
        self.traverse(origin, dir, &mut tmax, false, &mut best);
        best
    }

    /// Whether anything lies along the world-space ray within (0, tmax).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        let mut tmax = tmax;
        self.traverse(origin, dir, &mut tmax, true, &mut None)
    }

    /// Whether a triangle of group `instance` lies along the ray, given in the group's object
    /// space, within (0, tmax). An unknown group has no triangles.
    pub fn occluded_object_space(&self, instance: u32, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        let mut tmax = tmax;
        instance < self.instances.len() as u32
            && self.traverse_blas(instance, origin, dir, &mut tmax, true, &mut None)
    }

    fn traverse(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmax: &mut f32,
        any_hit: bool,
        best: &mut Option<Hit>,
    ) -> bool {
        let mut found = false;
        walk(&self.tlas_nodes, 0, origin, dir, tmax, &mut |index, count, tmax| {
            debug_assert_eq!(count, 1);
            let to_object = Mat4::from_cols_array_2d(&self.instances[index as usize].world_to_object);
            let (o, d) = (to_object.transform_point3(origin), to_object.transform_vector3(dir));
            found |= self.traverse_blas(index, o, d, tmax, any_hit, best);
            found && any_hit
        });
        found
    }

    fn traverse_blas(
        &self,
        instance: u32,
        origin: Vec3,
        dir: Vec3,
        tmax: &mut f32,
        any_hit: bool,
        best: &mut Option<Hit>,
    ) -> bool {
        let ray = WatertightRay::new(origin, dir);
        let mut found = false;
        let root = self.instances[instance as usize].info[0];
        walk(&self.blas_nodes, root, origin, dir, tmax, &mut |index, count, tmax| {
            for tri in index..index + count {
                let t = &self.triangles[tri as usize];
                let v = [t.v0, t.v1, t.v2].map(|v| Vec3::from_slice(&v[..3]));
                if let Some((t, barycentric)) = ray.intersect(v, *tmax) {
                    *tmax = t;
                    *best = Some(Hit { t, instance, triangle: tri, barycentric });
                    found = true;
                    if any_hit {
                        return true;
                    }
                }
            }
            false
        });
        found
    }
}

/// Visits the leaves a ray reaches, nearer child first, until `leaf` returns true (stop). `leaf`
/// gets (index, count, running tmax) and may shrink tmax to prune what lies beyond.
fn walk(
    nodes: &[BvhNode],
    root: u32,
    origin: Vec3,
    dir: Vec3,
    tmax: &mut f32,
    leaf: &mut dyn FnMut(u32, u32, &mut f32) -> bool,
) {
    let inv_dir = dir.recip();
    let enter = |at: u32, tmax: f32| node_bounds(&nodes[at as usize]).enter(origin, inv_dir, tmax);
    if enter(root, *tmax).is_none() {
        return;
    }
    let mut stack = Vec::with_capacity(64);
    let mut current = root;
    loop {
        let (index, count) = node_range(&nodes[current as usize]);
        if count > 0 {
            if leaf(index, count, tmax) {
                return;
            }
        } else {
            match (enter(index, *tmax), enter(index + 1, *tmax)) {
                (Some(l), Some(r)) => {
                    let (near, far) = if l <= r { (index, index + 1) } else { (index + 1, index) };
                    stack.push(far);
                    current = near;
                    continue;
                }
                (Some(_), None) => {
                    current = index;
                    continue;
                }
                (None, Some(_)) => {
                    current = index + 1;
                    continue;
                }
                (None, None) => {}
            }
        }
        // A node pushed earlier may now lie beyond a hit found since.
        match std::iter::from_fn(|| stack.pop()).find(|&n| enter(n, *tmax).is_some()) {
            Some(next) => current = next,
            None => return,
        }
    }
}
