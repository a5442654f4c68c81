//! The tetrahedral mesh of a probe set: tetrahedra over the input's indices, their adjacency, the
//! hull faces, and each tetrahedron's precomputed inverse matrix for barycentric weights
//! (Morishige 2014, step 4: the tetrahedra never change at run time).
use super::delaunay::{opposite, tetrahedralize};
use super::extrapolate::{Hull, HullFace};
use super::input::{distinct, Merged};
use crate::error::ProbeError;
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
/// `None` for a sliver (see `SLIVER`).
#[derive(Clone, Copy, Debug)]
struct Barycentric {
    origin: usize,
    inverse: Option<DMat3>,
}

/// A tetrahedron whose matrix's determinant (six times its volume) is below this fraction of
/// its longest edge cubed is a sliver. Its inverse would amplify the coordinates' rounding by
/// the inverse of that fraction (and where the determinant rounds to 0, give NaN), while its
/// four probes are all but coplanar, so the weights of the face that holds p's projection
/// reproduce p to within the sliver's thickness: below 1e-8 of the edge, past which the matrix
/// is the more accurate. Cell-centre lattices make
/// slivers wherever four of their points are coplanar in exact terms but not in binary
/// fractions (1/12 + k/6, for one).
const SLIVER: f64 = 1e-8;

impl Barycentric {
    /// The origin is the vertex nearest the others: for a needle (three close probes and a far
    /// one) the far one would make M's columns nearly parallel and lose most digits of the
    /// weights, where a near one keeps them.
    fn new(v: [DVec3; 4]) -> Barycentric {
        let spread = |i: usize| v.iter().map(|&w| w.distance_squared(v[i])).sum::<f64>();
        let origin = (1..4).fold(0, |best, i| if spread(i) < spread(best) { i } else { best });
        let [a, b, c] = opposite(v, origin);
        let o = v[origin];
        let m = DMat3::from_cols(a - o, b - o, c - o);
        let longest = (0..4).flat_map(|i| (0..i).map(move |j| v[i].distance(v[j]))).fold(0.0, f64::max);
        let volume = m.determinant().abs();
        let sliver = !volume.is_finite() || volume <= SLIVER * longest.powi(3);
        Barycentric { origin, inverse: (!sliver).then(|| m.inverse()) }
    }
}

/// The weights in a sliver: those of p projected onto the face whose triangle holds the
/// projection best (largest least weight), 0 for the vertex off it.
fn sliver_weights(v: [DVec3; 4], p: DVec3) -> [f64; 4] {
    let mut best: Option<(f64, usize, [f64; 3])> = None;
    for slot in 0..4 {
        let [a, b, c] = opposite(v, slot);
        let (e0, e1, e2) = (b - a, c - a, p - a);
        let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
        let denom = d00 * d11 - d01 * d01;
        // A face with its three probes on one line has no weights of its own.
        if !denom.is_finite() || denom <= 1e-12 * d00 * d11 {
            continue;
        }
        let (d20, d21) = (e2.dot(e0), e2.dot(e1));
        let beta = (d11 * d20 - d01 * d21) / denom;
        let gamma = (d00 * d21 - d01 * d20) / denom;
        let w = [1.0 - beta - gamma, beta, gamma];
        let least = w.iter().copied().fold(f64::MAX, f64::min);
        if best.is_none_or(|(l, ..)| least > l) {
            best = Some((least, slot, w));
        }
    }
    let mut weights = [0.0; 4];
    match best {
        Some((_, slot, w)) => {
            let sum: f64 = w.iter().map(|x| x.max(0.0)).sum();
            for (k, x) in w.into_iter().enumerate() {
                weights[k + usize::from(k >= slot)] = x.max(0.0) / sum;
            }
        }
        // Every face on a line: the four probes nearly on one, and p among them.
        None => {
            let near = (1..4).fold(0, |n, k| if v[k].distance(p) < v[n].distance(p) { k } else { n });
            weights[near] = 1.0;
        }
    }
    weights
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
    /// tetrahedron, relative to the coordinates; in a sliver (see `SLIVER`) they are a
    /// face's, which reproduce p to within the sliver's thickness.
    pub fn weights(&self, tet: u32, p: DVec3) -> [f64; 4] {
        let b = &self.barycentric[tet as usize];
        let corners = self.tets[tet as usize].map(|i| self.positions[i as usize]);
        let Some(inverse) = b.inverse else { return sliver_weights(corners, p) };
        let [x, y, z] = (inverse * (p - corners[b.origin])).to_array();
        let mut w = [x, y, z, 1.0 - x - y - z];
        w[b.origin..].rotate_right(1);
        w
    }
}
