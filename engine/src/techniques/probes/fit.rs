//! Automatic placement's last step: the kept probes' SH fitted by least squares to every
//! candidate's capture, instead of each probe keeping its own.
//!
//! A probe's own capture samples the light at one point, shadow edges and all; interpolated
//! over a tetrahedron many candidates wide, that sample stands for the whole neighbourhood. The
//! fitted values minimise, per SH coefficient,
//! `Σ_candidates (Σ_i w_i(c) x_i − s_c)² + λ Σ_kept (x_i − s_i)²`, w the interpolation weights at
//! candidate c: the interpolation that best reproduces every capture taken, the small λ term
//! holding a probe that few candidates constrain to its own capture (and making the system
//! definite). At λ's optimum the candidates' squared residual is never above that of the
//! captured values, which score the same objective with its second sum 0 (tested).
//! Irradiance is linear in the coefficients and each coefficient's problem is separate, so the
//! same values minimise the squared irradiance error over every normal.
//!
//! Solved by conjugate gradients on the normal equations, matrix-free (each candidate's row has
//! the 4 or 8 weights of its cell), with a Jacobi preconditioner: memory linear in the
//! candidates, where a dense solve would take the square of the kept probes.
use crate::error::ProbeError;
use crate::error::{Error, Result};
use crate::sh::ShRgb9;

/// The weight of a probe's own capture against one candidate's (a candidate at the probe has
/// weight 1 on it).
pub const OWN_WEIGHT: f64 = 0.1;

/// The 27 coefficients of an SH as one vector.
type Coefficients = [f64; 27];

fn flat(sh: &ShRgb9) -> Coefficients {
    std::array::from_fn(|i| f64::from(sh.c[i / 3][i % 3]))
}

fn unflat(x: &Coefficients) -> ShRgb9 {
    let mut sh = ShRgb9::default();
    for (i, v) in x.iter().enumerate() {
        sh.c[i / 3][i % 3] = *v as f32;
    }
    sh
}

