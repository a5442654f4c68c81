//! The tetrahedral mesh of a probe set: tetrahedra over the input's indices, their adjacency, the
//! hull faces, and each tetrahedron's precomputed inverse matrix for barycentric weights
//! (Morishige 2014, step 4: the tetrahedra never change at run time).
use super::delaunay::{opposite, tetrahedralize};
use super::error::ProbeError;
use super::extrapolate::{Hull, HullFace};
use super::input::{distinct, Merged};
use glam::{DMat3, DVec3};

/// What lies across a face of a tetrahedron.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Across {
    Tet(u32),
    /// The face is on the convex hull (the number is the hull face's).
    Hull(u32),
}

/// p ↦ weights of a tetrahedron's vertices: with the vertex at `origin` as p₃ and the others
/// p₀, p₁, p₂ in order, [a b c]ᵀ = M⁻¹ (p − p₃) and the origin's weight is 1 − a − b − c.
#[derive(Clone, Copy, Debug)]
struct Barycentric {
    origin: usize,
    inverse: DMat3,
}

impl Barycentric {
    /// The origin is the vertex nearest the others: for a needle (three close probes and a far
    /// one) the far one would make M's columns nearly parallel and lose most digits of the
    /// weights, where a near one keeps them.
    fn new(v: [DVec3; 4]) -> Barycentric {
        let spread = |i: usize| v.iter().map(|&w| w.distance_squared(v[i])).sum::<f64>();
        let origin = (1..4).fold(0, |best, i| if spread(i) < spread(best) { i } else { best });
        let [a, b, c] = opposite(v, origin);
        let o = v[origin];
        Barycentric { origin, inverse: DMat3::from_cols(a - o, b - o, c - o).inverse() }
    }
}

pub struct TetMesh {
    positions: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
    neighbours: Vec<[Across; 4]>,
    barycentric: Vec<Barycentric>,
    hull: Hull,
    merged: Vec<Merged>,
}

impl TetMesh {
    /// The Delaunay tetrahedralization of `positions`. Identical positions are merged (see
    /// [`TetMesh::merged`]); indices everywhere refer to `positions`.
    pub fn build(positions: &[DVec3]) -> Result<TetMesh, ProbeError> {
        let set = distinct(positions)?;
        if set.points.len() < 4 {
            return Err(ProbeError::TooFew { distinct: set.points.len(), total: positions.len() });
        }
        let cells = tetrahedralize(&set.points)?;
        let tets: Vec<[u32; 4]> = cells.iter().map(|c| c.v.map(|i| set.input_index[i as usize])).collect();
        let mut faces = Vec::new();
        let neighbours = cells
            .iter()
            .enumerate()
            .map(|(t, cell)| {
                std::array::from_fn(|slot| match cell.n[slot] {
                    Some(n) => Across::Tet(n),
                    None => {
                        faces.push(HullFace { tet: t as u32, slot, v: opposite(tets[t], slot) });
                        Across::Hull(faces.len() as u32 - 1)
                    }
                })
            })
            .collect();
        let barycentric = tets.iter().map(|t| Barycentric::new(t.map(|i| set.all[i as usize]))).collect();
        Ok(TetMesh {
            hull: Hull::new(set.all.len(), faces),
            positions: set.all,
            tets,
            neighbours,
            barycentric,
            merged: set.merged,
        })
    }

    /// The input positions (duplicates included; coordinates nearer 0 than 1e-30 set to 0).
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Each tetrahedron's four probes (input indices), positively oriented:
    /// (p₁ − p₀) · ((p₂ − p₀) × (p₃ − p₀)) > 0.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Across the face opposite each vertex of each tetrahedron.
    pub fn neighbours(&self) -> &[[Across; 4]] {
        &self.neighbours
    }

    /// The duplicate positions that were merged, by increasing `index`.
    pub fn merged(&self) -> &[Merged] {
        &self.merged
    }

    pub(super) fn hull(&self) -> &Hull {
        &self.hull
    }

    /// The barycentric weights of p in tetrahedron `tet` (in the order of its vertices). Like any
    /// floating-point solve, they are accurate to about 1e-16 × (longest edge)³ / volume of the
    /// tetrahedron, relative to the coordinates: slivers (nearly coplanar probes) lose digits.
    pub fn weights(&self, tet: u32, p: DVec3) -> [f64; 4] {
        let b = &self.barycentric[tet as usize];
        let origin = self.positions[self.tets[tet as usize][b.origin] as usize];
        let [x, y, z] = (b.inverse * (p - origin)).to_array();
        let mut w = [x, y, z, 1.0 - x - y - z];
        w[b.origin..].rotate_right(1);
        w
    }
}
