//! How `kage bench probe-count` scores a probe set at its test points: the relative RMS error
//! against the truth, with and without the visibility test ([`ProbeVisibility`]), the cost of
//! each lookup, and, with `--closed-room`, the leak itself:
//!
//! - the **closed room**: the same probes less those the path's centre cannot see, their SH as
//!   they are, interpolated without visibility. In a convex room (the dim room of `two-rooms`)
//!   these are exactly the room's own probes: what the set gives when no wall can be crossed.
//!   A trilinear grid's closed room is the sub-grid of those probes (when they form one).
//! - the **leaked fraction**: at the test points, the share of the interpolated irradiance
//!   Σ_i w_i max(E_i(n), 0) (summed over the channels) that comes from probes the path's centre
//!   cannot see.
//!
//! With `--path-frames`, also the **largest jump** ([`Frames`]): along the moving group's
//! centre at consecutive frames, the largest change of irradiance from one frame to the next
//! (over the 6 axis normals and the channels), relative to the RMS of the truth there.
use anyhow::Result;
use glam::{DVec3, Vec3};
use kage::reference::irradiance::Point;
use kage::techniques::probes::{
    Lattice, LookupCounts, Occluders, ProbeSet, ProbeVisibility, Visibility, Walker,
};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A set's score at the test points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Score {
    pub error: f64,
    /// The leaked fraction, when the closed room is measured.
    pub leaked: Option<f64>,
    /// The largest frame-to-frame jump, when frames are measured.
    pub jump: Option<f64>,
}

/// The moving group's centre at consecutive frames of its motion, each with the [`NORMALS`],
/// and the truth there.
pub struct Frames<'a> {
    pub points: &'a [Point],
    pub truth: &'a [[f64; 3]],
}

/// The normals at each frame's point: the axes.
pub const NORMALS: [Vec3; 6] = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];

impl Frames<'_> {
    /// The RMS of the truth over the frames: what jumps are relative to.
    pub fn rms(&self) -> f64 {
        rms(self.truth)
    }

    /// The largest jump of `values` (one per point, frame after frame) relative to [`Frames::rms`].
    pub fn largest_jump(&self, values: &[[f64; 3]]) -> f64 {
        let n = NORMALS.len();
        let jump = (n..values.len())
            .flat_map(|i| (0..3).map(move |k| (values[i][k] - values[i - n][k]).abs()))
            .fold(0.0, f64::max);
        jump / self.rms()
    }
}

fn rms(values: &[[f64; 3]]) -> f64 {
    (values.iter().flatten().map(|&e| e * e).sum::<f64>() / (3 * values.len().max(1)) as f64).sqrt()
}

/// Lookups of one visibility mode: their count by outcome and their time.
#[derive(Clone, Copy, Debug, Default)]
pub struct LookupCost {
    pub counts: LookupCounts,
    pub time: Duration,
}

impl LookupCost {
    /// Mean microseconds per lookup (walk, visibility rays, weights; not the blend).
    pub fn micros(&self) -> f64 {
        self.time.as_secs_f64() * 1e6 / self.counts.lookups.max(1) as f64
    }
}

pub struct Scorer<'a> {
    points: &'a [Point],
    truth: &'a [[f64; 3]],
    rms_truth: f64,
    occluders: &'a Arc<Occluders>,
    /// Where the closed room is seen from (the path's centre); `None`: not measured.
    room: Option<DVec3>,
    pub frames: Option<Frames<'a>>,
    /// Lookup costs without and with visibility.
    pub off: LookupCost,
    pub rays: LookupCost,
}

