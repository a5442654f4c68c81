//! Incremental 3D Delaunay tetrahedralization (Bowyer–Watson) with an infinite vertex.
//!
//! Every hull face is joined to a vertex at infinity by a "ghost" cell, so the cells always tile
//! all of space and a point outside the hull is inserted like any other (its conflicting ghost
//! cells are the hull faces it sees). Unlike a finite enclosing tetrahedron, this needs no
//! coordinates larger than the input's, which keeps the exact predicates cheap and the result
//! exactly the Delaunay tetrahedralization of the convex hull, whatever the coordinates' range.
use super::predicates::{collinear, inside_circle, inside_sphere, orient_at};
use super::rng::XorShift;
use super::spatial_sort::insertion_order;
use crate::error::ProbeError;
use glam::DVec3;

/// The vertex at infinity.
const INF: u32 = u32::MAX;
/// No neighbour yet (only while a star is being linked).
const UNSET: u32 = u32::MAX;
/// An empty slot of the edge table (no edge joins the infinite vertex to itself).
const NO_EDGE: u64 = u64::MAX;

/// A tetrahedron: vertices positively oriented (for a ghost cell, with the infinite vertex
/// replaced by any point beyond its hull face), and the neighbour across the face opposite each.
#[derive(Clone, Copy, Debug)]
struct Cell {
    v: [u32; 4],
    n: [u32; 4],
}

impl Cell {
    fn inf_slot(&self) -> Option<usize> {
        self.v.iter().position(|&v| v == INF)
    }
}

/// The vertices of the face opposite `slot`: the others, in order.
pub fn opposite<T: Copy>(v: [T; 4], slot: usize) -> [T; 3] {
    std::array::from_fn(|i| v[i + usize::from(i >= slot)])
}

/// A finite tetrahedron of the result; `n[i]` is `None` across a hull face.
#[derive(Clone, Copy, Debug)]
pub struct Tet {
    pub v: [u32; 4],
    pub n: [Option<u32>; 4],
}

/// The most tetrahedra (and ghost cells) a tetrahedralization may hold: points in general
/// position make about 6.5 per point, so this allows some 600,000 well-spread probes, while
/// points on two skew lines, which make quadratically many, stop here at about 150 MB instead of
/// growing without bound.
pub const MAX_TETRAHEDRA: usize = 1 << 22;

/// The Delaunay tetrahedralization of distinct `points` (at least 4), vertices indexing `points`.
pub fn tetrahedralize(points: &[DVec3]) -> Result<Vec<Tet>, ProbeError> {
    tetrahedralize_within(points, MAX_TETRAHEDRA)
}

/// [`tetrahedralize`] with at most `max` cells.
fn tetrahedralize_within(points: &[DVec3], max: usize) -> Result<Vec<Tet>, ProbeError> {
    let first = first_tetrahedron(points)?;
    let mut builder = Builder::new(points, first);
    for p in insertion_order(points) {
        if !first.contains(&p) {
            builder.insert(p);
            if builder.cells.len() - builder.free.len() > max {
                return Err(ProbeError::TooManyTetrahedra { points: points.len(), max });
            }
        }
    }
    Ok(builder.finite_tets())
}

/// Four points not in one plane, positively oriented: the first point, the next, the first not on
/// their line and the first not in their plane.
fn first_tetrahedron(points: &[DVec3]) -> Result<[u32; 4], ProbeError> {
    let flat = |shape| ProbeError::Flat { distinct: points.len(), shape };
    let (a, b) = (0, 1);
    let c = (2..points.len())
        .find(|&i| !collinear(points[a], points[b], points[i]))
        .ok_or_else(|| flat("on one line"))?;
    let d = (c + 1..points.len())
        .find(|&i| orient_at(points, [a, b, c, i].map(|k| k as u32)) != 0.0)
        .ok_or_else(|| flat("in one plane"))?;
    let v = [a, b, c, d].map(|k| k as u32);
    Ok(if orient_at(points, v) > 0.0 { v } else { [v[1], v[0], v[2], v[3]] })
}

/// A face of the cavity's boundary, and the new cell that joins it to the inserted point.
struct StarFace {
    /// The new cell's vertices; the inserted point at `apex`.
    v: [u32; 4],
    apex: usize,
    /// The cell outside the cavity across the face, and its slot that pointed into the cavity.
    outer: u32,
    outer_slot: usize,
}