/// The values of the probes whose own captures are `own` that best reproduce `captured`, the
/// capture at each candidate, where `rows[c]` holds the interpolation weights (probe index,
/// weight) at candidate c (see the module documentation).
pub fn fit(rows: &[Vec<(usize, f64)>], captured: &[ShRgb9], own: &[ShRgb9]) -> Result<Vec<ShRgb9>> {
    let k = own.len();
    if rows.len() != captured.len() || rows.iter().flatten().any(|&(i, _)| i >= k) {
        return Err(Error::InvalidArgument(format!(
            "probe fit: {} weight rows for {} captures over {k} probes",
            rows.len(),
            captured.len()
        )));
    }
    // Normal equations A x = b, A = Wᵀ W + λ I, b = Wᵀ s + λ s_own.
    let apply = |x: &[Coefficients]| -> Vec<Coefficients> {
        let mut y: Vec<Coefficients> = x.iter().map(|v| v.map(|e| OWN_WEIGHT * e)).collect();
        for row in rows {
            let mut wx = [0.0; 27];
            for &(i, w) in row {
                wx.iter_mut().zip(&x[i]).for_each(|(s, e)| *s += w * e);
            }
            for &(i, w) in row {
                y[i].iter_mut().zip(&wx).for_each(|(s, e)| *s += w * e);
            }
        }
        y
    };
    let own: Vec<Coefficients> = own.iter().map(flat).collect();
    let mut b: Vec<Coefficients> = own.iter().map(|v| v.map(|e| OWN_WEIGHT * e)).collect();
    let mut diagonal = vec![OWN_WEIGHT; k];
    for (row, s) in rows.iter().zip(captured) {
        let s = flat(s);
        for &(i, w) in row {
            b[i].iter_mut().zip(&s).for_each(|(t, e)| *t += w * e);
            diagonal[i] += w * w;
        }
    }

    // 27 preconditioned conjugate-gradient solves in lockstep, from the captured values.
    let mut x = own;
    let ax = apply(&x);
    let mut r: Vec<Coefficients> =
        b.iter().zip(&ax).map(|(b, a)| std::array::from_fn(|q| b[q] - a[q])).collect();
    let precondition = |r: &[Coefficients]| -> Vec<Coefficients> {
        r.iter().zip(&diagonal).map(|(v, d)| v.map(|e| e / d)).collect()
    };
    let dot = |a: &[Coefficients], b: &[Coefficients]| -> Coefficients {
        let mut s = [0.0; 27];
        for (u, v) in a.iter().zip(b) {
            s.iter_mut().zip(u.iter().zip(v)).for_each(|(s, (u, v))| *s += u * v);
        }
        s
    };
    let norm_b = dot(&b, &b);
    let mut z = precondition(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    // The condition number is at most (λ + the most candidates a probe weighs) / λ; on the
    // sets of `kage bench probe-count` (up to 320 probes over 1152 candidates) the residual
    // falls to 1e-9 of |b| in at most 34 iterations.
    for _ in 0..10 * k.max(100) {
        let rr = dot(&r, &r);
        if rr.iter().zip(&norm_b).all(|(rr, bb)| *rr <= 1e-18 * bb.max(f64::MIN_POSITIVE)) {
            return Ok(x.iter().map(unflat).collect());
        }
        let ap = apply(&p);
        let pap = dot(&p, &ap);
        let alpha: Coefficients = std::array::from_fn(|q| if pap[q] > 0.0 { rz[q] / pap[q] } else { 0.0 });
        for i in 0..k {
            for q in 0..27 {
                x[i][q] += alpha[q] * p[i][q];
                r[i][q] -= alpha[q] * ap[i][q];
            }
        }
        z = precondition(&r);
        let rz_next = dot(&r, &z);
        for i in 0..k {
            for q in 0..27 {
                let beta = if rz[q] > 0.0 { rz_next[q] / rz[q] } else { 0.0 };
                p[i][q] = z[i][q] + beta * p[i][q];
            }
        }
        rz = rz_next;
    }
    Err(ProbeError::FitDiverged { probes: k }.into())
}

#[cfg(test)]
mod tests {
    use super::super::reduce::{blend, reduce};
    use super::super::{Lattice, ProbeSet, Walker};
    use super::*;
    use glam::{DVec3, Vec3};

    fn sh_of(value: f32) -> ShRgb9 {
        let mut sh = ShRgb9::default();
        sh.c[0] = [value, 2.0 * value, 0.5];
        sh.c[4] = [-value; 3];
        sh
    }

    /// The squared distance of two SH's coefficients.
    fn distance2(a: &ShRgb9, b: &ShRgb9) -> f64 {
        flat(a).iter().zip(flat(b)).map(|(a, b)| (a - b) * (a - b)).sum()
    }

    fn assert_close(a: &[ShRgb9], b: &[ShRgb9], tolerance: f32) {
        for (f, o) in a.iter().zip(b) {
            for (a, b) in f.c.iter().flatten().zip(o.c.iter().flatten()) {
                assert!((a - b).abs() < tolerance, "{a} against {b}");
            }
        }
    }

    /// The squared coefficient residual of the values `x` interpolated by `rows` against `captured`.
    fn squared_residual(rows: &[Vec<(usize, f64)>], captured: &[ShRgb9], x: &[ShRgb9]) -> f64 {
        rows.iter()
            .zip(captured)
            .map(|(row, s)| distance2(&blend(row.iter().map(|&(i, w)| (&x[i], w))), s))
            .sum()
    }

    /// The squared coefficient residual of `set`'s interpolation at each of `positions`.
    fn set_residual(set: &ProbeSet, positions: &[DVec3], sh: &[ShRgb9]) -> f64 {
        let mut walker = Walker::default();
        positions
            .iter()
            .zip(sh)
            .map(|(p, s)| distance2(&set.interpolate(&mut walker, p.as_vec3()).unwrap(), s))
            .sum()
    }

    /// Two probes at the ends of a segment, candidates along it: linear interpolation.
    fn segment(values: &[f32]) -> (Vec<Vec<(usize, f64)>>, Vec<ShRgb9>) {
        let n = values.len() - 1;
        let rows = (0..=n).map(|c| vec![(0, 1.0 - c as f64 / n as f64), (1, c as f64 / n as f64)]).collect();
        (rows, values.iter().map(|&v| sh_of(v)).collect())
    }

    #[test]
    fn a_field_the_interpolation_reproduces_keeps_its_captured_values() {
        let (rows, captured) = segment(&[1.0, 1.5, 2.0, 2.5, 3.0]);
        let own = [captured[0], captured[4]];
        let fitted = fit(&rows, &captured, &own).unwrap();
        assert_close(&fitted, &own, 1e-5);
    }

    #[test]
    fn the_fit_never_reproduces_the_candidates_worse_than_the_captured_values() {
        // A spike at one end: the captured end values are far from the candidates' trend.
        let (rows, captured) = segment(&[4.0, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6]);
        let own = [captured[0], captured[7]];
        let fitted = fit(&rows, &captured, &own).unwrap();
        let (before, after) =
            (squared_residual(&rows, &captured, &own), squared_residual(&rows, &captured, &fitted));
        assert!(after < 0.5 * before, "fitted residual {after} against captured {before}");
        // The exact optimum of the 2 × 2 normal equations, per coefficient, for c₀'s red.
        let n = 7.0;
        let (mut a, mut b) = ([[OWN_WEIGHT, 0.0], [0.0, OWN_WEIGHT]], [OWN_WEIGHT * 4.0, OWN_WEIGHT * 1.6]);
        for (c, s) in [4.0, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6].iter().enumerate() {
            let w = [1.0 - c as f64 / n, c as f64 / n];
            for i in 0..2 {
                b[i] += w[i] * s;
                for j in 0..2 {
                    a[i][j] += w[i] * w[j];
                }
            }
        }
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let exact = [(b[0] * a[1][1] - b[1] * a[0][1]) / det, (a[0][0] * b[1] - a[1][0] * b[0]) / det];
        for (f, e) in fitted.iter().zip(exact) {
            assert!((f64::from(f.c[0][0]) - e).abs() < 1e-5, "{} against {e}", f.c[0][0]);
        }
    }

    #[test]
    fn automatic_placement_fitted_reproduces_the_candidates_better_than_its_captures() {
        let positions = Lattice::cell_centres(Vec3::ZERO, Vec3::ONE, [6; 3]).positions();
        let field = |p: DVec3| {
            let bump = (3.0 * (-(p - DVec3::new(0.3, 0.6, 0.5)).length_squared() / 0.05).exp()) as f32;
            let mut sh = ShRgb9::default();
            sh.c[0] = [1.0 + p.x as f32 + bump, 1.0, 1.0];
            sh.c[2] = [0.5 * bump; 3];
            sh
        };
        let sh: Vec<ShRgb9> = positions.iter().map(|&p| field(p)).collect();
        let captured = ProbeSet::kept(&positions, &sh, &reduce(&positions, &sh, 0.3).unwrap()).unwrap();
        let kept = captured.probe_count();
        assert!(kept < positions.len(), "{kept} kept");
        let before = set_residual(&captured, &positions, &sh);
        let fitted = captured.fitted(&positions, &sh).unwrap();
        let after = set_residual(&fitted, &positions, &sh);
        assert_eq!(fitted.probe_count(), kept);
        assert!(after < 0.8 * before, "fitted residual {after} against captured {before}");
    }

    #[test]
    fn a_grid_fitted_to_a_linear_field_inside_it_keeps_its_captures() {
        let lattice = Lattice::cell_centres(Vec3::ZERO, Vec3::ONE, [4; 3]);
        let linear = |p: DVec3| sh_of((1.0 + 2.0 * p.x - p.y + 0.5 * p.z) as f32);
        let own: Vec<ShRgb9> = lattice.positions().iter().map(|&p| linear(p)).collect();
        // Candidates within the lattice's cell centres, where trilinear weights reproduce a
        // linear field: the captures already fit exactly.
        let inside = Lattice::cell_centres(Vec3::splat(0.125), Vec3::splat(0.875), [5; 3]).positions();
        let captured: Vec<ShRgb9> = inside.iter().map(|&p| linear(p)).collect();
        let fitted = ProbeSet::trilinear(lattice, own.clone()).unwrap().fitted(&inside, &captured).unwrap();
        assert_close(&fitted.sh, &own, 1e-4);
    }

    #[test]
    fn mismatched_rows_are_an_error() {
        let (rows, captured) = segment(&[1.0, 2.0]);
        assert!(fit(&rows, &captured[..1], &captured).is_err());
        assert!(fit(&rows, &captured, &captured[..1]).is_err());
    }
}
