//! Real spherical harmonics on the CPU: the reference that the GPU projection and the tests are
//! checked against, so everything here favours exactness over speed (f64 sums, exact solid
//! angles, normalisation constants computed from their closed forms rather than rounded).
//!
//! # Basis and ordering
//!
//! The standard orthonormal real basis of Sloan's "Stupid Spherical Harmonics (SH) Tricks" and
//! Ramamoorthi & Hanrahan 2001, without the Condon–Shortley phase (every constant below is
//! positive). Coefficient `i = l(l + 1) + m` holds `y_l^m`, for `l = 0..=4` (`bands = 1..=5`, so
//! at most [`coeff_count`]`(5) = 25` coefficients). For a unit direction `(x, y, z)`:
//!
//! | l | m → polynomial (times its constant `K_l^m`) |
//! |---|---|
//! | 0 | 0: 1 (`K = 1/(2√π)` ≈ 0.282095) |
//! | 1 | −1: y, 0: z, 1: x (`K = √(3/(4π))` ≈ 0.488603) |
//! | 2 | −2: xy (1.092548), −1: yz (1.092548), 0: 3z² − 1 (0.315392), 1: xz (1.092548), 2: x² − y² (0.546274) |
//! | 3 | −3: y(3x² − y²), −2: xyz, −1: y(5z² − 1), 0: z(5z² − 3), 1: x(5z² − 1), 2: z(x² − y²), 3: x(x² − 3y²) |
//! | 4 | −4: xy(x² − y²), −3: yz(3x² − y²), −2: xy(7z² − 1), −1: yz(7z² − 3), 0: 35z⁴ − 30z² + 3, 1: xz(7z² − 3), 2: (x² − y²)(7z² − 1), 3: xz(x² − 3y²), 4: x²(x² − 3y²) − y²(3x² − y²) |
//!
//! The l = 3 and 4 constants are in `K` below, each written as its closed form.
//!
//! Kage is +Y up, but these are the textbook Cartesian formulas applied to Kage's (x, y, z)
//! as they are: here z is just an axis and the "zonal" functions (m = 0) are symmetric about
//! Kage's z axis, not about up. Keeping the textbook form means coefficients can be compared
//! with published values and the shaders can copy the polynomials verbatim.
pub mod rotation;

use glam::{DVec3, Mat4, Vec3};
use std::f64::consts::PI;

pub use crate::equirect::{equirect_direction, equirect_texel_solid_angle};
use crate::{Error, Result};

/// The most bands (l = 0..=4) that [`eval_basis`] and [`project_equirect`] handle.
pub const MAX_BANDS: usize = 5;

/// Number of coefficients in the first `bands` bands.
pub const fn coeff_count(bands: usize) -> usize {
    bands * bands
}

/// `f64::sqrt` is not `const`; Heron's iteration started above the root decreases monotonically,
/// so stopping when it no longer decreases gives the root to the last bit or so (a test checks
/// every constant against `f64::sqrt`). Only called on positive constants.
const fn const_sqrt(x: f64) -> f64 {
    let mut y = if x > 1.0 { x } else { 1.0 };
    loop {
        let next = 0.5 * (y + x / y);
        if next >= y {
            return y;
        }
        y = next;
    }
}

/// `K_l^m` for the polynomials in the module doc, indexed like the coefficients.
const K: [f64; 25] = [
    // l = 0
    0.5 * const_sqrt(1.0 / PI),
    // l = 1
    const_sqrt(3.0 / (4.0 * PI)),
    const_sqrt(3.0 / (4.0 * PI)),
    const_sqrt(3.0 / (4.0 * PI)),
    // l = 2
    0.5 * const_sqrt(15.0 / PI),
    0.5 * const_sqrt(15.0 / PI),
    0.25 * const_sqrt(5.0 / PI),
    0.5 * const_sqrt(15.0 / PI),
    0.25 * const_sqrt(15.0 / PI),
    // l = 3
    0.25 * const_sqrt(35.0 / (2.0 * PI)),
    0.5 * const_sqrt(105.0 / PI),
    0.25 * const_sqrt(21.0 / (2.0 * PI)),
    0.25 * const_sqrt(7.0 / PI),
    0.25 * const_sqrt(21.0 / (2.0 * PI)),
    0.25 * const_sqrt(105.0 / PI),
    0.25 * const_sqrt(35.0 / (2.0 * PI)),
    // l = 4
    0.75 * const_sqrt(35.0 / PI),
    0.75 * const_sqrt(35.0 / (2.0 * PI)),
    0.75 * const_sqrt(5.0 / PI),
    0.75 * const_sqrt(5.0 / (2.0 * PI)),
    (3.0 / 16.0) * const_sqrt(1.0 / PI),
    0.75 * const_sqrt(5.0 / (2.0 * PI)),
    (3.0 / 8.0) * const_sqrt(5.0 / PI),
    0.75 * const_sqrt(35.0 / (2.0 * PI)),
    (3.0 / 16.0) * const_sqrt(35.0 / PI),
];

