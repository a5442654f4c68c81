//! Axis-aligned boxes, as the BVH builder and the CPU traversal use them.
use glam::{Mat4, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub lo: Vec3,
    pub hi: Vec3,
}

impl Aabb {
    /// Contains nothing; the identity of [`Aabb::union`]. Every ray misses it.
    pub const EMPTY: Aabb = Aabb { lo: Vec3::splat(f32::INFINITY), hi: Vec3::splat(f32::NEG_INFINITY) };

    pub fn of_points(points: &[Vec3]) -> Aabb {
        points.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p))
    }

    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb { lo: self.lo.min(p), hi: self.hi.max(p) }
    }

    pub fn union(self, other: Aabb) -> Aabb {
        Aabb { lo: self.lo.min(other.lo), hi: self.hi.max(other.hi) }
    }

    pub fn is_empty(&self) -> bool {
        self.lo.cmpgt(self.hi).any()
    }

    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// Surface area; 0 for an empty box.
    pub fn area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.hi - self.lo;
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    pub fn contains(&self, other: &Aabb) -> bool {
        self.lo.cmple(other.lo).all() && other.hi.cmple(self.hi).all()
    }

    /// The box around this box's eight corners moved by `m`.
    pub fn transformed(&self, m: Mat4) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        let corners: Vec<Vec3> = (0..8)
            .map(|i| {
                let pick = |bit: usize, axis: usize| {
                    if i & bit == 0 {
                        self.lo[axis]
                    } else {
                        self.hi[axis]
                    }
                };
                m.transform_point3(Vec3::new(pick(1, 0), pick(2, 1), pick(4, 2)))
            })
            .collect();
        Aabb::of_points(&corners)
    }

    /// Where a ray enters the box within [0, tmax], if it does; `inv_dir` is 1 / direction
    /// (infinities for axis-parallel rays). The same arithmetic as bvh.glsl's bvh_enter_box.
    pub fn enter(&self, origin: Vec3, inv_dir: Vec3, tmax: f32) -> Option<f32> {
        let t0 = (self.lo - origin) * inv_dir;
        let t1 = (self.hi - origin) * inv_dir;
        // f32::max/min drop a NaN operand as GLSL's max/min may; NaN arises only from 0 * inf.
        let near = t0.min(t1);
        let far = t0.max(t1);
        let enter = near.x.max(near.y).max(near.z.max(0.0));
        let leave = far.x.min(far.y).min(far.z.min(tmax));
        (enter <= leave).then_some(enter)
    }
}

/// Deterministic uniform numbers in [0, 1) from `seed` (a linear congruential generator), for
/// the builders' tests.
#[cfg(test)]
pub fn test_random(seed: u32) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1 << 24) as f32
    }
}