struct Builder<'a> {
    points: &'a [DVec3],
    cells: Vec<Cell>,
    free: Vec<u32>,
    /// Per cell: `2 * insertion` when in the current cavity, `2 * insertion + 1` when tested and
    /// not in it (no clearing between insertions).
    mark: Vec<u32>,
    insertion: u32,
    /// Where the next walk starts: a cell made by the last insertion.
    hint: u32,
    rng: XorShift,
    cavity: Vec<u32>,
    star: Vec<StarFace>,
    /// The star's edges, each with a new cell and the slot opposite the face on it.
    edges: Vec<(u64, u32, usize)>,
}

impl<'a> Builder<'a> {
    /// One finite cell and the four ghost cells around it.
    fn new(points: &'a [DVec3], first: [u32; 4]) -> Builder<'a> {
        let mut builder = Builder {
            points,
            cells: vec![Cell { v: first, n: [UNSET; 4] }],
            free: Vec::new(),
            mark: vec![0],
            insertion: 1,
            hint: 0,
            rng: XorShift::new(0x2545_f491),
            cavity: Vec::new(),
            star: Vec::new(),
            edges: Vec::new(),
        };
        // The infinite vertex lies beyond each face, opposite the vertex it replaces: swapping two
        // other vertices keeps the ghost cell positively oriented.
        let star = (0..4)
            .map(|i| {
                let mut v = first;
                v[i] = INF;
                v.swap((i + 1) % 4, (i + 2) % 4);
                StarFace { v, apex: i, outer: 0, outer_slot: i }
            })
            .collect();
        builder.star = star;
        builder.build_star();
        builder
    }

    fn insert(&mut self, p: u32) {
        self.insertion += 1;
        let inside = 2 * self.insertion;
        let start = self.locate(p);
        self.cavity.clear();
        self.star.clear();
        self.cavity.push(start);
        self.mark[start as usize] = inside;
        // The conflicting cells form a connected region around p: grow it from the cell holding p.
        let mut k = 0;
        while k < self.cavity.len() {
            let c = self.cavity[k];
            k += 1;
            for slot in 0..4 {
                let next = self.cells[c as usize].n[slot];
                let mark = self.mark[next as usize];
                if mark == inside {
                    continue;
                }
                if mark != inside + 1 && self.conflicts(next, p) {
                    self.mark[next as usize] = inside;
                    self.cavity.push(next);
                    continue;
                }
                self.mark[next as usize] = inside + 1;
                let mut v = self.cells[c as usize].v;
                v[slot] = p;
                let outer_slot =
                    self.cells[next as usize].n.iter().position(|&n| n == c).expect("adjacency is symmetric");
                self.star.push(StarFace { v, apex: slot, outer: next, outer_slot });
            }
        }
        self.free.extend_from_slice(&self.cavity);
        self.build_star();
    }

    /// Replaces the cavity by the cells of `self.star` and links them to each other and to the
    /// cells outside.
    fn build_star(&mut self) {
        // Open addressing, at most 3/4 full: each edge's first face waits there for its second.
        let size = (4 * self.star.len()).next_power_of_two();
        let shift = 64 - size.trailing_zeros();
        self.edges.clear();
        self.edges.resize(size, (NO_EDGE, 0, 0));
        let star = std::mem::take(&mut self.star);
        for face in &star {
            let cell = Cell {
                v: face.v,
                n: std::array::from_fn(|i| if i == face.apex { face.outer } else { UNSET }),
            };
            let id = match self.free.pop() {
                Some(id) => {
                    self.cells[id as usize] = cell;
                    id
                }
                None => {
                    self.cells.push(cell);
                    self.mark.push(0);
                    self.cells.len() as u32 - 1
                }
            };
            self.cells[face.outer as usize].n[face.outer_slot] = id;
            // The face opposite slot k (≠ apex) joins the apex to the edge of the two other
            // vertices; the cavity's boundary is a sphere, so each edge is in exactly two faces.
            for k in (0..4).filter(|&k| k != face.apex) {
                let f = opposite(face.v, k);
                let apex = face.apex - usize::from(k < face.apex);
                let (a, b) = (f[(apex + 1) % 3], f[(apex + 2) % 3]);
                let key = (a.min(b) as u64) << 32 | a.max(b) as u64;
                // Fibonacci hashing: the top bits of the key times 2⁶⁴/φ.
                let mut at = (key.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> shift) as usize;
                loop {
                    let (other_key, other, other_slot) = self.edges[at];
                    if other_key == NO_EDGE {
                        self.edges[at] = (key, id, k);
                        break;
                    }
                    if other_key == key {
                        self.cells[id as usize].n[k] = other;
                        self.cells[other as usize].n[other_slot] = id;
                        break;
                    }
                    at = (at + 1) & (size - 1);
                }
            }
            self.hint = id;
        }
        self.star = star;
    }

    /// Whether p is inside the (perturbed) circumsphere of cell c; for a ghost cell, whether p is
    /// beyond its hull face, or in that face's plane and inside its circumcircle.
    fn conflicts(&self, c: u32, p: u32) -> bool {
        let cell = self.cells[c as usize];
        let Some(slot) = cell.inf_slot() else { return inside_sphere(self.points, cell.v, p) };
        let mut v = cell.v;
        v[slot] = p;
        let o = orient_at(self.points, v);
        if o != 0.0 {
            return o > 0.0;
        }
        inside_circle(self.points, opposite(cell.v, slot), p)
    }

    /// A cell in conflict with p: the finite cell holding it, or a ghost cell whose hull face p
    /// is strictly beyond. A visibility walk from the hint that tries faces in random order
    /// (Devillers, Pion & Teillaud 2002), so it cannot cycle.
    fn locate(&mut self, p: u32) -> u32 {
        let mut c = self.hint;
        let start = self.cells[c as usize];
        if let Some(slot) = start.inf_slot() {
            c = start.n[slot];
        }
        let mut from = UNSET;
        'walk: loop {
            let cell = self.cells[c as usize];
            let first = self.rng.below(4) as usize;
            for k in 0..4 {
                let slot = (first + k) % 4;
                if cell.n[slot] == from {
                    continue;
                }
                let mut v = cell.v;
                v[slot] = p;
                if orient_at(self.points, v) < 0.0 {
                    from = c;
                    c = cell.n[slot];
                    if self.cells[c as usize].inf_slot().is_some() {
                        return c;
                    }
                    continue 'walk;
                }
            }
            return c;
        }
    }