/// All 25 basis functions at once: they share most products, and callers wanting fewer just
/// take a prefix.
fn basis25(d: DVec3) -> [f64; 25] {
    let (x, y, z) = (d.x, d.y, d.z);
    let (x2, y2, z2) = (x * x, y * y, z * z);
    let poly = [
        1.0,
        y,
        z,
        x,
        x * y,
        y * z,
        3.0 * z2 - 1.0,
        x * z,
        x2 - y2,
        y * (3.0 * x2 - y2),
        x * y * z,
        y * (5.0 * z2 - 1.0),
        z * (5.0 * z2 - 3.0),
        x * (5.0 * z2 - 1.0),
        z * (x2 - y2),
        x * (x2 - 3.0 * y2),
        x * y * (x2 - y2),
        y * z * (3.0 * x2 - y2),
        x * y * (7.0 * z2 - 1.0),
        y * z * (7.0 * z2 - 3.0),
        (35.0 * z2 - 30.0) * z2 + 3.0,
        x * z * (7.0 * z2 - 3.0),
        (x2 - y2) * (7.0 * z2 - 1.0),
        x * z * (x2 - 3.0 * y2),
        x2 * (x2 - 3.0 * y2) - y2 * (3.0 * x2 - y2),
    ];
    std::array::from_fn(|i| K[i] * poly[i])
}

/// Evaluates the basis functions of the first `bands` bands at `dir` into `out`, in the order of
/// the module doc, and returns how many it wrote: `coeff_count(bands.min(MAX_BANDS))`, cut to
/// `out.len()` when `out` is shorter (never a panic; compare the count when it matters).
///
/// `dir` is used as given, not normalised: the polynomials are the basis only on the unit sphere.
pub fn eval_basis(bands: usize, dir: Vec3, out: &mut [f32]) -> usize {
    let basis = basis25(dir.as_dvec3());
    let n = coeff_count(bands.min(MAX_BANDS)).min(out.len());
    for (o, b) in out[..n].iter_mut().zip(basis) {
        *o = b as f32;
    }
    n
}

/// [`eval_basis`] in f64, for sums over many directions where f32 rounding would show.
pub fn eval_basis_f64(bands: usize, dir: DVec3, out: &mut [f64]) -> usize {
    let basis = basis25(dir);
    let n = coeff_count(bands.min(MAX_BANDS)).min(out.len());
    out[..n].copy_from_slice(&basis[..n]);
    n
}

/// Ramamoorthi & Hanrahan's Â_l: the clamped-cosine kernel's per-band factor, which turns
/// radiance coefficients into irradiance coefficients.
const A_HAT: [f64; 3] = [PI, 2.0 * PI / 3.0, PI / 4.0];

fn band_of(i: usize) -> usize {
    match i {
        0 => 0,
        1..=3 => 1,
        _ => 2,
    }
}

/// Three bands (9 coefficients) of RGB radiance: `c[i][channel]`, `i` as in the module doc.
/// Enough for diffuse irradiance, whose kernel is almost entirely in bands 0–2.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShRgb9 {
    pub c: [[f32; 3]; 9],
}

impl ShRgb9 {
    /// Takes the first 9 coefficients of a projection such as [`project_equirect`]'s; `None`
    /// when it has fewer than 3 bands.
    pub fn from_f64(coeffs: &[[f64; 3]]) -> Option<Self> {
        let coeffs = coeffs.get(..9)?;
        Some(Self { c: std::array::from_fn(|i| coeffs[i].map(|v| v as f32)) })
    }

    /// Irradiance at a surface with unit normal `n` (Ramamoorthi & Hanrahan 2001, eq. 7):
    /// `E(n) = Σ Â_l L_lm y_lm(n)`. Not clamped: a map with strong, small lights can ring
    /// negative, and the caller decides what to do about it.
    pub fn irradiance(&self, n: Vec3) -> [f32; 3] {
        let y = basis25(n.as_dvec3());
        let mut e = [0.0f64; 3];
        for (i, c) in self.c.iter().enumerate() {
            let w = A_HAT[band_of(i)] * y[i];
            for ch in 0..3 {
                e[ch] += w * f64::from(c[ch]);
            }
        }
        e.map(|v| v as f32)
    }

