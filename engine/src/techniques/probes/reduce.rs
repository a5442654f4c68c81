//! Automatic placement's second half: from a dense set of captured candidates, greedily drop
//! the probes that the others reproduce by tetrahedral interpolation.
//!
//! The error of a probe against the SH interpolated at its position: the largest difference of
//! irradiance over 14 normals (the axes and the diagonals) and the three channels, relative to
//! the probe's mean irradiance over all normals (so that dark probes are judged by their own
//! light, and the dark side of a bright one does not blow up). A probe with almost no light
//! is judged against 1/1000 of the candidates' mean instead.
//!
//! The greedy pass: every candidate is first scored by its error against the others (one
//! tetrahedralization without it each); then, most redundant first, a candidate is dropped when
//! the set without it reproduces it **and every candidate dropped before it** within the
//! tolerance (one tetrahedralization per try, then a walk per dropped candidate). So when it
//! ends every candidate, kept or not, is within the tolerance of the kept set's interpolation.
//! Re-tetrahedralizing the whole kept set per try costs O(n log n) each, O(n² log n) in all:
//! a second for a few hundred candidates, small beside their capture.
use super::lookup::Walker;
use super::solids::directions;
use super::tetmesh::TetMesh;
use crate::error::Result;
use crate::sh::ShRgb9;
use glam::DVec3;

/// The SH at `p` from `sh` (in the order of `mesh`'s input positions) by `walker`'s tetrahedral
/// weights.
fn interpolate(mesh: &TetMesh, sh: &[&ShRgb9], walker: &mut Walker, p: DVec3) -> Result<ShRgb9> {
    let location = walker.locate(mesh, p)?;
    Ok(blend(location.probes.iter().zip(location.weights).map(|(&i, w)| (sh[i as usize], w))))
}

/// The sum of weighted SH.
pub fn blend<'a>(weighted: impl IntoIterator<Item = (&'a ShRgb9, f64)>) -> ShRgb9 {
    let mut sum = ShRgb9::default();
    for (sh, w) in weighted {
        for (total, c) in sum.c.iter_mut().zip(&sh.c) {
            for (t, v) in total.iter_mut().zip(c) {
                *t += w as f32 * v;
            }
        }
    }
    sum
}

/// A probe's mean irradiance over all normals, per channel: Â₀ Y₀₀ c₀ = π · (1 / 2√π) · c₀.
fn mean_irradiance(sh: &ShRgb9) -> f32 {
    let c0 = sh.c[0].iter().copied().fold(0.0, f32::max);
    0.5 * std::f32::consts::PI.sqrt() * c0
}

/// The relative error of `approx` against `exact` (see the module documentation); `floor`
/// bounds the divisor from below.
pub fn sh_error(approx: &ShRgb9, exact: &ShRgb9, floor: f32) -> f32 {
    let scale = mean_irradiance(exact).max(floor);
    directions()
        .iter()
        .map(|&n| {
            let (a, e) = (approx.irradiance(n), exact.irradiance(n));
            (0..3).map(|k| (a[k] - e[k]).abs()).fold(0.0, f32::max)
        })
        .fold(0.0, f32::max)
        / scale
}

