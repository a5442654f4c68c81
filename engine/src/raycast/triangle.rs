//! The watertight ray–triangle test (Woop, Benthin and Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1)) and ray-origin offsetting, the same arithmetic as bvh.glsl.
use glam::{IVec3, Vec3};

/// A ray sheared onto its dominant axis: the per-ray half of the watertight test.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    origin: Vec3,
    /// kx, ky, kz: kz is the axis along which the direction is largest.
    k: [usize; 3],
    shear: Vec3,
}

impl WatertightRay {
    /// `dir` need not be unit length; t is measured in units of `dir`.
    pub fn new(origin: Vec3, dir: Vec3) -> WatertightRay {
        let kz = dir.abs().max_position();
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keeps the winding as seen along the ray, which the sign tests rely on.
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        WatertightRay {
            origin,
            k: [kx, ky, kz],
            shear: Vec3::new(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]),
        }
    }

    /// A hit with t in (0, tmax): t and the barycentric weights of v1 and v2. Edge functions are
    /// evaluated without fused multiply-adds, so an edge shared by two triangles gets exactly
    /// negated values in both and no ray passes between them; a value of exactly zero counts as
    /// inside, so a ray exactly through a shared edge hits both.
    pub fn intersect(&self, v: [Vec3; 3], tmax: f32) -> Option<(f32, [f32; 2])> {
        let [kx, ky, kz] = self.k;
        let s = self.shear;
        let a = v[0] - self.origin;
        let b = v[1] - self.origin;
        let c = v[2] - self.origin;
        let ax = a[kx] - s.x * a[kz];
        let ay = a[ky] - s.y * a[kz];
        let bx = b[kx] - s.x * b[kz];
        let by = b[ky] - s.y * b[kz];
        let cx = c[kx] - s.x * c[kz];
        let cy = c[ky] - s.y * c[kz];
        let u = cx * by - cy * bx;
        let w1 = ax * cy - ay * cx;
        let w2 = bx * ay - by * ax;
        if (u < 0.0 || w1 < 0.0 || w2 < 0.0) && (u > 0.0 || w1 > 0.0 || w2 > 0.0) {
            return None;
        }
        let det = u + w1 + w2;
        if det == 0.0 {
            return None;
        }
        let tt = u * (s.z * a[kz]) + w1 * (s.z * b[kz]) + w2 * (s.z * c[kz]);
        let outside = if det > 0.0 { tt <= 0.0 || tt >= tmax * det } else { tt >= 0.0 || tt <= tmax * det };
        if outside {
            return None;
        }
        let inv = 1.0 / det;
        let t = tt * inv;
        (t > 0.0 && t < tmax).then_some((t, [w1 * inv, w2 * inv]))
    }
}

/// Moves `p` off its surface along `n` (towards the side the new ray leaves on) by a few ulps
/// of its coordinates, or by a fixed tiny distance near the origin where ulps vanish (Wächter
/// and Binder 2019, Ray Tracing Gems ch. 6). The same as bvh.glsl's offset_ray_origin.
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let of_i: IVec3 = (INT_SCALE * n).as_ivec3();
    let moved = |axis: usize| {
        let step = if p[axis] < 0.0 { -of_i[axis] } else { of_i[axis] };
        f32::from_bits((p[axis].to_bits() as i32).wrapping_add(step) as u32)
    };
    Vec3::from_array(std::array::from_fn(|axis| {
        if p[axis].abs() < ORIGIN {
            p[axis] + FLOAT_SCALE * n[axis]
        } else {
            moved(axis)
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fan of thin triangles around a centre vertex: every ray through the fan's interior,
    /// however close to an edge or the centre, must hit at least one triangle.
    #[test]
    fn rays_through_shared_edges_never_fall_through() {
        let centre = Vec3::new(0.1, 0.2, 0.0);
        let rim: Vec<Vec3> = (0..7)
            .map(|i| {
                let a = i as f32 / 7.0 * std::f32::consts::TAU;
                centre + Vec3::new(a.cos(), a.sin(), 0.0) * (1.0 + 0.37 * i as f32)
            })
            .collect();
        let triangles: Vec<[Vec3; 3]> = (0..7).map(|i| [centre, rim[i], rim[(i + 1) % 7]]).collect();
        let origin = Vec3::new(0.3, -0.2, 5.0);
        // Rays aimed at points of the edges themselves (exactly representable interpolations
        // are rare, so these land within an ulp of each edge, on either side), and at the centre.
        let mut targets = vec![centre];
        for r in &rim {
            for k in 1..200 {
                targets.push(centre.lerp(*r, k as f32 / 200.0));
            }
        }
        for target in targets {
            let ray = WatertightRay::new(origin, (target - origin).normalize());
            let hits = triangles.iter().filter(|t| ray.intersect(**t, f32::INFINITY).is_some()).count();
            assert!(hits >= 1, "a ray towards {target} fell through the mesh");
        }
    }

    #[test]
    fn hit_distance_barycentrics_and_range() {
        let tri = [Vec3::new(0.0, 0.0, -2.0), Vec3::new(1.0, 0.0, -2.0), Vec3::new(0.0, 1.0, -2.0)];
        let ray = WatertightRay::new(Vec3::new(0.25, 0.5, 0.0), Vec3::NEG_Z);
        let (t, [b1, b2]) = ray.intersect(tri, 10.0).unwrap();
        assert!((t - 2.0).abs() < 1e-6 && (b1 - 0.25).abs() < 1e-6 && (b2 - 0.5).abs() < 1e-6);
        // Both windings hit (two-sided), nothing at or beyond tmax, nothing behind the origin.
        assert!(ray.intersect([tri[0], tri[2], tri[1]], 10.0).is_some());
        assert!(ray.intersect(tri, 2.0).is_none());
        assert!(WatertightRay::new(Vec3::new(0.25, 0.5, -3.0), Vec3::NEG_Z).intersect(tri, 10.0).is_none());
        // Unnormalised directions measure t in their own units.
        let (t, _) =
            WatertightRay::new(Vec3::new(0.25, 0.5, 0.0), Vec3::NEG_Z * 4.0).intersect(tri, 10.0).unwrap();
        assert!((t - 0.5).abs() < 1e-6);
    }

    #[test]
    fn offset_moves_to_the_normal_side_at_every_scale() {
        for p in [Vec3::ZERO, Vec3::new(1e-3, -2.0, 3e4), Vec3::new(-5e5, 0.02, 7.0)] {
            for n in [Vec3::X, Vec3::NEG_Y, Vec3::new(0.6, 0.0, -0.8)] {
                let q = offset_ray_origin(p, n);
                assert!((q - p).dot(n) > 0.0, "{p} along {n} gave {q}");
                assert!((q - p).length() < 1e-3 * (1.0 + p.abs().max_element()));
            }
        }
    }
}
