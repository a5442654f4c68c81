//! Rotating SH coefficients. A rotation maps each band onto itself, so for every band l there is
//! a (2l+1)×(2l+1) matrix D_l with y_l(R ω) = D_l y_l(ω). Kage finds D_l by evaluating the
//! basis at a fixed, well-spread set of directions before and after the rotation and solving
//! the least-squares system once per band; with more directions than unknowns the fit is exact
//! to rounding (tested against projection of rotated functions), with no recurrence to get wrong.
use super::{coeff_count, eval_basis_f64, MAX_BANDS};
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// Directions used for the fit: a Fibonacci spiral, so no band's evaluation matrix is singular.
const FIT_DIRECTIONS: usize = 64;

fn fit_directions() -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..FIT_DIRECTIONS)
        .map(|k| {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / FIT_DIRECTIONS as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * k as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// Per band: the pseudo-inverse P_l = Aᵀ(AAᵀ)⁻¹ of the basis evaluated at the fit directions
/// (A is (2l+1)×N), stored row-major N×(2l+1).
fn pseudo_inverses() -> &'static [Vec<f64>] {
    static CELL: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    CELL.get_or_init(|| {
        let dirs = fit_directions();
        let mut all = vec![0.0; coeff_count(MAX_BANDS)];
        let evaluated: Vec<Vec<f64>> = dirs
            .iter()
            .map(|&d| {
                eval_basis_f64(MAX_BANDS, d, &mut all);
                all.clone()
            })
            .collect();
        (0..MAX_BANDS)
            .map(|l| {
                let (first, n) = (l * l, 2 * l + 1);
                let a = |m: usize, k: usize| evaluated[k][first + m];
                // AAᵀ, then its inverse by Gauss–Jordan (small, symmetric positive definite).
                let mut gram = vec![0.0; n * n];
                for i in 0..n {
                    for j in 0..n {
                        gram[i * n + j] = (0..dirs.len()).map(|k| a(i, k) * a(j, k)).sum();
                    }
                }
                let inv = invert(&gram, n);
                let mut p = vec![0.0; dirs.len() * n];
                for k in 0..dirs.len() {
                    for j in 0..n {
                        p[k * n + j] = (0..n).map(|i| a(i, k) * inv[i * n + j]).sum();
                    }
                }
                p
            })
            .collect()
    })
}

/// Inverse of an n×n well-conditioned matrix (Gauss–Jordan with partial pivoting).
fn invert(m: &[f64], n: usize) -> Vec<f64> {
    let mut a = m.to_vec();
    let mut inv: Vec<f64> = (0..n * n).map(|i| if i / n == i % n { 1.0 } else { 0.0 }).collect();
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&x, &y| a[x * n + col].abs().total_cmp(&a[y * n + col].abs())).unwrap_or(col);
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
            inv.swap(col * n + k, pivot * n + k);
        }
        let d = a[col * n + col];
        for k in 0..n {
            a[col * n + k] /= d;
            inv[col * n + k] /= d;
        }
        for row in (0..n).filter(|&r| r != col) {
            let f = a[row * n + col];
            for k in 0..n {
                a[row * n + k] -= f * a[col * n + k];
                inv[row * n + k] -= f * inv[col * n + k];
            }
        }
    }
    inv
}

/// The coefficients of g(ω) = f(R ω), given those of f, for `bands` bands (≤ 5), per channel.
/// With R the object-to-world rotation of a group and f the environment in world space, g is
/// the environment as the group's object space sees it.
pub fn rotate(coeffs: &[[f64; 3]], bands: usize, rotation: DMat3) -> Vec<[f64; 3]> {
    let bands = bands.min(MAX_BANDS);
    let mut out = vec![[0.0; 3]; coeff_count(bands)];
    let dirs = fit_directions();
    let mut all = vec![0.0; coeff_count(bands)];
    let rotated: Vec<Vec<f64>> = dirs
        .iter()
        .map(|&d| {
            eval_basis_f64(bands, rotation * d, &mut all);
            all.clone()
        })
        .collect();
    for (l, p) in pseudo_inverses().iter().enumerate().take(bands) {
        let (first, n) = (l * l, 2 * l + 1);
        // D = B P with B[m][k] = y_lm(R ω_k); g = Dᵀ c.
        for m in 0..n {
            for j in 0..n {
                let d: f64 = (0..dirs.len()).map(|k| rotated[k][first + m] * p[k * n + j]).sum();
                for ch in 0..3 {
                    out[first + j][ch] += d * coeffs.get(first + m).map_or(0.0, |c| c[ch]);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(ω) = exp(2 (ω·a)) − a wiggle: smooth, with energy in every band up to 4.
    fn f(w: DVec3) -> f64 {
        let a = DVec3::new(0.3, -0.5, 0.8).normalize();
        (2.0 * w.dot(a)).exp() + w.x * w.y * w.z
    }

    /// Projection by quadrature on a fine latitude–longitude grid (exact for band-limited
    /// products to far below the tolerance).
    fn project(g: impl Fn(DVec3) -> f64, bands: usize) -> Vec<f64> {
        let (nt, np) = (200, 400);
        let mut out = vec![0.0; coeff_count(bands)];
        let mut y = vec![0.0; coeff_count(bands)];
        for i in 0..nt {
            let (t0, t1) = (
                std::f64::consts::PI * i as f64 / nt as f64,
                std::f64::consts::PI * (i + 1) as f64 / nt as f64,
            );
            let t = 0.5 * (t0 + t1);
            for j in 0..np {
                let p = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
                let w = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                let d_omega = (t0.cos() - t1.cos()) * 2.0 * std::f64::consts::PI / np as f64;
                eval_basis_f64(bands, w, &mut y);
                let v = g(w);
                for (o, yi) in out.iter_mut().zip(&y) {
                    *o += v * yi * d_omega;
                }
            }
        }
        out
    }

    #[test]
    fn rotated_coefficients_are_those_of_the_rotated_function() {
        let r = DMat3::from_euler(glam::EulerRot::ZYX, 0.7, -1.1, 0.4);
        let c: Vec<[f64; 3]> = project(f, 5).into_iter().map(|v| [v, 2.0 * v, -v]).collect();
        let rotated = rotate(&c, 5, r);
        let expected = project(|w| f(r * w), 5);
        // The midpoint quadrature of `project` is good to a few 1e-5 of the largest coefficient;
        // the rotation itself is exact to rounding (next test).
        let scale = expected.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        for (i, e) in expected.iter().enumerate() {
            assert!((rotated[i][0] - e).abs() < 1e-4 * scale, "coefficient {i}: {} vs {e}", rotated[i][0]);
            assert!((rotated[i][1] - 2.0 * e).abs() < 2e-4 * scale);
        }
    }

    #[test]
    fn identity_and_inverse_round_trip_exactly() {
        let c: Vec<[f64; 3]> = (0..25).map(|i| [i as f64 * 0.1 - 1.0, (i * i) as f64 * 0.01, 1.0]).collect();
        let same = rotate(&c, 5, DMat3::IDENTITY);
        let r = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 2.3);
        let back = rotate(&rotate(&c, 5, r), 5, r.transpose());
        for i in 0..25 {
            for ch in 0..3 {
                assert!((same[i][ch] - c[i][ch]).abs() < 1e-12);
                assert!((back[i][ch] - c[i][ch]).abs() < 1e-10, "{i}: {} vs {}", back[i][ch], c[i][ch]);
            }
        }
    }
}
