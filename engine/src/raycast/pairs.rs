//! The bottom-level trees as the GPU traverses them: one [`BvhPair`] per interior node, its two
//! children's boxes quantized to 8 bits per coordinate on a grid over the node's own box (as
//! compressed wide BVHs do, Ylitie, Karras and Laine 2017, at width two). A step of the
//! traversal then reads two texels instead of two 2-texel nodes: on lavapipe every texel read
//! is a gather over eight lanes, which is most of a step's cost (see BENCHMARKS.md, "Ray
//! casting"). The grid's origin gives up the lowest 8 bits of its mantissa to hold the grid
//! step's exponent, which costs a box at most about one f32 step of its coordinates.
//!
//! The quantized boxes are conservative in the shader's own arithmetic: each corner is
//! `origin + q * step` with `step` a power of two, so `q * step` is exact and the one rounding
//! of the sum is the same whether the device fuses it or not; the builder moves each `q`
//! outwards until that f32 sum encloses the exact box, and coarsens the grid where 255 steps
//! cannot reach (a tiny box far from the origin).
use super::aabb::Aabb;
use super::sah::{node_bounds, node_range};
use crate::error::{Error, Result};
use crate::layouts::{constants, BvhNode, BvhPair};
use crate::scene::MAX_TRIANGLES;
use glam::Vec3;

/// The pairs of one tree (`nodes` as the SAH builder flattened it, its leaves' triangle ranges
/// offset by `first_triangle`), numbered from `base` in the order of their interior nodes, so
/// the root's pair is `base`: a tree whose root is a leaf (or empty) gets one pair of that leaf
/// (or of nothing) and an empty second child.
pub fn pairs(nodes: &[BvhNode], first_triangle: u32, base: u32) -> Result<Vec<BvhPair>> {
    let mut pair_of = Vec::with_capacity(nodes.len());
    let mut interior = 0u32;
    for node in nodes {
        pair_of.push(base + interior);
        interior += u32::from(node_range(node).1 == 0 && !node_bounds(node).is_empty());
    }
    let reference = |at: usize| -> Result<u32> {
        let node = &nodes[at];
        let (index, count) = node_range(node);
        if node_bounds(node).is_empty() {
            return Ok(constants::NO_HIT);
        }
        if count == 0 {
            return Ok(pair_of[at]);
        }
        let first = first_triangle + index;
        if count > 7 || first as usize >= MAX_TRIANGLES {
            return Err(Error::InvalidArgument(format!(
                "the scene has too many triangles for a BVH leaf reference ({first} + {count}; at most \
                 {MAX_TRIANGLES})"
            )));
        }
        Ok(constants::BVH_LEAF | count << 28 | first)
    };
    let mut out = Vec::with_capacity(interior as usize + 1);
    for node in nodes {
        let (index, count) = node_range(node);
        if count == 0 && !node_bounds(node).is_empty() {
            let children = [index as usize, index as usize + 1];
            out.push(pair(
                children.map(|c| node_bounds(&nodes[c])),
                [reference(children[0])?, reference(children[1])?],
            )?);
        }
    }
    if out.is_empty() {
        // The root is a leaf, or the tree is empty: one pair of the root and nothing.
        out.push(pair([node_bounds(&nodes[0]), Aabb::EMPTY], [reference(0)?, constants::NO_HIT])?);
    }
    Ok(out)
}

/// One pair: the children's boxes on a grid over their union, with their references.
fn pair(children: [Aabb; 2], refs: [u32; 2]) -> Result<BvhPair> {
    let union = children
        .iter()
        .zip(refs)
        .filter(|(_, r)| *r != constants::NO_HIT)
        .fold(Aabb::EMPTY, |u, (b, _)| u.union(*b));
    let lo = if union.is_empty() { Vec3::ZERO } else { union.lo };
    let mut origin = [0u32; 4];
    let mut boxes = [0u32; 4];
    for axis in 0..3 {
        let grid = grid_origin(lo[axis]).ok_or_else(|| {
            Error::InvalidArgument(format!(
                "a BVH box starts at {}, too near the largest f32 for the ray casting grid",
                lo[axis]
            ))
        })?;
        let (exponent, quantized) = quantize_axis(grid, &children.map(|b| (b.lo[axis], b.hi[axis])), refs);
        origin[axis] = grid.to_bits() | exponent;
        for (c, (q_lo, q_hi)) in quantized.into_iter().enumerate() {
            boxes[axis] |= q_lo << (16 * c) | q_hi << (16 * c + 8);
        }
    }
    origin[3] = refs[0];
    boxes[3] = refs[1];
    Ok(BvhPair { origin, boxes })
}

