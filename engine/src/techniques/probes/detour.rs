//! The way round: how far a point must travel through free space, around the static geometry,
//! to reach a probe. The visibility test ([`super::visibility`]) uses it to tell a probe in
//! another space (behind a wall: reached only by a long way round through a door or an
//! opening, or not at all) from one in the point's own space that a column, an arch or a
//! roof's edge hides from it (a short way round), whose light is the point's own.
//!
//! A grid of cells over the static geometry's box, each joined to its 26 neighbours where no
//! static surface crosses the segment between their centres (a ray each, once per scene); per
//! probe, the length of the shortest path along those joins from the probe to every cell
//! (Dijkstra, computed the first time a lookup needs it). A path along the joins overestimates
//! the straight line by at most 13 % (26 directions: 1.128 at worst) plus the steps into
//! the grid at each end.
//!
//! Limits: the grid spans the static geometry's box only, so that rooms under one roof are not
//! joined over it; a probe or point outside the box reaches it through the nearest cells it
//! sees. Openings narrower than a cell may close.
use super::visibility::Occluders;
use crate::raycast::SceneBvh;
use glam::DVec3;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Cells along the box's longest side.
pub const CELLS_LONGEST: usize = 48;

/// A space holding less than this share of the grid's cells is a sealed pocket, not a room
/// ([`FreeGrid::sealed`]): in the atrium, gaps between the arches' boxes and the edge beam.
pub const MIN_SPACE_SHARE: f64 = 0.01;

/// The forward half of the 26 neighbour offsets (the other half is their negation).
const FORWARD: [[i32; 3]; 13] = [
    [1, 0, 0],
    [0, 1, 0],
    [0, 0, 1],
    [1, 1, 0],
    [1, -1, 0],
    [1, 0, 1],
    [1, 0, -1],
    [0, 1, 1],
    [0, 1, -1],
    [1, 1, 1],
    [1, 1, -1],
    [1, -1, 1],
    [1, -1, -1],
];

/// The free-space grid of one scene's static geometry.
#[derive(Clone, Debug)]
pub struct FreeGrid {
    lo: DVec3,
    /// The cell's size along each axis (the box's side over its cells: near-cubic cells whose
    /// outermost centres lie half a cell inside the box, never above a roof).
    cell: DVec3,
    dims: [usize; 3],
    /// Per cell, bit k: the join to the cell at `FORWARD[k]` is open.
    open: Vec<u16>,
    /// Per cell, the number of cells its joins connect it to, itself included: the size of
    /// its space.
    space: Vec<u32>,
}

impl FreeGrid {
    /// The grid over the box of `bvh`'s triangles, joins tested through `occluders`; `None`
    /// without triangles.
    pub(super) fn build(bvh: &SceneBvh, occluders: &Occluders) -> Option<FreeGrid> {
        let bounds = bvh.bounds()?;
        let (lo, hi) = (bounds.lo.as_dvec3(), bounds.hi.as_dvec3());
        let extent = hi - lo;
        if !extent.is_finite() || extent.max_element() <= 0.0 {
            return None;
        }
        let side = extent.max_element() / CELLS_LONGEST as f64;
        let dims = extent.to_array().map(|e| ((e / side).round() as usize).max(1));
        // A side thinner than a cell (a floor alone) gets one cell, centred on it.
        let size = DVec3::from_array(std::array::from_fn(|a| {
            if extent[a] < side {
                side
            } else {
                extent[a] / dims[a] as f64
            }
        }));
        let lo = (lo + hi) * 0.5 - size * DVec3::from_array(dims.map(|d| d as f64)) * 0.5;
        let cells = dims[0] * dims[1] * dims[2];
        let mut grid = FreeGrid { lo, cell: size, dims, open: vec![0; cells], space: vec![0; cells] };
        for index in 0..grid.open.len() {
            let at = grid.coords(index);
            let centre = grid.centre(at);
            let mut bits = 0u16;
            for (k, offset) in FORWARD.iter().enumerate() {
                if let Some(next) = grid.neighbour(at, *offset) {
                    if occluders.sees(centre, grid.centre(next)) {
                        bits |= 1 << k;
                    }
                }
            }
            grid.open[index] = bits;
        }
        grid.space = grid.space_sizes();
        Some(grid)
    }

    /// Each cell's [`FreeGrid::space`]: the cells connected, found by walking the joins.
    fn space_sizes(&self) -> Vec<u32> {
        let mut label = vec![u32::MAX; self.open.len()];
        let mut sizes = Vec::new();
        for start in 0..self.open.len() {
            if label[start] != u32::MAX {
                continue;
            }
            let id = sizes.len() as u32;
            label[start] = id;
            let mut stack = vec![start];
            let mut size = 0u32;
            while let Some(cell) = stack.pop() {
                size += 1;
                for (next, _) in self.joined(cell) {
                    if label[next] == u32::MAX {
                        label[next] = id;
                        stack.push(next);
                    }
                }
            }
            sizes.push(size);
        }
        label.into_iter().map(|id| sizes[id as usize]).collect()
    }

