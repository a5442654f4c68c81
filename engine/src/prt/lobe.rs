//! The transfer of an unshadowed vertex in closed form: the SH projection of the normalised
//! clamped cosine lobe `(1/π) max(ω·n, 0)`. What every vertex of a convex object must get, so
//! it is the check of the whole precomputation.
//!
//! # Derivation
//! About the z axis the lobe is zonal, with coefficients
//! `h_l = ∫ (1/π) max(cos θ, 0) y_l^0(ω) dω = 2 ∫₀¹ z y_l^0(z) dz`:
//! `h_0 = 1/(2√π)`, `h_1 = 1/√(3π)`, `h_2 = √5/(8√π)`, `h_3 = 0`, `h_4 = −1/(16√π)`
//! (times π these are the usual √π/2, √(π/3), √(5π)/8, 0, −√π/16).
//! A zonal function rotated from z to `n` has coefficients `√(4π/(2l+1)) h_l y_l^m(n)` (the
//! addition theorem), and `√(4π/(2l+1)) h_l` is Ramamoorthi & Hanrahan's Â_l divided by π:
//! 1, 2/3, 1/4, 0, −1/24. So `T_l^m(n) = (Â_l/π) y_l^m(n)`.
use glam::DVec3;

use crate::sh;

/// `Â_l / π` for l = 0..=4.
const BAND_FACTOR: [f64; 5] = [1.0, 2.0 / 3.0, 0.25, 0.0, -1.0 / 24.0];

/// The unshadowed transfer vector of a vertex with unit normal `n`: `bands²` coefficients
/// (`bands` is cut to [`sh::MAX_BANDS`]).
pub fn clamped_cosine(bands: usize, n: DVec3) -> Vec<f64> {
    let bands = bands.min(sh::MAX_BANDS);
    let mut y = [0.0; 25];
    let count = sh::eval_basis_f64(bands, n, &mut y);
    (0..count).map(|i| BAND_FACTOR[band_of(i)] * y[i]).collect()
}

/// The band `l` of coefficient `i = l(l + 1) + m`.
fn band_of(i: usize) -> usize {
    (i as f64).sqrt() as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn band_of_inverts_the_index() {
        for l in 0..5usize {
            for i in l * l..(l + 1) * (l + 1) {
                assert_eq!(band_of(i), l);
            }
        }
    }

    /// Integrates the lobe against the basis with a fine product rule (midpoint in z and φ) and
    /// compares every coefficient, for several normals: checks the band factors and the
    /// rotation together.
    #[test]
    fn closed_form_matches_numerical_projection() {
        let normals = [
            DVec3::Z,
            DVec3::Y,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::new(-0.9, 0.1, -0.2).normalize(),
        ];
        let (nz, nphi) = (1500, 1500);
        for n in normals {
            let mut sum = [0.0f64; 25];
            let mut y = [0.0f64; 25];
            for i in 0..nz {
                let z = -1.0 + (i as f64 + 0.5) * 2.0 / nz as f64;
                let r = (1.0 - z * z).sqrt();
                for j in 0..nphi {
                    let phi = (j as f64 + 0.5) * 2.0 * PI / nphi as f64;
                    let w = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                    let lobe = w.dot(n).max(0.0) / PI;
                    sh::eval_basis_f64(5, w, &mut y);
                    for (s, yi) in sum.iter_mut().zip(y) {
                        *s += lobe * yi;
                    }
                }
            }
            let d_omega = (2.0 / nz as f64) * (2.0 * PI / nphi as f64);
            let expected = clamped_cosine(5, n);
            for (i, (s, e)) in sum.iter().zip(&expected).enumerate() {
                // The kink of max(·, 0) limits the midpoint rule: 4.5e-6 at worst at this resolution.
                assert!((s * d_omega - e).abs() < 2e-5, "n={n} i={i}: {} vs {e}", s * d_omega);
            }
        }
    }
}
