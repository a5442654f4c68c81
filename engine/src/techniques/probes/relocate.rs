//! Automatic placement's third step: a local search that moves each kept probe to a nearby
//! candidate while that lowers the error with which the fitted set reproduces every candidate.
//!
//! The reduction ([`super::reduce`]) decides how many probes the tolerance needs, but it leaves
//! them where greedy removal stopped: it judges each removal by the captured values and by the
//! worst candidate it changes. What the engine interpolates is the set after the fit
//! ([`super::fit`]), so this step scores that: the objective is the squared irradiance error,
//! over every candidate, the 14 normals of the reduction and the three channels, of the fitted
//! set's interpolation (clamped at 0, as the renderer does) against the candidate's capture.
//! Absolute, not relative: the error `kage bench probe-count` reports is an RMS over points
//! divided by the truth's RMS, which weighs each place by its light.
//!
//! In sweeps, each kept probe in turn tries the [`NEIGHBOURS`] candidates nearest it that are
//! not kept, and moves to the one that lowers the objective most, if any does. Sweeps repeat
//! until one moves nothing, at most [`MAX_SWEEPS`]: a probe walks one neighbour per sweep; on
//! the benchmark's sets the objective falls 2–3× in four sweeps and by a few per cent in each
//! after; the test points' error after four sweeps differed from that after up to twenty by
//! at most 0.08, either way, and on 21 of 32 sets by under 0.003.
//! The count is the reduction's; the objective never rises. With occluders
//! ([`super::ProbeVisibility::Rays`]) the objective's interpolation and fit leave out the probes
//! a candidate does not see, as the lookups will.
//!
//! Each try tetrahedralizes the kept probes and fits their SH anew: a few milliseconds for
//! hundreds of probes over a thousand candidates, so a sweep costs `NEIGHBOURS` × kept of them,
//! and the whole search grows with the square of the kept probes. Sets of more than
//! [`MAX_RELOCATED`] stay where the reduction left them: the search took minutes for 300 probes
//! over 2560 candidates, and from 84 probes on its effect on the benchmark's errors ranged from
//! 26 % lower to 16 % higher, where up to 69 probes it lowered them by 7–49 % (BENCHMARKS.md).
use super::reduce::blend;
use super::set::ProbeSet;
use super::solids::directions;
use super::visibility::Occluders;
use crate::error::ProbeError;
use crate::error::{Error, Result};
use crate::sh::ShRgb9;
use glam::DVec3;
use std::sync::Arc;

/// Candidates each probe tries per sweep: on a lattice, the six across its faces.
pub const NEIGHBOURS: usize = 6;
/// Most sweeps over the kept probes.
pub const MAX_SWEEPS: usize = 4;
/// Most kept probes that are relocated.
pub const MAX_RELOCATED: usize = 256;

