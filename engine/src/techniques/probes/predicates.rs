//! Exact geometric predicates (Shewchuk's adaptive ones, from the `robust` crate) in Kage's
//! orientation convention, and the symbolic perturbation that breaks in-sphere ties.
//!
//! Convention: [`orient`]`(a, b, c, d) > 0` when (b − a) · ((c − a) × (d − a)) > 0, that is when the
//! tetrahedron abcd is positively (right-handed) oriented; `robust::orient3d` has the opposite sign.
//!
//! Ties (five cospherical points: every cube of a grid) are broken as if each point i were lifted
//! by a weight εⁱ (Devillers & Teillaud 2011, "Perturbations for Delaunay and weighted Delaunay 3D
//! triangulations"), so the result is the Delaunay tetrahedralization of a set in general position:
//! consistent whatever the insertion order, and never with a flat tetrahedron.
use glam::DVec3;
use robust::{Coord, Coord3D};

fn coord(p: DVec3) -> Coord3D<f64> {
    Coord3D { x: p.x, y: p.y, z: p.z }
}

/// Positive when abcd is positively oriented, negative when negatively, zero when coplanar; the
/// sign is exact.
pub fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    -robust::orient3d(coord(a), coord(b), coord(c), coord(d))
}

/// For abcd positively oriented: positive when e is strictly inside the sphere through a, b, c and
/// d, negative outside, zero on it; the sign is exact.
pub fn in_sphere(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> f64 {
    // `robust::insphere` wants its own positive orientation, which is our negative one.
    -robust::insphere(coord(a), coord(b), coord(c), coord(d), coord(e))
}

/// [`orient`] of four points given by index.
pub fn orient_at(points: &[DVec3], v: [u32; 4]) -> f64 {
    let [a, b, c, d] = v.map(|i| points[i as usize]);
    orient(a, b, c, d)
}

/// Whether point `e` is inside the perturbed circumsphere of the positively oriented tetrahedron
/// `v` (all indices distinct, points distinct).
pub fn inside_sphere(points: &[DVec3], v: [u32; 4], e: u32) -> bool {
    let [a, b, c, d] = v.map(|i| points[i as usize]);
    let s = in_sphere(a, b, c, d, points[e as usize]);
    if s != 0.0 {
        return s > 0.0;
    }
    // The perturbed determinant is a polynomial in ε whose leading coefficients are, for the
    // most perturbed points first, the orientation of the tetrahedron with that point replaced by
    // e (or, when e itself comes first, the orientation of abcd: positive, so e is outside). Two
    // terms suffice: if both vanished, e would lie on the line through the two other vertices and
    // on the sphere, i.e. coincide with one of them.
    for q in most_perturbed::<5>([v[0], v[1], v[2], v[3], e]).into_iter().take(2) {
        // q == e: its coefficient is the orientation of abcd, positive, so e is outside.
        let Some(slot) = v.iter().position(|&x| x == q) else { return false };
        let mut w = v;
        w[slot] = e;
        let o = orient_at(points, w);
        if o != 0.0 {
            return o > 0.0;
        }
    }
    false
}

/// For e coplanar with the triangle `t`: whether e is inside the perturbed circumcircle of `t`.
/// This is the in-sphere test of a cell joining a hull face to the infinite vertex, when the new
/// point lies in the plane of that face.
pub fn inside_circle(points: &[DVec3], t: [u32; 3], e: u32) -> bool {
    let [a, b, c] = t.map(|i| points[i as usize]);
    let p = points[e as usize];
    // Within the common plane, drop the axis along which the triangle's projection is largest:
    // an affine bijection of the plane, so orientations keep their signs up to one common factor.
    let axis = (0..3)
        .max_by(|&i, &j| orient2d(a, b, c, i).abs().total_cmp(&orient2d(a, b, c, j).abs()))
        .unwrap_or(0);
    // The sphere through a, b, c and any point off their plane cuts the plane in the triangle's
    // circumcircle, so the exact in-sphere test with such a point decides the in-circle test.
    let mut off = a;
    off[axis] += a.abs().max_element().max(1.0);
    let o = orient(a, b, c, off);
    let s = in_sphere(a, b, c, off, p);
    if s != 0.0 {
        return (s > 0.0) == (o > 0.0);
    }
    let local = orient2d(a, b, c, axis);
    for q in most_perturbed::<4>([t[0], t[1], t[2], e]).into_iter().take(3) {
        // q == e: its coefficient is the triangle's own orientation, so e is outside.
        let Some(slot) = t.iter().position(|&x| x == q) else { return false };
        let mut w = [a, b, c];
        w[slot] = p;
        let o = orient2d(w[0], w[1], w[2], axis);
        if o != 0.0 {
            return (o > 0.0) == (local > 0.0);
        }
    }
    false
}

/// The indices in decreasing order of perturbation (the highest index is perturbed most).
fn most_perturbed<const N: usize>(mut v: [u32; N]) -> [u32; N] {
    v.sort_unstable_by(|a, b| b.cmp(a));
    v
}

/// The exact orientation of triangle abc projected along `axis`.
fn orient2d(a: DVec3, b: DVec3, c: DVec3, axis: usize) -> f64 {
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    let flat = |p: DVec3| Coord { x: p[i], y: p[j] };
    robust::orient2d(flat(a), flat(b), flat(c))
}

/// Whether a, b and c lie on one line (exactly).
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    (0..3).all(|axis| orient2d(a, b, c, axis) == 0.0)
}
