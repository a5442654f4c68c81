//! The binned SAH builder (Wald 2007, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies"), used for both levels: triangles in a bottom-level tree, instances in the top
//! level.
use super::aabb::Aabb;
use crate::layouts::{constants, BvhNode};
use glam::Vec3;

/// Bins per axis; beyond 16 the trees barely improve (Wald 2007).
const BINS: usize = 16;
/// SAH cost of visiting a node, relative to one primitive test.
const TRAVERSAL_COST: f32 = 1.0;

/// A flattened tree: `nodes[0]` is the root, the two children of an interior node are adjacent,
/// and a leaf's `index .. index + count` is a range of `order`, which lists the primitives (by
/// their index in the input) leaf by leaf.
pub struct Tree {
    pub nodes: Vec<BvhNode>,
    pub order: Vec<u32>,
}

pub fn node(bounds: Aabb, index: u32, count: u32) -> BvhNode {
    BvhNode {
        lo: bounds.lo.extend(f32::from_bits(index)).to_array(),
        hi: bounds.hi.extend(f32::from_bits(count)).to_array(),
    }
}

pub fn node_bounds(node: &BvhNode) -> Aabb {
    Aabb { lo: Vec3::from_slice(&node.lo[..3]), hi: Vec3::from_slice(&node.hi[..3]) }
}

/// (index, count) of a node; count 0 means interior.
pub fn node_range(node: &BvhNode) -> (u32, u32) {
    (node.lo[3].to_bits(), node.hi[3].to_bits())
}

/// Builds a tree over `boxes` with at most `max_leaf` primitives per leaf. No primitives give a
/// single empty root that every ray misses.
pub fn build(boxes: &[Aabb], max_leaf: usize) -> Tree {
    let mut builder = Builder {
        boxes,
        centroids: boxes.iter().map(Aabb::centroid).collect(),
        order: (0..boxes.len() as u32).collect(),
        nodes: vec![node(Aabb::EMPTY, 0, 0)],
        max_leaf: max_leaf.max(1),
    };
    if !boxes.is_empty() {
        builder.split(0, 0, boxes.len(), 0);
    }
    Tree { nodes: builder.nodes, order: builder.order }
}

struct Builder<'a> {
    boxes: &'a [Aabb],
    centroids: Vec<Vec3>,
    order: Vec<u32>,
    nodes: Vec<BvhNode>,
    max_leaf: usize,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: usize,
}

struct Split {
    axis: usize,
    /// Primitives in bins below this go left.
    bin: usize,
    cost: f32,
}

impl Builder<'_> {
    fn split(&mut self, at: usize, start: usize, end: usize, depth: u32) {
        let prims = &self.order[start..end];
        let bounds = prims.iter().fold(Aabb::EMPTY, |b, &p| b.union(self.boxes[p as usize]));
        let centroids = prims.iter().fold(Aabb::EMPTY, |b, &p| b.grow(self.centroids[p as usize]));
        let n = end - start;
        if n == 1 {
            self.nodes[at] = node(bounds, start as u32, 1);
            return;
        }
        // Splits follow the SAH while the subtree could still be finished with median splits
        // (each halving the primitives) within the shader's fixed stack: no leaf is ever
        // deeper than KAGE_BVH_STACK - 1, so the stack cannot overflow for any input.
        let halvings = n.next_power_of_two().trailing_zeros();
        let best = if depth + halvings + 1 < constants::BVH_STACK {
            self.best_split(start, end, &bounds, &centroids)
        } else {
            None
        };
        if n <= self.max_leaf && best.as_ref().is_none_or(|s| s.cost >= n as f32) {
            self.nodes[at] = node(bounds, start as u32, n as u32);
            return;
        }
        let mid = match best {
            Some(split) => {
                let (lo, extent) =
                    (centroids.lo[split.axis], centroids.hi[split.axis] - centroids.lo[split.axis]);
                let centroids = &self.centroids;
                let prims = &mut self.order[start..end];
                let mut left = 0;
                for i in 0..prims.len() {
                    let c = centroids[prims[i] as usize][split.axis];
                    if bin_of(c, lo, extent) < split.bin {
                        prims.swap(i, left);
                        left += 1;
                    }
                }
                start + left
            }
            None => {
                // Object median along the widest centroid axis: always splits in two halves.
                let axis = (centroids.hi - centroids.lo).max_position();
                let centroids = &self.centroids;
                self.order[start..end].select_nth_unstable_by(n / 2, |&a, &b| {
                    centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
                });
                start + n / 2
            }
        };
        let children = self.nodes.len();
        self.nodes.push(node(Aabb::EMPTY, 0, 0));
        self.nodes.push(node(Aabb::EMPTY, 0, 0));
        self.nodes[at] = node(bounds, children as u32, 0);
        self.split(children, start, mid, depth + 1);
        self.split(children + 1, mid, end, depth + 1);
    }

    /// The cheapest SAH split over all three axes, if any bin boundary separates the centroids.
    fn best_split(&self, start: usize, end: usize, bounds: &Aabb, centroids: &Aabb) -> Option<Split> {
        let area = bounds.area();
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        let mut best: Option<Split> = None;
        for axis in 0..3 {
            let (lo, extent) = (centroids.lo[axis], centroids.hi[axis] - centroids.lo[axis]);
            if extent <= 0.0 || !extent.is_finite() {
                continue;
            }
            let mut bins = [Bin { bounds: Aabb::EMPTY, count: 0 }; BINS];
            for &p in &self.order[start..end] {
                let bin = &mut bins[bin_of(self.centroids[p as usize][axis], lo, extent)];
                bin.bounds = bin.bounds.union(self.boxes[p as usize]);
                bin.count += 1;
            }
            // right_cost[i]: area × count of bins i.. , swept from the right.
            let mut right_cost = [0.0f32; BINS];
            let mut acc = Bin { bounds: Aabb::EMPTY, count: 0 };
            for i in (1..BINS).rev() {
                acc.bounds = acc.bounds.union(bins[i].bounds);
                acc.count += bins[i].count;
                right_cost[i] = acc.bounds.area() * acc.count as f32;
            }
            let mut left = Bin { bounds: Aabb::EMPTY, count: 0 };
            for i in 1..BINS {
                left.bounds = left.bounds.union(bins[i - 1].bounds);
                left.count += bins[i - 1].count;
                let right_count = end - start - left.count;
                if left.count == 0 || right_count == 0 {
                    continue;
                }
                let cost = TRAVERSAL_COST + (left.bounds.area() * left.count as f32 + right_cost[i]) / area;
                if best.as_ref().is_none_or(|b| cost < b.cost) {
                    best = Some(Split { axis, bin: i, cost });
                }
            }
        }
        best
    }
}