    /// The finite cells, renumbered, with ghost neighbours as hull faces.
    fn finite_tets(&self) -> Vec<Tet> {
        let mut dead = vec![false; self.cells.len()];
        for &c in &self.free {
            dead[c as usize] = true;
        }
        let mut number = vec![u32::MAX; self.cells.len()];
        let mut tets = Vec::new();
        for (i, cell) in self.cells.iter().enumerate() {
            if !dead[i] && cell.inf_slot().is_none() {
                number[i] = tets.len() as u32;
                tets.push(Tet { v: cell.v, n: [None; 4] });
            }
        }
        for (i, cell) in self.cells.iter().enumerate() {
            if number[i] != u32::MAX {
                tets[number[i] as usize].n =
                    cell.n.map(|n| Some(number[n as usize]).filter(|&k| k != u32::MAX));
            }
        }
        tets
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on two skew lines make quadratically many tetrahedra (n² for n points on each):
    /// past the bound the construction stops with an error naming it, instead of growing.
    #[test]
    fn quadratically_many_tetrahedra_stop_at_the_bound() {
        let line = |n: usize, f: fn(f64) -> DVec3| (0..n).map(move |i| f(i as f64 / n as f64));
        let skew: Vec<DVec3> = line(40, |t| DVec3::new(t, 0.0, 0.0))
            .chain(line(40, |t| DVec3::new(0.5, 1.0, t - 0.5)))
            .collect();
        let all = tetrahedralize_within(&skew, usize::MAX).unwrap().len();
        assert!(all > 40 * 30, "{all} tetrahedra: not quadratic, the test proves nothing");
        let error = tetrahedralize_within(&skew, all / 2).unwrap_err();
        assert!(matches!(error, ProbeError::TooManyTetrahedra { points: 80, .. }), "{error}");
        assert!(error.to_string().contains("spread them in 3D"), "{error}");
    }
}