/// The largest f32 at or below `lo` whose lowest 8 mantissa bits are zero (they hold the grid
/// step's exponent); none past the most negative such f32.
fn grid_origin(lo: f32) -> Option<f32> {
    let truncated = f32::from_bits(lo.to_bits() & !0xff);
    // Truncating moves a negative value up: the next one down is a unit of the 9th bit away.
    let origin = if truncated <= lo { truncated } else { f32::from_bits((lo.to_bits() & !0xff) + 0x100) };
    origin.is_finite().then_some(origin)
}

/// The biased exponent of the finest grid step along one axis on which every live child's
/// extent (`lo`, `hi`) fits in 255 steps from `origin` and is enclosed by the f32 corners, and
/// each child's (min, max) in steps. An absent child gets (0, 0), never read.
fn quantize_axis(origin: f32, children: &[(f32, f32); 2], refs: [u32; 2]) -> (u32, [(u32, u32); 2]) {
    let extent = children
        .iter()
        .zip(refs)
        .filter(|(_, r)| *r != constants::NO_HIT)
        .map(|((_, hi), _)| f64::from(*hi) - f64::from(origin))
        .fold(0.0, f64::max);
    // The smallest normal step, else the step that spans the extent in 255.
    let mut exponent =
        if extent > 0.0 { ((extent / 255.0).log2().ceil() as i32 + 127).max(1) as u32 } else { 1 };
    loop {
        let step = f32::from_bits(exponent << 23);
        let corner = |q: u32| origin + q as f32 * step;
        let fit = |(lo, hi): (f32, f32)| -> Option<(u32, u32)> {
            let mut q_lo =
                ((f64::from(lo) - f64::from(origin)) / f64::from(step)).floor().clamp(0.0, 255.0) as u32;
            while q_lo > 0 && corner(q_lo) > lo {
                q_lo -= 1;
            }
            let mut q_hi =
                ((f64::from(hi) - f64::from(origin)) / f64::from(step)).ceil().clamp(0.0, 255.0) as u32;
            while q_hi < 255 && corner(q_hi) < hi {
                q_hi += 1;
            }
            (corner(q_lo) <= lo && corner(q_hi) >= hi).then_some((q_lo, q_hi))
        };
        let fitted: Option<Vec<(u32, u32)>> = children
            .iter()
            .zip(refs)
            .map(|(&c, r)| if r == constants::NO_HIT { Some((0, 0)) } else { fit(c) })
            .collect();
        match fitted {
            Some(q) => return (exponent, [q[0], q[1]]),
            None => exponent += 1,
        }
    }
}

/// A pair's child box `child` (0 or 1) as the shader dequantizes it.
#[cfg(test)]
pub fn child_box(pair: &BvhPair, child: usize) -> Aabb {
    let origin = Vec3::from_array(std::array::from_fn(|a| f32::from_bits(pair.origin[a] & !0xff)));
    let step = Vec3::from_array(std::array::from_fn(|a| f32::from_bits((pair.origin[a] & 0xff) << 23)));
    let corner = |c: usize| {
        let q = Vec3::from_array(std::array::from_fn(|a| ((pair.boxes[a] >> (8 * c)) & 0xff) as f32));
        origin + q * step
    };
    Aabb { lo: corner(2 * child), hi: corner(2 * child + 1) }
}

/// Where a pair's child `child` (0 or 1) leads.
#[cfg(test)]
fn child_reference(pair: &BvhPair, child: usize) -> u32 {
    [pair.origin[3], pair.boxes[3]][child]
}

#[cfg(test)]
mod tests {
    use super::super::sah;
    use super::*;