/// `kept` (indices into `positions`, whose captures are `sh`) with each probe moved while that
/// lowers `objective` (unmoved when there are more than `MAX_RELOCATED`); ascending, the
/// same count. `occluders`: those the set's lookups will test visibility against.
pub fn relocate(
    positions: &[DVec3],
    sh: &[ShRgb9],
    mut kept: Vec<usize>,
    occluders: Option<&Arc<Occluders>>,
) -> Result<Vec<usize>> {
    if kept.len() > MAX_RELOCATED {
        kept.sort_unstable();
        return Ok(kept);
    }
    let mut is_kept = vec![false; positions.len()];
    let distinct = kept.iter().all(|&j| j < positions.len() && !std::mem::replace(&mut is_kept[j], true));
    if !distinct || sh.len() != positions.len() {
        return Err(Error::InvalidArgument(format!(
            "probe relocation: the {} kept probes must be distinct indices into the {} candidates, which need one SH each ({} given)",
            kept.len(),
            positions.len(),
            sh.len()
        )));
    }
    let mut best = objective(positions, sh, &kept, occluders)?;
    for _ in 0..MAX_SWEEPS {
        let mut moved = false;
        for slot in 0..kept.len() {
            let mut choice = None;
            for candidate in nearest_free(positions, &is_kept, positions[kept[slot]]) {
                let mut trial = kept.clone();
                trial[slot] = candidate;
                // A move that leaves the probes in one plane is no placement, and one whose fit
                // does not converge is no better than where the probe is.
                let error = match objective(positions, sh, &trial, occluders) {
                    Err(Error::Probes(
                        ProbeError::Flat { .. } | ProbeError::TooFew { .. } | ProbeError::FitDiverged { .. },
                    )) => continue,
                    error => error?,
                };
                if error < best {
                    (best, choice) = (error, Some(candidate));
                }
            }
            if let Some(candidate) = choice {
                is_kept[kept[slot]] = false;
                is_kept[candidate] = true;
                kept[slot] = candidate;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    kept.sort_unstable();
    Ok(kept)
}

/// The [`NEIGHBOURS`] candidates nearest `p` that are not kept, nearest first (ties by index).
fn nearest_free(positions: &[DVec3], is_kept: &[bool], p: DVec3) -> Vec<usize> {
    let mut free: Vec<(f64, usize)> = (0..positions.len())
        .filter(|&j| !is_kept[j])
        .map(|j| ((positions[j] - p).length_squared(), j))
        .collect();
    let cmp = |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    if free.len() > NEIGHBOURS {
        free.select_nth_unstable_by(NEIGHBOURS, cmp);
        free.truncate(NEIGHBOURS);
    }
    free.sort_by(cmp);
    free.into_iter().map(|(_, j)| j).collect()
}

/// The squared irradiance error over every candidate of the probes `kept` fitted to `sh` (see
/// the module documentation). The fit's weights at the candidates serve the error too.
fn objective(
    positions: &[DVec3],
    sh: &[ShRgb9],
    kept: &[usize],
    occluders: Option<&Arc<Occluders>>,
) -> Result<f64> {
    let points: Vec<DVec3> = kept.iter().map(|&j| positions[j]).collect();
    let set =
        ProbeSet::tetrahedral(&points, kept.iter().map(|&j| sh[j]).collect())?.seeing(occluders.cloned());
    let rows = set.rows(positions)?;
    let set = set.fitted_by(&rows, sh)?;
    let normals = directions();
    let mut sum = 0.0;
    for (row, exact) in rows.iter().zip(sh) {
        let approx = blend(row.iter().map(|&(i, w)| (&set.sh[i], w)));
        for &n in &normals {
            let (a, e) = (approx.irradiance(n), exact.irradiance(n));
            sum += (0..3).map(|k| f64::from(a[k].max(0.0) - e[k]).powi(2)).sum::<f64>();
        }
    }
    Ok(sum)
}

#[cfg(test)]
mod tests {
    use super::super::{reduce, Lattice};
    use super::*;
    use glam::Vec3;

    /// A field with a bright bump off the centre, over a 6³ lattice of candidates.
    fn bump_field() -> (Vec<DVec3>, Vec<ShRgb9>) {
        let positions = Lattice::cell_centres(Vec3::ZERO, Vec3::ONE, [6; 3]).positions();
        let sh = positions
            .iter()
            .map(|&p| {
                let bump = (4.0 * (-(p - DVec3::new(0.3, 0.6, 0.45)).length_squared() / 0.04).exp()) as f32;
                let mut sh = ShRgb9::default();
                sh.c[0] = [1.0 + 0.5 * p.x as f32 + bump, 1.0 + bump, 1.0];
                sh.c[2] = [0.5 * bump; 3];
                sh
            })
            .collect();
        (positions, sh)
    }

    #[test]
    fn a_probe_away_from_the_light_it_should_hold_walks_to_it() {
        let (positions, sh) = bump_field();
        // The lattice's eight corners and one probe in the far corner, away from the bump.
        let corner = |c: DVec3| positions.iter().position(|p| (*p - c).length() < 1e-5).unwrap();
        let (lo, hi) = (1.0 / 12.0, 11.0 / 12.0);
        let mut kept: Vec<usize> = (0..8)
            .map(|k| corner(DVec3::new([lo, hi][k & 1], [lo, hi][(k >> 1) & 1], [lo, hi][(k >> 2) & 1])))
            .collect();
        let stray = corner(DVec3::new(9.0 / 12.0, 3.0 / 12.0, 9.0 / 12.0));
        kept.push(stray);
        let before = objective(&positions, &sh, &kept, None).unwrap();
        let moved = relocate(&positions, &sh, kept.clone(), None).unwrap();
        let after = objective(&positions, &sh, &moved, None).unwrap();
        assert_eq!(moved.len(), kept.len());
        assert!(after < 0.8 * before, "objective {before} → {after}");
        // The stray probe went towards the bump (one lattice step per sweep at most).
        let bump = DVec3::new(0.3, 0.6, 0.45);
        let new: Vec<&usize> = moved.iter().filter(|j| !kept.contains(j)).collect();
        assert!(!new.is_empty());
        let nearest = new.iter().map(|&&j| (positions[j] - bump).length()).fold(f64::MAX, f64::min);
        assert!(nearest < (positions[stray] - bump).length(), "{nearest}");
    }

    #[test]
    fn relocation_keeps_the_count_and_never_raises_the_objective() {
        let (positions, sh) = bump_field();
        for tolerance in [0.6, 0.3, 0.1] {
            let kept = reduce(&positions, &sh, tolerance).unwrap();
            let before = objective(&positions, &sh, &kept, None).unwrap();
            let moved = relocate(&positions, &sh, kept.clone(), None).unwrap();
            let after = objective(&positions, &sh, &moved, None).unwrap();
            assert_eq!(moved.len(), kept.len());
            assert!(moved.windows(2).all(|w| w[0] < w[1]), "sorted, distinct: {moved:?}");
            assert!(after <= before, "tolerance {tolerance}: {before} → {after}");
        }
    }

    #[test]
    fn a_set_above_the_bound_stays_where_it_is() {
        let positions = Lattice::cell_centres(Vec3::ZERO, Vec3::ONE, [8; 3]).positions();
        let sh = vec![ShRgb9::default(); positions.len()];
        let kept: Vec<usize> = (0..=MAX_RELOCATED).rev().map(|j| 2 * j).collect();
        let mut sorted = kept.clone();
        sorted.sort_unstable();
        assert_eq!(relocate(&positions, &sh, kept, None).unwrap(), sorted);
    }

    #[test]
    fn bad_indices_are_an_error() {
        let (positions, sh) = bump_field();
        for kept in [vec![0, 1, 2, positions.len()], vec![0, 1, 2, 2, 3]] {
            let error = relocate(&positions, &sh, kept, None).unwrap_err().to_string();
            assert!(error.contains("distinct indices"), "{error}");
        }
        assert!(relocate(&positions, &sh[1..], vec![0, 1, 2, 3], None).is_err());
    }

    #[test]
    fn flat_candidates_are_an_error() {
        let positions: Vec<DVec3> = (0..6).map(|i| DVec3::new(i as f64, (i % 2) as f64, 0.0)).collect();
        let sh = vec![ShRgb9::default(); positions.len()];
        assert!(relocate(&positions, &sh, vec![0, 1, 2, 3], None).is_err());
    }
}