fn bin_of(c: f32, lo: f32, extent: f32) -> usize {
    (((c - lo) / extent * BINS as f32) as usize).min(BINS - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic scatter of small boxes, some coincident, so that the median fallback runs.
    fn boxes(n: usize) -> Vec<Aabb> {
        let mut next = super::super::aabb::test_random(12345);
        (0..n)
            .map(|i| {
                let c = if i % 7 == 0 { Vec3::ONE } else { Vec3::new(next(), next(), next()) * 10.0 };
                let half = Vec3::new(next(), next(), next()) * 0.3;
                Aabb { lo: c - half, hi: c + half }
            })
            .collect()
    }

    #[test]
    fn every_primitive_is_in_exactly_one_leaf_and_children_nest_in_parents() {
        for n in [1, 2, 5, 100, 3000] {
            let input = boxes(n);
            let tree = build(&input, 4);
            let mut seen = vec![0u32; n];
            let mut stack = vec![(0usize, 0u32)];
            let mut max_depth = 0;
            while let Some((at, depth)) = stack.pop() {
                max_depth = max_depth.max(depth);
                let bounds = node_bounds(&tree.nodes[at]);
                let (index, count) = node_range(&tree.nodes[at]);
                if count > 0 {
                    assert!(count <= 4, "leaf of {count} primitives");
                    for &p in &tree.order[index as usize..(index + count) as usize] {
                        seen[p as usize] += 1;
                        assert!(bounds.contains(&input[p as usize]), "primitive outside its leaf");
                    }
                } else {
                    for child in [index as usize, index as usize + 1] {
                        assert!(
                            bounds.contains(&node_bounds(&tree.nodes[child])),
                            "child outside its parent"
                        );
                        stack.push((child, depth + 1));
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{n} primitives: some in no leaf or in several");
            assert!(max_depth < constants::BVH_STACK, "depth {max_depth}");
        }
    }

    #[test]
    fn exponentially_spaced_primitives_stay_within_the_traversal_stack() {
        // The SAH peels such boxes off one at a time, which alone would nest 150 deep.
        let input: Vec<Aabb> = (0..150)
            .map(|i| {
                let c = Vec3::splat(1.5f32.powi(i));
                Aabb { lo: c, hi: c * 1.01 }
            })
            .collect();
        let tree = build(&input, 4);
        let mut stack = vec![(0usize, 0u32)];
        while let Some((at, depth)) = stack.pop() {
            assert!(depth < constants::BVH_STACK, "a node at depth {depth}");
            let (index, count) = node_range(&tree.nodes[at]);
            if count == 0 {
                stack.extend([(index as usize, depth + 1), (index as usize + 1, depth + 1)]);
            }
        }
    }

    #[test]
    fn coincident_primitives_still_split_down_to_small_leaves() {
        let input = vec![Aabb { lo: Vec3::ZERO, hi: Vec3::ONE }; 100];
        let tree = build(&input, 4);
        assert!(tree.nodes.iter().all(|n| node_range(n).1 <= 4));
    }

    #[test]
    fn no_primitives_give_an_empty_root() {
        let tree = build(&[], 4);
        assert_eq!(tree.nodes.len(), 1);
        assert!(node_bounds(&tree.nodes[0]).is_empty());
    }
}