    /// The same irradiance as the quadratic form `E(n) = (n, 1)ᵀ M (n, 1)`, one symmetric `M`
    /// per channel (Ramamoorthi & Hanrahan 2001, eq. 12): what a shader evaluates in a few
    /// multiply-adds. The paper's c1..c5 (0.429043, 0.511664, 0.743125, 0.886227, 0.247708) are
    /// rounded; they are computed here from Â_l and the basis constants so that this form agrees
    /// with [`ShRgb9::irradiance`] to f32 precision.
    pub fn irradiance_matrix(&self) -> [Mat4; 3] {
        let [c1, c2, c3, c4, c5] = irradiance_matrix_constants().map(|c| c as f32);
        std::array::from_fn(|ch| {
            let l = |i: usize| self.c[i][ch];
            Mat4::from_cols_array_2d(&[
                [c1 * l(8), c1 * l(4), c1 * l(7), c2 * l(3)],
                [c1 * l(4), -c1 * l(8), c1 * l(5), c2 * l(1)],
                [c1 * l(7), c1 * l(5), c3 * l(6), c2 * l(2)],
                [c2 * l(3), c2 * l(1), c2 * l(2), c4 * l(0) - c5 * l(6)],
            ])
        })
    }
}

/// c1..c5 of Ramamoorthi & Hanrahan eq. 12. The off-diagonal entries appear twice in `nᵀMn`,
/// hence the halves: e.g. `2·c1·xy` must give `Â2·K_2^-2·xy` with `K_2^-2 = 2·K_2^2`.
fn irradiance_matrix_constants() -> [f64; 5] {
    [A_HAT[2] * K[8], A_HAT[1] * K[3] / 2.0, 3.0 * A_HAT[2] * K[6], A_HAT[0] * K[0], A_HAT[2] * K[6]]
}

/// Projects a `width`×`height` equirectangular radiance map (row 0 at the top, row-major) onto
/// the first `bands` bands: `c_i = Σ_pixels L(ω) y_i(ω) Δω`, with each pixel's exact solid angle
/// `Δω` and its centre's direction. Returns `coeff_count(bands)` RGB coefficients.
///
/// Errors (as [`Error::InvalidArgument`]) on `bands` outside `1..=MAX_BANDS`, a zero size, a
/// pixel count other than `width·height`, or a NaN or infinite pixel.
pub fn project_equirect(width: u32, height: u32, pixels: &[[f32; 3]], bands: usize) -> Result<Vec<[f64; 3]>> {
    if !(1..=MAX_BANDS).contains(&bands) {
        return Err(Error::InvalidArgument(format!(
            "SH projection onto {bands} bands: Kage supports 1 to {MAX_BANDS}"
        )));
    }
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 || w.checked_mul(h) != Some(pixels.len()) {
        return Err(Error::InvalidArgument(format!(
            "SH projection of a {width}×{height} map given {} pixels",
            pixels.len()
        )));
    }
    if let Some(i) = pixels.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        return Err(Error::InvalidArgument(format!(
            "SH projection: pixel ({}, {}) of the {width}×{height} map is NaN or infinite",
            i % w,
            i / w
        )));
    }

    let n = coeff_count(bands);
    // Each texel as s × s sub-texels of its radiance (see `equirect_subdivisions`).
    let s = equirect_subdivisions(height);
    let (columns, rows) = (width * s, height * s);
    let mut coeffs = vec![[0.0f64; 3]; n];
    let mut basis = [0.0f64; 25];
    for (j, row) in pixels.chunks_exact(w).enumerate() {
        for sub_row in j as u32 * s..(j as u32 + 1) * s {
            let d_omega = equirect_texel_solid_angle(columns, rows, sub_row);
            let v = (f64::from(sub_row) + 0.5) / f64::from(rows);
            for (i, p) in row.iter().enumerate() {
                for sub_column in i as u32 * s..(i as u32 + 1) * s {
                    let u = (f64::from(sub_column) + 0.5) / f64::from(columns);
                    eval_basis_f64(bands, equirect_direction(u, v), &mut basis);
                    for (c, y) in coeffs.iter_mut().zip(&basis[..n]) {
                        let wy = y * d_omega;
                        for ch in 0..3 {
                            c[ch] += wy * f64::from(p[ch]);
                        }
                    }
                }
            }
        }
    }
    Ok(coeffs)
}

