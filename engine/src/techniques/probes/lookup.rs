//! Finding the tetrahedron that holds a point, by walking from where the last lookup ended.
use super::input::usable;
use super::predicates::orient;
use super::rng::XorShift;
use super::tetmesh::{Across, TetMesh};
use crate::error::ProbeError;
use glam::DVec3;

/// Where a point lies: its tetrahedron's probes and their weights (non-negative, summing to 1,
/// reproducing the point inside the hull).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    pub tet: u32,
    pub probes: [u32; 4],
    pub weights: [f64; 4],
    /// The point is outside the convex hull: the weights are those of the nearest point of the
    /// hull, on a face of `tet` (the vertex off that face has weight 0).
    pub extrapolated: bool,
    /// Tetrahedra and hull faces stepped through (a measure of the walk's cost).
    pub steps: u32,
}

/// A moving object's place in a mesh: each lookup starts from the last one's tetrahedron, so a
/// coherent motion costs under one step per lookup on average (BENCHMARKS.md).
#[derive(Clone, Debug)]
pub struct Walker {
    tet: u32,
    rng: XorShift,
}

impl Default for Walker {
    fn default() -> Self {
        Walker::starting_at(0)
    }
}

impl Walker {
    /// A walker whose first lookup starts from tetrahedron `tet` (tetrahedron 0 when `tet` is not
    /// in the mesh).
    pub fn starting_at(tet: u32) -> Walker {
        Walker { tet, rng: XorShift::new(0x6c07_8965 ^ tet) }
    }

    /// A visibility walk with exact orientations, trying faces in random order (Devillers, Pion &
    /// Teillaud 2002, "remembering stochastic walk"): it cannot cycle, whatever the mesh's
    /// degeneracies, and leaves through a hull face only when p is outside the hull.
    pub fn locate(&mut self, mesh: &TetMesh, p: DVec3) -> Result<Location, ProbeError> {
        let p = usable(p).map_err(|problem| ProbeError::BadPoint { position: p.to_array(), problem })?;
        let positions = mesh.positions();
        let mut t = if (self.tet as usize) < mesh.tets().len() { self.tet } else { 0 };
        let mut from = None;
        let mut steps = 0;
        'walk: loop {
            let v = mesh.tets()[t as usize].map(|i| positions[i as usize]);
            let first = self.rng.below(4) as usize;
            for k in 0..4 {
                let slot = (first + k) % 4;
                let across = mesh.neighbours()[t as usize][slot];
                if Some(across) == from {
                    continue;
                }
                let mut q = v;
                q[slot] = p;
                if orient(q[0], q[1], q[2], q[3]) >= 0.0 {
                    continue;
                }
                match across {
                    Across::Tet(next) => {
                        from = Some(Across::Tet(t));
                        t = next;
                        steps += 1;
                        continue 'walk;
                    }
                    Across::Hull(face) => return Ok(self.extrapolate(mesh, p, face, steps)),
                }
            }
            self.tet = t;
            // p is inside by exact predicates; rounding may leave a weight a hair below 0.
            let w = mesh.weights(t, p).map(|x| x.max(0.0));
            let sum: f64 = w.iter().sum();
            let probes = mesh.tets()[t as usize];
            return Ok(Location { tet: t, probes, weights: w.map(|x| x / sum), extrapolated: false, steps });
        }
    }

    fn extrapolate(&mut self, mesh: &TetMesh, p: DVec3, face: u32, steps: u32) -> Location {
        let near = mesh.hull().nearest(mesh.positions(), p, face);
        let face = mesh.hull().faces[near.face as usize];
        self.tet = face.tet;
        let mut weights = [0.0; 4];
        for (k, w) in near.weights.into_iter().enumerate() {
            weights[k + usize::from(k >= face.slot)] = w;
        }
        Location {
            tet: face.tet,
            probes: mesh.tets()[face.tet as usize],
            weights,
            extrapolated: true,
            steps: steps + 1 + near.steps,
        }
    }
}