    /// Boxes of every size and place, including tiny ones far from the origin and flat ones.
    fn boxes(n: usize) -> Vec<Aabb> {
        let mut next = super::super::aabb::test_random(7);
        (0..n)
            .map(|i| {
                let scale = [1e-3, 1.0, 1e3][i % 3];
                let far = if i % 5 == 0 { 1e4 } else { 0.0 };
                let c = Vec3::new(next(), next(), next()) * scale + Vec3::splat(far);
                let mut half = Vec3::new(next(), next(), next()) * scale * [1e-4, 0.1][i % 2];
                if i % 7 == 0 {
                    half.y = 0.0;
                }
                Aabb { lo: c - half, hi: c + half }
            })
            .collect()
    }

    #[test]
    fn every_quantized_child_encloses_its_exact_box_and_leads_where_the_tree_does() {
        for n in [1, 2, 3, 50, 2000] {
            let input = boxes(n);
            let tree = sah::build(&input, 4);
            let pairs = pairs(&tree.nodes, 100, 10).unwrap();
            let root = 10;
            // Walk the pairs from the root and the tree from its root together.
            let mut stack = vec![(root, 0usize)];
            let mut leaves = 0;
            while let Some((pair_index, node)) = stack.pop() {
                let pair = &pairs[(pair_index - 10) as usize];
                let (index, count) = node_range(&tree.nodes[node]);
                let children: Vec<usize> =
                    if count == 0 { vec![index as usize, index as usize + 1] } else { vec![node] };
                for (c, &child) in children.iter().enumerate() {
                    let exact = node_bounds(&tree.nodes[child]);
                    let quantized = child_box(pair, c);
                    assert!(quantized.contains(&exact), "{n} boxes: {quantized:?} does not hold {exact:?}");
                    // No looser than a grid step on each side: a step is the power of two at or
                    // above 1/255 of the pair's box, so at most 2/255 of it per side (or a few f32
                    // steps of the coordinates, 1e4 at most here, where those are coarser).
                    let slack = (quantized.hi - quantized.lo) - (exact.hi - exact.lo);
                    let span = node_bounds(&tree.nodes[node]).hi - node_bounds(&tree.nodes[node]).lo;
                    assert!(
                        slack.cmple(span * (4.0 / 255.0) + Vec3::splat(1e-2)).all(),
                        "{slack} over {span}"
                    );
                    let reference = child_reference(pair, c);
                    let (child_index, child_count) = node_range(&tree.nodes[child]);
                    if child_count > 0 {
                        assert_eq!(reference, constants::BVH_LEAF | child_count << 28 | (100 + child_index));
                        leaves += child_count;
                    } else {
                        stack.push((reference, child));
                    }
                }
                if count > 0 {
                    assert_eq!(child_reference(pair, 1), constants::NO_HIT);
                }
            }
            assert_eq!(leaves as usize, n, "every primitive in one leaf reached from the root");
        }
    }

    #[test]
    fn the_grid_origin_is_at_or_just_below_the_box_and_leaves_its_low_byte_free() {
        let values =
            [0.0f32, -0.0, 1.0, -1.0, 1.000_001, -1.000_001, 3.3e-39, -3.3e-39, 10_000.37, -10_000.37];
        for lo in values {
            let origin = grid_origin(lo).unwrap();
            assert!(origin <= lo, "{origin} above {lo}");
            assert_eq!(origin.to_bits() & 0xff, 0, "{origin} for {lo}");
            // One unit of the 9th mantissa bit at most: 2^-15 of the value (or of the smallest normal).
            let gap = f64::from(lo) - f64::from(origin);
            assert!(gap <= f64::from(lo.abs().max(f32::MIN_POSITIVE)) * 2f64.powi(-15), "{origin} for {lo}");
        }
        assert_eq!(grid_origin(f32::MIN), None, "no f32 below the most negative one");
    }

    #[test]
    fn an_empty_tree_has_one_pair_of_no_children() {
        let tree = sah::build(&[], 4);
        let pairs = pairs(&tree.nodes, 0, 3).unwrap();
        assert_eq!(pairs.len(), 1);
        assert_eq!([0, 1].map(|c| child_reference(&pairs[0], c)), [constants::NO_HIT; 2]);
    }
}
