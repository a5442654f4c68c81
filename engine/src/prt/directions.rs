//! The directions the transfer shader (`shaders-glsl/prt_transfer.comp`) casts from a vertex,
//! computed again on the CPU: to check the shader's sums against (the lanes cast the points in
//! another order, which must still be every point once) and to hand the same rays to another
//! ray tracer (`kage bench rays --export`).
use glam::Vec3;

/// The `k`-th of `rays` cosine-weighted directions about unit normal `n` of vertex `vertex`
/// (its index over the whole scene, which seeds its shift): the Hammersley point
/// (k / rays, radical inverse of k), rotated by the vertex's hashed shift (Cranley–Patterson),
/// lifted from the unit disc onto the hemisphere.
pub fn direction(vertex: u32, n: Vec3, k: u32, rays: u32) -> Vec3 {
    let to_unit = 1.0 / 4_294_967_296.0;
    let shift = [pcg_hash(2 * vertex), pcg_hash(2 * vertex + 1)].map(|h| (f64::from(h) * to_unit) as f32);
    let u = [k as f32 / rays as f32 + shift[0], (f64::from(k.reverse_bits()) * to_unit) as f32 + shift[1]]
        .map(f32::fract);
    let (r, phi) = (u[0].sqrt(), 2.0 * std::f32::consts::PI * u[1]);
    let (tangent, bitangent) = tangent_frame(n);
    (r * phi.cos() * tangent + r * phi.sin() * bitangent + (1.0 - u[0]).max(0.0).sqrt() * n).normalize()
}

/// PCG output permutation (Jarzynski and Olano 2020), as the shader has it.
fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The shader's orthonormal frame about unit `n`, without a branch on its direction (Duff et
/// al. 2017).
fn tangent_frame(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let c = n.x * n.y * a;
    (Vec3::new(1.0 + s * n.x * n.x * a, s * c, -s * n.x), Vec3::new(c, s + n.y * n.y * a, -n.y))
}
