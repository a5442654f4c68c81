//! Automatic placement's second half: from a dense set of captured candidates, greedily drop
//! the probes that the others reproduce by tetrahedral interpolation.
//!
//! The error of a probe against the SH interpolated at its position: the RMS difference of
//! irradiance over 14 normals (the axes and the diagonals) and the three channels, relative to
//! the larger of the probe's own mean irradiance (over all normals) and the candidates' mean.
//! RMS, as the error the placement is measured by (`kage bench probe-count`): the largest
//! difference instead is set by the one normal facing a patch of sun, and kept 15–60 % more
//! probes for the same error on the moving object's path (BENCHMARKS.md).
//! Relative to its own light alone, a probe in the shade beside a patch of sun would be "wrong"
//! by many times its light, and every probe along every shadow's edge would stay; relative to
//! the scene's mean alone, probes that see the sun would be held to a fraction of their light.
//!
//! The greedy passes, in rounds: the kept set is tetrahedralized; every kept probe is scored by
//! its error against the set without it; then, most redundant first, a probe is dropped when the
//! set without it reproduces it **and every candidate dropped before whose tetrahedron has it as
//! a vertex** (the only ones whose interpolation its removal changes) within the tolerance.
//! Rounds repeat until one drops nothing. So when it ends every candidate, kept or not, is within
//! the tolerance of the kept set's interpolation.
//!
//! The set without a probe is not re-tetrahedralized whole (O(n log n) per try, hours for a
//! thousand lattice candidates): removing a probe changes only its star, whose cavity the
//! Delaunay tetrahedra of its neighbours alone fill (see `reduce`), so each try tetrahedralizes
//! its 10–30 neighbours. Within a round, a probe whose neighbour was dropped waits for the next
//! round, when its star is current again. Two approximations remain, both small: ties between
//! cospherical probes (every lattice) may be broken differently in the small tetrahedralization
//! than in the whole; and on the hull the extrapolation is from the neighbours' hull, not the
//! whole set's.
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

/// A probe's mean irradiance over all normals and channels: Â₀ Y₀₀ c₀ = π · (1 / 2√π) · c₀.
fn mean_irradiance(sh: &ShRgb9) -> f32 {
    0.5 * std::f32::consts::PI.sqrt() * sh.c[0].iter().sum::<f32>() / 3.0
}

/// The candidates' mean irradiance; the smallest positive number for a set in the dark, where
/// every error is 0.
fn mean_scale(sh: &[ShRgb9]) -> f32 {
    (sh.iter().map(mean_irradiance).sum::<f32>() / sh.len().max(1) as f32).max(f32::MIN_POSITIVE)
}

/// The error of `approx` against `exact` relative to the larger of `exact`'s mean irradiance
/// and `scale` (see the module documentation).
fn sh_error(approx: &ShRgb9, exact: &ShRgb9, scale: f32) -> f32 {
    let scale = mean_irradiance(exact).max(scale);
    let normals = directions();
    let squares: f32 = normals
        .iter()
        .map(|&n| {
            let (a, e) = (approx.irradiance(n), exact.irradiance(n));
            (0..3).map(|k| (a[k] - e[k]).powi(2)).sum::<f32>()
        })
        .sum();
    (squares / (3 * normals.len()) as f32).sqrt() / scale
}

/// The candidates to keep (indices into `positions`, ascending) so that the tetrahedral
/// interpolation of the kept ones' SH reproduces every candidate's within `tolerance` (see the
/// module documentation). At least four non-coplanar candidates are always kept.
pub fn reduce(positions: &[DVec3], sh: &[ShRgb9], tolerance: f32) -> Result<Vec<usize>> {
    let n = positions.len();
    let scale = mean_scale(sh);
    let mut kept = vec![true; n];
    let mut dropped: Vec<usize> = Vec::new();
    loop {
        let index: Vec<usize> = (0..n).filter(|&j| kept[j]).collect();
        let points: Vec<DVec3> = index.iter().map(|&j| positions[j]).collect();
        let Ok(mesh) = TetMesh::build(&points) else { break };
        // Each kept probe's neighbours (the other vertices of its tetrahedra), and the dropped
        // candidates whose tetrahedron it is a vertex of: removing it changes exactly those
        // tetrahedra, so it changes the interpolation at exactly those candidates.
        let mut link: Vec<Vec<u32>> = vec![Vec::new(); index.len()];
        for tet in mesh.tets() {
            for &a in tet {
                link[a as usize].extend(tet.iter().filter(|&&b| b != a));
            }
        }
        for l in &mut link {
            l.sort_unstable();
            l.dedup();
        }
        let mut affected: Vec<Vec<usize>> = vec![Vec::new(); index.len()];
        let mut walker = Walker::default();
        for &j in &dropped {
            for a in walker.locate(&mesh, positions[j])?.probes {
                affected[a as usize].push(j);
            }
        }
        // The interpolation at `probes` from the set without kept probe `k`: the Delaunay
        // tetrahedra of its neighbours alone, which include those that fill its star's cavity
        // in the tetrahedralization without it (their circumspheres are empty of every probe).
        // `None` when the neighbours are flat.
        let error_without = |k: usize, probes: &[usize]| -> Result<Option<f32>> {
            let around: Vec<usize> = link[k].iter().map(|&a| index[a as usize]).collect();
            let Ok(local) = TetMesh::build(&around.iter().map(|&a| positions[a]).collect::<Vec<_>>()) else {
                return Ok(None);
            };
            let local_sh: Vec<&ShRgb9> = around.iter().map(|&a| &sh[a]).collect();
            let mut walker = Walker::default();
            let mut worst = 0.0f32;
            for &j in probes {
                let approx = interpolate(&local, &local_sh, &mut walker, positions[j])?;
                worst = worst.max(sh_error(&approx, &sh[j], scale));
            }
            Ok(Some(worst))
        };
        let mut score = Vec::new();
        for (k, &probe) in index.iter().enumerate() {
            if let Some(e) = error_without(k, &[probe])? {
                if e <= tolerance {
                    score.push((e, k));
                }
            }
        }
        score.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // Most redundant first, those whose stars do not touch a star changed in this round:
        // for them this round's tetrahedralization is still the current one.
        let mut touched = vec![false; index.len()];
        let mut left = index.len();
        let mut removed = false;
        for (_, k) in score {
            if touched[k] || left <= 4 {
                continue;
            }
            let mut check = affected[k].clone();
            check.push(index[k]);
            if error_without(k, &check)?.is_some_and(|e| e <= tolerance) {
                kept[index[k]] = false;
                dropped.push(index[k]);
                touched[k] = true;
                for &a in &link[k] {
                    touched[a as usize] = true;
                }
                left -= 1;
                removed = true;
            }
        }
        if !removed {
            break;
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
        let scale = mean_scale(&sh);
        let mut walker = Walker::default();
        for (p, exact) in positions.iter().zip(&sh) {
            let approx = interpolate(&mesh, &kept_sh, &mut walker, *p).unwrap();
            assert!(sh_error(&approx, exact, scale) <= tolerance, "{p}");
        }
    }
}