/// Sub-texels per side that an equirectangular map of `height` rows is projected with, as
/// `sh_project.comp` does: enough for [`constants::SH_MIN_ROWS`] rows (1 from that height on),
/// each sub-texel with its exact solid angle and its centre's direction. One sample per texel
/// puts a 2×1 map's whole sphere on its horizon.
///
/// [`constants::SH_MIN_ROWS`]: crate::layouts::constants::SH_MIN_ROWS
pub(crate) fn equirect_subdivisions(height: u32) -> u32 {
    crate::layouts::constants::SH_MIN_ROWS.div_ceil(height.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An independent construction of the same basis from spherical coordinates and the
    /// associated Legendre recurrence (no Condon–Shortley phase), to check the hand-expanded
    /// polynomials, signs included.
    fn reference_basis(l: usize, m: i64, d: DVec3) -> f64 {
        let am = m.unsigned_abs() as usize;
        let ct = d.z;
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let phi = d.y.atan2(d.x);
        // P_m^m, then upwards in l.
        let mut pmm = 1.0;
        for k in 0..am {
            pmm *= (2 * k + 1) as f64 * st;
        }
        let mut p = pmm;
        if l > am {
            let mut prev = pmm;
            p = ct * (2 * am + 1) as f64 * pmm;
            for ll in (am + 2)..=l {
                let next = ((2 * ll - 1) as f64 * ct * p - (ll + am - 1) as f64 * prev) / (ll - am) as f64;
                prev = p;
                p = next;
            }
        }
        let fact = |n: usize| (1..=n).map(|k| k as f64).product::<f64>();
        let k = ((2 * l + 1) as f64 / (4.0 * PI) * fact(l - am) / fact(l + am)).sqrt();
        match m {
            0 => k * p,
            m if m > 0 => 2f64.sqrt() * k * (m as f64 * phi).cos() * p,
            m => 2f64.sqrt() * k * (-m as f64 * phi).sin() * p,
        }
    }

    fn test_dirs() -> Vec<DVec3> {
        (0..200)
            .map(|i| {
                // A spread of directions that avoids the axes.
                let t = i as f64;
                DVec3::new((t * 1.7).sin(), (t * 0.37 + 0.2).cos(), (t * 2.9).sin() + 0.1).normalize()
            })
            .collect()
    }

    #[test]
    fn const_sqrt_matches_std() {
        for x in [
            1.0 / PI,
            3.0 / (4.0 * PI),
            15.0 / PI,
            35.0 / (2.0 * PI),
            105.0 / PI,
            7.0 / PI,
            21.0 / (2.0 * PI),
            5.0 / PI,
            5.0 / (2.0 * PI),
            35.0 / PI,
        ] {
            let (a, b) = (const_sqrt(x), x.sqrt());
            assert!((a - b).abs() <= b * f64::EPSILON, "{x}: {a} vs {b}");
        }
    }

    #[test]
    fn low_order_constants_match_the_published_values() {
        let published =
            [0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392, 1.092548, 0.546274];
        for (k, p) in K.iter().zip(published) {
            assert!((k - p).abs() < 5e-7, "{k} vs {p}");
        }
    }

    #[test]
    fn basis_matches_the_legendre_construction() {
        for d in test_dirs() {
            let mut out = [0.0; 25];
            assert_eq!(eval_basis_f64(5, d, &mut out), 25);
            for l in 0..5usize {
                for m in -(l as i64)..=(l as i64) {
                    let i = (l * (l + 1)) as i64 + m;
                    let r = reference_basis(l, m, d);
                    assert!((out[i as usize] - r).abs() < 1e-12, "l={l} m={m}: {} vs {r}", out[i as usize]);
                }
            }
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        // dω = dz dφ: a fine midpoint rule in z times an evenly spaced φ rule, which is exact for
        // the trigonometric degrees involved (≤ 8), integrates the products to ~1e-7.
        let (nz, nphi) = (2000, 64);
        let mut gram = [[0.0f64; 25]; 25];
        let mut y = [0.0; 25];
        for a in 0..nz {
            let z = -1.0 + 2.0 * (a as f64 + 0.5) / nz as f64;
            let r = (1.0 - z * z).sqrt();
            for b in 0..nphi {
                let phi = 2.0 * PI * b as f64 / nphi as f64;
                eval_basis_f64(5, DVec3::new(r * phi.cos(), r * phi.sin(), z), &mut y);
                for i in 0..25 {
                    for j in 0..25 {
                        gram[i][j] += y[i] * y[j];
                    }
                }
            }
        }
        let d_omega = 4.0 * PI / (nz * nphi) as f64;
        for (i, row) in gram.iter().enumerate() {
            for (j, g) in row.iter().enumerate() {
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((g * d_omega - expected).abs() < 1e-5, "<y{i}, y{j}> = {}", g * d_omega);
            }
        }
    }

    #[test]
    fn eval_basis_counts_and_truncates() {
        let mut out = [7.0f32; 25];
        assert_eq!(eval_basis(3, Vec3::Y, &mut out), 9);
        assert_eq!(out[9], 7.0, "beyond the requested bands is left alone");
        assert!((out[1] - 0.488603).abs() < 1e-6);
        assert_eq!(eval_basis(9, Vec3::Y, &mut out), 25);
        assert_eq!(eval_basis(3, Vec3::Y, &mut out[..4]), 4);
        assert_eq!(eval_basis(0, Vec3::Y, &mut out), 0);
    }

    #[test]
    fn solid_angles_sum_to_the_sphere() {
        for (w, h) in [(1, 1), (8, 4), (512, 256), (7, 3)] {
            let total: f64 = (0..h).map(|r| w as f64 * equirect_texel_solid_angle(w, h, r)).sum();
            assert!((total - 4.0 * PI).abs() < 1e-9, "{w}×{h}: {total}");
        }
        assert_eq!(equirect_texel_solid_angle(8, 4, 4), 0.0);
        assert_eq!(equirect_texel_solid_angle(0, 4, 0), 0.0);
    }

    #[test]
    fn equirect_direction_follows_the_convention() {
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
        assert!(close(equirect_direction(0.25, 0.5), DVec3::X));
        assert!(close(equirect_direction(0.0, 0.5), -DVec3::Z));
        assert!(close(equirect_direction(0.5, 0.5), DVec3::Z));
        assert!(close(equirect_direction(0.75, 0.5), -DVec3::X));
        assert!(close(equirect_direction(0.3, 0.0), DVec3::Y));
        assert!(close(equirect_direction(0.3, 1.0), -DVec3::Y));
        // And it inverts u = atan2(x, −z)/2π wrapped into [0, 1), v = acos(y)/π.
        for j in 0..16 {
            for i in 0..32 {
                let (u, v) = ((i as f64 + 0.5) / 32.0, (j as f64 + 0.5) / 16.0);
                let d = equirect_direction(u, v);
                assert!((d.length() - 1.0).abs() < 1e-12);
                let back_u = (d.x.atan2(-d.z) / (2.0 * PI)).rem_euclid(1.0);
                assert!((back_u - u).abs() < 1e-12, "u {u} → {back_u}");
                assert!((d.y.acos() / PI - v).abs() < 1e-12, "v {v}");
            }
        }
    }

    fn map(w: u32, h: u32, f: impl Fn(DVec3) -> [f32; 3]) -> Vec<[f32; 3]> {
        let mut pixels = Vec::with_capacity((w * h) as usize);
        for j in 0..h {
            for i in 0..w {
                let u = (i as f64 + 0.5) / w as f64;
                let v = (j as f64 + 0.5) / h as f64;
                pixels.push(f(equirect_direction(u, v)));
            }
        }
        pixels
    }

    #[test]
    fn constant_map_projects_onto_the_first_coefficient_only() {
        let c = [0.5f32, 1.0, 2.0];
        let coeffs = project_equirect(512, 256, &map(512, 256, |_| c), 5).unwrap();
        assert_eq!(coeffs.len(), 25);
        for ch in 0..3 {
            let expected = 2.0 * PI.sqrt() * f64::from(c[ch]);
            assert!((coeffs[0][ch] - expected).abs() < 1e-9 * expected);
        }
        for (i, c) in coeffs.iter().enumerate().skip(1) {
            // Centre sampling in θ leaves an O(1/height²) residue in the terms with y² in them.
            assert!(c.iter().all(|v| v.abs() < 1e-4), "coefficient {i}: {c:?}");
        }
    }

    #[test]
    fn linear_map_projects_onto_bands_0_and_1_only() {
        // f(ω) = 5 + a·ω: ∫ (a·ω) K1 ω_k dω = a_k K1 4π/3 = a_k √(4π/3).
        let a = DVec3::new(3.0, 2.0, -1.0);
        let f = |d: DVec3| [(5.0 + a.dot(d)) as f32, (5.0 + 0.5 * a.dot(d)) as f32, 5.0];
        let coeffs = project_equirect(1024, 512, &map(1024, 512, f), 5).unwrap();
        let s = (4.0 * PI / 3.0).sqrt();
        for (ch, scale) in [(0, 1.0), (1, 0.5), (2, 0.0)] {
            assert!((coeffs[0][ch] - 10.0 * PI.sqrt()).abs() < 1e-6);
            let expected = [a.y * s * scale, a.z * s * scale, a.x * s * scale];
            for (i, e) in expected.iter().enumerate() {
                let got = coeffs[1 + i][ch];
                assert!((got - e).abs() < 1e-4 * s, "ch {ch} coefficient {}: {got} vs {e}", 1 + i);
            }
            for (i, c) in coeffs.iter().enumerate().skip(4) {
                assert!(c[ch].abs() < 1e-4, "ch {ch} coefficient {i}: {}", c[ch]);
            }
        }
    }

    #[test]
    fn constant_radiance_one_gives_irradiance_pi() {
        let coeffs = project_equirect(256, 128, &map(256, 128, |_| [1.0; 3]), 3).unwrap();
        let sh = ShRgb9::from_f64(&coeffs).unwrap();
        for d in test_dirs() {
            for e in sh.irradiance(d.as_vec3()) {
                assert!((f64::from(e) - PI).abs() < 1e-4, "{d}: {e}");
            }
        }
    }

    /// Maps of a few texels, each texel projected as sub-texels: before, a 2×1 map gave 1.18 at
    /// +Y and 7.07 at +X. The sub-texels' midpoint rule errs by O((π / 512)²) ≈ 4e-5 relative.
    #[test]
    fn tiny_constant_maps_give_irradiance_pi() {
        for (w, h) in [(2, 1), (4, 2), (16, 8)] {
            let coeffs = project_equirect(w, h, &map(w, h, |_| [1.0; 3]), 3).unwrap();
            let sh = ShRgb9::from_f64(&coeffs).unwrap();
            for d in test_dirs() {
                let e = f64::from(sh.irradiance(d.as_vec3())[0]);
                assert!((e / PI - 1.0).abs() < 1e-3, "{w}x{h} at {d}: {e}");
            }
        }
    }

    #[test]
    fn irradiance_matrix_agrees_with_the_direct_sum() {
        let published = [0.429043, 0.511664, 0.743125, 0.886227, 0.247708];
        // Within 2e-6 rather than half a unit in the sixth place: the paper's values come from
        // already rounded factors, e.g. it prints c3 = 0.743125 where 3·(π/4)·K_2^0 =
        // 0.74312387, and c2 = 0.511664 where (2π/3)·K_1/2 = 0.51166335.
        for (c, p) in irradiance_matrix_constants().iter().zip(published) {
            assert!((c - p).abs() < 2e-6, "{c} vs {p}");
        }
        let sh = ShRgb9 {
            c: std::array::from_fn(|i| {
                let t = i as f32;
                [1.0 - 0.1 * t, (t * 0.7).sin(), 0.3 * (t * 1.3).cos()]
            }),
        };
        let m = sh.irradiance_matrix();
        for d in test_dirs() {
            let n = d.as_vec3();
            let direct = sh.irradiance(n);
            let n4 = n.extend(1.0);
            for ch in 0..3 {
                let quad = n4.dot(m[ch] * n4);
                assert!((quad - direct[ch]).abs() < 1e-5, "{n} ch {ch}: {quad} vs {}", direct[ch]);
            }
        }
    }

    #[test]
    fn bad_projection_input_is_an_error() {
        let px = vec![[1.0f32; 3]; 8];
        assert!(project_equirect(4, 2, &px, 0).is_err());
        assert!(project_equirect(4, 2, &px, 6).is_err());
        assert!(project_equirect(4, 3, &px, 3).is_err());
        assert!(project_equirect(0, 0, &[], 3).is_err());
        let mut nan = px.clone();
        nan[5][1] = f32::NAN;
        let err = project_equirect(4, 2, &nan, 3).unwrap_err().to_string();
        assert!(err.contains("(1, 1)"), "{err}");
        assert!(ShRgb9::from_f64(&project_equirect(4, 2, &px, 2).unwrap()).is_none());
    }
}
