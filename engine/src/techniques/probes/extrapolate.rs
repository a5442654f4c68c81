//! Outside the convex hull: the weights of the nearest point of the hull.
//!
//! The nearest point of a convex set moves continuously with p, and on the hull the weights of a
//! hull face are those of its tetrahedron (the fourth vertex's weight is 0 there), so lookups are
//! continuous across the hull and stay a convex combination of probes far away: never black,
//! never NaN. Far from the hull the lighting is that of the hull's nearest point, not an
//! extrapolated trend, which cannot overshoot.
use glam::DVec3;

/// A face of the convex hull: face `slot` of tetrahedron `tet`, with vertices `v` (input indices).
#[derive(Clone, Copy, Debug)]
pub struct HullFace {
    pub tet: u32,
    pub slot: usize,
    pub v: [u32; 3],
}

/// The hull faces and, for each vertex, the faces around it.
pub struct Hull {
    pub faces: Vec<HullFace>,
    fan_start: Vec<u32>,
    fans: Vec<u32>,
}

/// The point of a hull face nearest p: the face, the weights of its three vertices, the squared
/// distance, and the faces tried on the way there.
#[derive(Clone, Copy, Debug)]
pub struct Nearest {
    pub face: u32,
    pub weights: [f64; 3],
    pub distance2: f64,
    pub steps: u32,
}

impl Hull {
    pub fn new(vertex_count: usize, faces: Vec<HullFace>) -> Hull {
        let mut fan_start = vec![0u32; vertex_count + 1];
        for face in &faces {
            for v in face.v {
                fan_start[v as usize + 1] += 1;
            }
        }
        for i in 0..vertex_count {
            fan_start[i + 1] += fan_start[i];
        }
        let mut fill = fan_start.clone();
        let mut fans = vec![0; fan_start[vertex_count] as usize];
        for (f, face) in faces.iter().enumerate() {
            for v in face.v {
                fans[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        Hull { faces, fan_start, fans }
    }

    fn fan(&self, v: u32) -> &[u32] {
        &self.fans[self.fan_start[v as usize] as usize..self.fan_start[v as usize + 1] as usize]
    }

    /// Greedy descent over the faces around the current face's vertices, from `start`. The
    /// distance to a convex set has no local minimum but the global one, and the nearest point of
    /// a face lies inside it, on an edge or at a vertex, all of whose faces are tried: so the
    /// descent stops only at the nearest face. Each step strictly decreases the distance, so it
    /// ends.
    pub fn nearest(&self, positions: &[DVec3], p: DVec3, start: u32) -> Nearest {
        let at = |face: u32, steps| {
            let v = self.faces[face as usize].v.map(|i| positions[i as usize]);
            let (weights, distance2) = closest_on_triangle(p, v);
            Nearest { face, weights, distance2, steps }
        };
        let mut best = at(start, 0);
        loop {
            let mut next = best;
            for v in self.faces[best.face as usize].v {
                for &face in self.fan(v) {
                    let candidate = at(face, best.steps + 1);
                    if candidate.distance2 < next.distance2 {
                        next = candidate;
                    }
                }
            }
            if next.face == best.face {
                return best;
            }
            best = next;
        }
    }
}

/// The barycentric weights of the point of triangle t nearest p, and the squared distance.
pub(super) fn closest_on_triangle(p: DVec3, t: [DVec3; 3]) -> ([f64; 3], f64) {
    let [a, b, c] = t;
    let n = (b - a).cross(c - a);
    let area2 = n.length_squared();
    if area2 > 0.0 {
        // Barycentrics of p's projection onto the plane: signed sub-triangle areas.
        let wa = (b - p).cross(c - p).dot(n) / area2;
        let wb = (c - p).cross(a - p).dot(n) / area2;
        let w = [wa, wb, 1.0 - wa - wb];
        if w.iter().all(|&x| x >= 0.0) {
            let q = w[0] * a + w[1] * b + w[2] * c;
            return (w, p.distance_squared(q));
        }
    }
    // Otherwise the nearest point is on the boundary: the nearest of the three edges.
    let edge = |i: usize| {
        let (u, v) = (t[i], t[(i + 1) % 3]);
        let s = ((p - u).dot(v - u) / u.distance_squared(v)).clamp(0.0, 1.0);
        let mut w = [0.0; 3];
        w[i] = 1.0 - s;
        w[(i + 1) % 3] = s;
        (w, p.distance_squared(u.lerp(v, s)))
    };
    [edge(1), edge(2)].into_iter().fold(edge(0), |best, e| if e.1 < best.1 { e } else { best })
}