/// The candidates to keep (indices into `positions`, ascending) so that the tetrahedral
/// interpolation of the kept ones' SH reproduces every candidate's within `tolerance` (see the
/// module documentation). At least four non-coplanar candidates are always kept.
pub fn reduce(positions: &[DVec3], sh: &[ShRgb9], tolerance: f32) -> Result<Vec<usize>> {
    let n = positions.len();
    let floor = 1e-3 * sh.iter().map(mean_irradiance).sum::<f32>() / n.max(1) as f32;
    // The error of candidate `i` against the interpolation of `kept` (a mask), or `None` when
    // those cannot be tetrahedralized (too few, or flat).
    let build = |kept: &[bool]| -> Option<(TetMesh, Vec<usize>)> {
        let index: Vec<usize> = (0..n).filter(|&j| kept[j]).collect();
        let points: Vec<DVec3> = index.iter().map(|&j| positions[j]).collect();
        TetMesh::build(&points).ok().map(|mesh| (mesh, index))
    };
    let errors = |mesh: &TetMesh, index: &[usize], probes: &[usize]| -> Result<f32> {
        let kept_sh: Vec<&ShRgb9> = index.iter().map(|&j| &sh[j]).collect();
        let mut walker = Walker::default();
        let mut worst = 0.0f32;
        for &i in probes {
            let approx = interpolate(mesh, &kept_sh, &mut walker, positions[i])?;
            worst = worst.max(sh_error(&approx, &sh[i], floor));
        }
        Ok(worst)
    };

    let mut kept = vec![true; n];
    let mut score = Vec::with_capacity(n);
    for i in 0..n {
        kept[i] = false;
        if let Some((mesh, index)) = build(&kept) {
            score.push((errors(&mesh, &index, &[i])?, i));
        }
        kept[i] = true;
    }
    score.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));

    let mut dropped = Vec::new();
    for (first_error, i) in score {
        // Dropping more probes can make a candidate's error smaller as well as larger, but
        // one over the tolerance against all the others is rarely saved: skip it.
        if first_error > tolerance {
            break;
        }
        kept[i] = false;
        dropped.push(i);
        let within = match build(&kept) {
            Some((mesh, index)) => errors(&mesh, &index, &dropped)? <= tolerance,
            None => false,
        };
        if !within {
            kept[i] = true;
            dropped.pop();
        }
    }
    Ok((0..n).filter(|&j| kept[j]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// SH whose coefficients are linear in position: tetrahedral interpolation reproduces them
    /// exactly, so all but a tetrahedron's worth of probes go.
    fn linear(p: DVec3) -> ShRgb9 {
        let mut sh = ShRgb9::default();
        sh.c[0] = [2.0 + p.x as f32, 2.0, 2.0 + 0.5 * p.z as f32];
        sh.c[1] = [0.3 * p.y as f32; 3];
        sh
    }

    fn grid(n: u32) -> Vec<DVec3> {
        let lattice = super::super::Lattice::cell_centres(Vec3::ZERO, Vec3::ONE, [n; 3]);
        lattice.positions()
    }

    #[test]
    fn a_linear_field_needs_only_the_hull_corners() {
        let positions = grid(4);
        let sh: Vec<ShRgb9> = positions.iter().map(|&p| linear(p)).collect();
        let kept = reduce(&positions, &sh, 1e-4).unwrap();
        // Outside the kept hull the extrapolation is of the nearest hull point, not linear; so
        // the cube's 8 corners stay, and no more are needed.
        assert_eq!(kept.len(), 8, "{kept:?}");
    }

    #[test]
    fn a_bump_keeps_probes_around_it_and_every_candidate_stays_within_the_tolerance() {
        let positions = grid(5);
        let bump = |p: DVec3| {
            let mut sh = linear(p);
            sh.c[0][1] += 3.0 * (-((p - DVec3::splat(0.5)).length_squared()) / 0.02).exp() as f32;
            sh
        };
        let sh: Vec<ShRgb9> = positions.iter().map(|&p| bump(p)).collect();
        let tolerance = 0.05;
        let kept = reduce(&positions, &sh, tolerance).unwrap();
        assert!(kept.len() > 8 && kept.len() < positions.len(), "{} kept", kept.len());
        // The centre of the bump is kept.
        let centre = positions.iter().position(|p| (*p - DVec3::splat(0.5)).length() < 1e-9).unwrap();
        assert!(kept.contains(&centre));
        let points: Vec<DVec3> = kept.iter().map(|&i| positions[i]).collect();
        let mesh = TetMesh::build(&points).unwrap();
        let kept_sh: Vec<&ShRgb9> = kept.iter().map(|&i| &sh[i]).collect();
        let floor = 1e-3 * sh.iter().map(mean_irradiance).sum::<f32>() / sh.len() as f32;
        let mut walker = Walker::default();
        for (p, exact) in positions.iter().zip(&sh) {
            let approx = interpolate(&mesh, &kept_sh, &mut walker, *p).unwrap();
            assert!(sh_error(&approx, exact, floor) <= tolerance, "{p}");
        }
    }
}