impl<'a> Scorer<'a> {
    pub fn new(
        points: &'a [Point],
        truth: &'a [[f64; 3]],
        occluders: &'a Arc<Occluders>,
        room: Option<DVec3>,
        frames: Option<Frames<'a>>,
    ) -> Scorer<'a> {
        Scorer {
            points,
            truth,
            rms_truth: rms(truth),
            occluders,
            room,
            frames,
            off: LookupCost::default(),
            rays: LookupCost::default(),
        }
    }

    pub fn rms_truth(&self) -> f64 {
        self.rms_truth
    }

    /// `set`'s error (and leaked fraction) with lookups of `visibility`.
    pub fn score(&mut self, set: &ProbeSet, visibility: ProbeVisibility) -> Result<Score> {
        // The set's own visibility, or one built for it.
        let built = match (&set.visibility, visibility) {
            (None, ProbeVisibility::Rays) => {
                Some(Visibility::new(self.occluders.clone(), set.mesh.positions()))
            }
            _ => None,
        };
        let seeing = match visibility {
            ProbeVisibility::Rays => set.visibility.as_ref().or(built.as_ref()),
            ProbeVisibility::Off => None,
        };
        let seen_from_room = self.room.map(|c| self.seen_from(c, set.mesh.positions()));
        let mut walker = Walker::default();
        let (mut sum, mut leaked, mut total) = (0.0, 0.0, 0.0);
        for (point, exact) in self.points.iter().zip(self.truth) {
            let p = Vec3::from(point.position).as_dvec3();
            let start = Instant::now();
            let lookup = set.lookup_with(&mut walker, p, seeing)?;
            let cost = if seeing.is_some() { &mut self.rays } else { &mut self.off };
            cost.time += start.elapsed();
            cost.counts.count(lookup.seen);
            sum += squared_error(&set.blend(&lookup.weights), point, exact);
            if let Some(seen) = &seen_from_room {
                let n = Vec3::from(point.normal);
                for &(probe, w) in lookup.weights.iter().filter(|(_, w)| *w != 0.0) {
                    let e: f64 = set.sh[probe].irradiance(n).iter().map(|&e| f64::from(e.max(0.0))).sum();
                    total += w * e;
                    if !seen[probe] {
                        leaked += w * e;
                    }
                }
            }
        }
        let jump = match &self.frames {
            Some(frames) => {
                // One walker along the frames, as the technique's.
                let mut walker = Walker::default();
                let mut values = Vec::with_capacity(frames.points.len());
                for at in frames.points.chunks(NORMALS.len()) {
                    let p = Vec3::from(at[0].position).as_dvec3();
                    let sh = set.blend(&set.lookup_with(&mut walker, p, seeing)?.weights);
                    values.extend(NORMALS.iter().map(|&n| sh.irradiance(n).map(|e| f64::from(e.max(0.0)))));
                }
                Some(frames.largest_jump(&values))
            }
            None => None,
        };
        Ok(Score {
            error: (sum / (3 * self.truth.len()) as f64).sqrt() / self.rms_truth,
            leaked: seen_from_room.map(|_| if total > 0.0 { leaked / total } else { 0.0 }),
            jump,
        })
    }

    /// `set`'s closed room (see the module documentation); `None` when it is not measured, or
    /// when the probes seen from the room span no volume (a single layer of a grid).
    pub fn closed_room(&self, set: &ProbeSet) -> Option<ProbeSet> {
        let seen = self.seen_from(self.room?, set.mesh.positions());
        let kept = |indices: &[usize]| indices.iter().map(|&i| set.sh[i]).collect::<Vec<_>>();
        match &set.trilinear {
            Some(lattice) => {
                let (sub, indices) = sub_lattice(lattice, &seen)?;
                ProbeSet::trilinear(sub, kept(&indices)).ok()
            }
            None => {
                let indices: Vec<usize> = (0..seen.len()).filter(|&i| seen[i]).collect();
                let positions: Vec<DVec3> = indices.iter().map(|&i| set.mesh.positions()[i]).collect();
                ProbeSet::tetrahedral(&positions, kept(&indices)).ok()
            }
        }
    }

    fn seen_from(&self, c: DVec3, positions: &[DVec3]) -> Vec<bool> {
        positions.iter().map(|&q| self.occluders.sees(c, q)).collect()
    }
}

/// The smallest box of `lattice`'s probes holding every `seen` one, when it holds no other, and
/// its probes' indices in `lattice` in the box's own order.
fn sub_lattice(lattice: &Lattice, seen: &[bool]) -> Option<(Lattice, Vec<usize>)> {
    let [nx, ny, _] = lattice.counts.map(|n| n as usize);
    let ijk = |i: usize| [i % nx, (i / nx) % ny, i / (nx * ny)];
    let (mut lo, mut hi) = ([usize::MAX; 3], [0; 3]);
    for i in (0..seen.len()).filter(|&i| seen[i]) {
        for (a, c) in ijk(i).into_iter().enumerate() {
            (lo[a], hi[a]) = (lo[a].min(c), hi[a].max(c));
        }
    }
    if lo[0] == usize::MAX {
        return None;
    }
    let counts: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a] + 1);
    let mut indices = Vec::with_capacity(counts.iter().product());
    for k in lo[2]..=hi[2] {
        for j in lo[1]..=hi[1] {
            for i in lo[0]..=hi[0] {
                indices.push(i + nx * (j + ny * k));
            }
        }
    }
    if indices.len() != seen.iter().filter(|&&s| s).count() {
        return None;
    }
    let first = lattice.first + lattice.step * DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
    Some((Lattice { first, step: lattice.step, counts: counts.map(|n| n as u32) }, indices))
}

/// Σ over channels of (E_sh(n), clamped at 0 as the renderer does, − E)².
pub fn squared_error(sh: &kage::sh::ShRgb9, point: &Point, exact: &[f64; 3]) -> f64 {
    let e = sh.irradiance(Vec3::from(point.normal));
    (0..3).map(|k| (f64::from(e[k].max(0.0)) - exact[k]).powi(2)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sub_lattice_is_the_box_of_the_seen_probes_or_none() {
        let lattice = Lattice { first: DVec3::ZERO, step: DVec3::ONE, counts: [4, 2, 3] };
        // Every probe with i ≥ 2 seen: a 2 × 2 × 3 box from x = 2.
        let seen: Vec<bool> = (0..24).map(|i| i % 4 >= 2).collect();
        let (sub, indices) = sub_lattice(&lattice, &seen).unwrap();
        assert_eq!((sub.counts, sub.first), ([2, 2, 3], DVec3::new(2.0, 0.0, 0.0)));
        assert_eq!(indices[..4], [2, 3, 6, 7]);
        assert!(sub.positions().iter().zip(&indices).all(|(p, &i)| *p == lattice.positions()[i]));
        // One probe of that box hidden: not a box.
        let mut holed = seen.clone();
        holed[7] = false;
        assert!(sub_lattice(&lattice, &holed).is_none());
        assert!(sub_lattice(&lattice, &[false; 24]).is_none());
    }
}
