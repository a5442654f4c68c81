//! Trilinear interpolation over a regular probe grid: the common baseline that tetrahedral
//! interpolation (Morishige 2014) is measured against. The grid must cover the whole box, walls
//! and solids included, so probes are spent where nothing moves; tetrahedra go anywhere.
use glam::{DVec3, Vec3};

/// Probes at `first + step · (i, j, k)` for i < `counts[0]`, j < `counts[1]`,
/// k < `counts[2]`; probe (i, j, k) is number `i + counts[0] · (j + counts[1] · k)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    pub first: DVec3,
    pub step: DVec3,
    pub counts: [u32; 3],
}

impl Lattice {
    /// The cell centres of a `counts` grid over the box from `lo` to `hi` (never on its faces:
    /// walls are there).
    pub fn cell_centres(lo: Vec3, hi: Vec3, counts: [u32; 3]) -> Lattice {
        let step = (hi - lo).as_dvec3() / DVec3::from(counts.map(f64::from));
        Lattice { first: lo.as_dvec3() + 0.5 * step, step, counts }
    }

    pub fn len(&self) -> usize {
        self.counts.iter().map(|&n| n as usize).product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The probe positions in probe order.
    pub fn positions(&self) -> Vec<DVec3> {
        let [nx, ny, nz] = self.counts;
        let mut positions = Vec::with_capacity(self.len());
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    positions.push(self.first + self.step * DVec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        positions
    }

    /// The eight probes at the corners of the cell holding `p` and their trilinear weights
    /// (non-negative, summing to 1). Outside the grid's box `p` is first clamped onto it, so the
    /// light there is that of the nearest point of the box, continuous across its faces. An axis
    /// with one probe, or with no extent, takes that probe's layer alone.
    pub fn weights(&self, p: DVec3) -> [(u32, f64); 8] {
        let axis = |a: usize| -> (u32, f64) {
            let n = self.counts[a];
            let t = (p[a] - self.first[a]) / self.step[a];
            if n < 2 || !t.is_finite() {
                return (0, 0.0);
            }
            let t = t.clamp(0.0, (n - 1) as f64);
            let cell = (t.floor() as u32).min(n - 2);
            (cell, t - cell as f64)
        };
        let [(i, fx), (j, fy), (k, fz)] = [axis(0), axis(1), axis(2)];
        let [nx, ny, nz] = self.counts;
        // The corner one step further along an axis with a single layer is that layer again, at
        // weight 0.
        let next = |c: u32, n: u32| (c + 1).min(n - 1);
        std::array::from_fn(|corner| {
            let (dx, dy, dz) = (corner & 1 == 1, corner & 2 == 2, corner & 4 == 4);
            let x = if dx { next(i, nx) } else { i };
            let y = if dy { next(j, ny) } else { j };
            let z = if dz { next(k, nz) } else { k };
            let w = |d: bool, f: f64| if d { f } else { 1.0 - f };
            (x + nx * (y + ny * z), w(dx, fx) * w(dy, fy) * w(dz, fz))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice() -> Lattice {
        Lattice::cell_centres(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.0), [4, 3, 2])
    }

    /// A scalar field sampled at the probes, interpolated at `p`.
    fn interpolate(lattice: &Lattice, field: impl Fn(DVec3) -> f64, p: DVec3) -> f64 {
        let values: Vec<f64> = lattice.positions().into_iter().map(field).collect();
        lattice.weights(p).iter().map(|&(i, w)| w * values[i as usize]).sum()
    }

    #[test]
    fn a_linear_field_is_reproduced_exactly_inside_the_grid() {
        let lattice = lattice();
        let field = |p: DVec3| 0.3 - 1.7 * p.x + 2.5 * p.y + 0.75 * p.z;
        let (lo, hi) = (lattice.first, lattice.first + lattice.step * DVec3::new(3.0, 2.0, 1.0));
        for s in 0..=20 {
            let f = s as f64 / 20.0;
            let p = lo + (hi - lo) * DVec3::new(f, (f * 7.0).fract(), (f * 3.0).fract());
            // Rounding of a few operations on values of order 10.
            let exact = field(p);
            assert!((interpolate(&lattice, field, p) - exact).abs() < 1e-12, "{p}");
            let sum: f64 = lattice.weights(p).iter().map(|w| w.1).sum();
            assert!((sum - 1.0).abs() < 1e-12 && lattice.weights(p).iter().all(|w| w.1 >= 0.0));
        }
    }

    #[test]
    fn continuous_across_cell_faces() {
        let lattice = lattice();
        // Not linear: continuity is the weights', not the field's.
        let field = |p: DVec3| (3.0 * p.x).sin() * p.y.exp() + p.z * p.z * p.x;
        // On the face between cells 1 and 2 along X, and a hair either side of it.
        let x = lattice.first.x + 2.0 * lattice.step.x;
        let at = |x: f64| interpolate(&lattice, field, DVec3::new(x, 0.7, 2.9));
        let (left, on, right) = (at(x - 1e-9), at(x), at(x + 1e-9));
        // The field's slope times 1e-9, bounded by 100 here.
        assert!((left - on).abs() < 1e-7 && (right - on).abs() < 1e-7, "{left} {on} {right}");
    }

    #[test]
    fn outside_the_box_the_nearest_point_of_the_box_is_used() {
        let lattice = lattice();
        let field = |p: DVec3| p.x * p.y - p.z;
        let last = lattice.first + lattice.step * DVec3::new(3.0, 2.0, 1.0);
        let inside = DVec3::new(0.4, last.y, lattice.first.z);
        let outside = DVec3::new(0.4, last.y + 5.0, lattice.first.z - 2.0);
        assert_eq!(interpolate(&lattice, field, outside), interpolate(&lattice, field, inside));
        // Beyond a corner: that corner's probe alone.
        let w = lattice.weights(last + 1.0);
        let corner = (lattice.len() - 1) as u32;
        assert!(w.iter().all(|&(i, w)| w == 0.0 || (i == corner && w == 1.0)), "{w:?}");
    }

    #[test]
    fn an_axis_without_extent_takes_its_single_layer() {
        let flat = Lattice::cell_centres(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0), [2, 2, 2]);
        let w = flat.weights(DVec3::new(0.5, 0.0, 0.5));
        assert!((w.iter().map(|w| w.1).sum::<f64>() - 1.0).abs() < 1e-12, "{w:?}");
    }
}