    /// The cells joined to `cell`, each with the join's index into `FORWARD`.
    fn joined(&self, cell: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let at = self.coords(cell);
        FORWARD.iter().enumerate().flat_map(move |(k, offset)| {
            [1, -1].into_iter().filter_map(move |sign| {
                let next = self.index(self.neighbour(at, offset.map(|o| o * sign))?);
                // The join's bit is kept by the cell it leaves forward from.
                let from = if sign == 1 { cell } else { next };
                (self.open[from] & (1 << k) != 0).then_some((next, k))
            })
        })
    }

    /// Whether `q` is sealed off in a pocket: every cell around it that it sees lies in a space
    /// of less than [`MIN_SPACE_SHARE`] of the grid's cells (or it sees none), as a gap closed
    /// on all sides between boxes that do not quite overlap, or the inside of a solid.
    pub(super) fn sealed(&self, q: DVec3, occluders: &Occluders) -> bool {
        let least = MIN_SPACE_SHARE * self.open.len() as f64;
        self.entries(q, occluders).iter().all(|&(cell, _)| f64::from(self.space[cell]) < least)
    }

    fn coords(&self, index: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [index % nx, (index / nx) % ny, index / (nx * ny)]
    }

    fn index(&self, at: [usize; 3]) -> usize {
        at[0] + self.dims[0] * (at[1] + self.dims[1] * at[2])
    }

    fn centre(&self, at: [usize; 3]) -> DVec3 {
        self.lo + (DVec3::from_array(at.map(|c| c as f64)) + 0.5) * self.cell
    }

    fn neighbour(&self, at: [usize; 3], offset: [i32; 3]) -> Option<[usize; 3]> {
        let mut next = [0; 3];
        for a in 0..3 {
            let c = at[a] as i64 + i64::from(offset[a]);
            if c < 0 || c >= self.dims[a] as i64 {
                return None;
            }
            next[a] = c as usize;
        }
        Some(next)
    }

    /// The (up to 8) cells whose centres surround `q` (the nearest ones, clamped to the grid,
    /// where `q` lies outside), those `q` sees, each with its distance from `q`.
    pub(super) fn entries(&self, q: DVec3, occluders: &Occluders) -> Vec<(usize, f64)> {
        let f = (q - self.lo) / self.cell - 0.5;
        let base: [i64; 3] = std::array::from_fn(|a| f[a].floor() as i64);
        let mut cells: Vec<usize> = (0..8)
            .map(|k| {
                let at: [usize; 3] = std::array::from_fn(|a| {
                    (base[a] + ((k >> a) & 1) as i64).clamp(0, self.dims[a] as i64 - 1) as usize
                });
                self.index(at)
            })
            .collect();
        cells.sort_unstable();
        cells.dedup();
        cells
            .into_iter()
            .map(|i| (i, self.centre(self.coords(i))))
            .filter(|&(_, c)| occluders.sees(q, c))
            .map(|(i, c)| (i, q.distance(c)))
            .collect()
    }

    /// The length of the shortest path along open joins from `q` to every cell (infinite where
    /// none leads), entering the grid at the cells around `q` that it sees.
    pub(super) fn distances_from(&self, q: DVec3, occluders: &Occluders) -> Vec<f32> {
        let steps = FORWARD.map(|o| (DVec3::from_array(o.map(f64::from)) * self.cell).length());
        let mut distance = vec![f32::INFINITY; self.open.len()];
        // Keyed by the distances' bits, which order as the distances do (never negative).
        let mut heap = BinaryHeap::new();
        for (cell, d) in self.entries(q, occluders) {
            distance[cell] = d as f32;
            heap.push(Reverse(((d as f32).to_bits(), cell)));
        }
        while let Some(Reverse((bits, cell))) = heap.pop() {
            let d = f32::from_bits(bits);
            if d > distance[cell] {
                continue;
            }
            for (next, k) in self.joined(cell) {
                let through = d + steps[k] as f32;
                if through < distance[next] {
                    distance[next] = through;
                    heap.push(Reverse((through.to_bits(), next)));
                }
            }
        }
        distance
    }

    /// The length of the way round from a point `p` to the probe whose
    /// [`FreeGrid::distances_from`] is `field`: into the grid at a cell around `p` that it sees
    /// (`entries`, [`FreeGrid::entries`] of `p`), then along the joins; `None` when `p` sees
    /// none.
    pub(super) fn way_round(&self, field: &[f32], entries: &[(usize, f64)]) -> Option<f64> {
        entries.iter().map(|&(cell, d)| d + f64::from(field[cell])).min_by(f64::total_cmp)
    }

    /// The largest side of a cell.
    pub(super) fn cell_size(&self) -> f64 {
        self.cell.max_element()
    }
}
