//! The insertion order: a biased randomized insertion order (BRIO, Amenta, Choi & Rote 2003) whose
//! rounds are sorted along a Hilbert curve. Consecutive points are then close, so each walk from
//! the last new tetrahedron is short, while the random rounds keep the expected work of
//! randomized incremental construction.
use super::rng::XorShift;
use glam::DVec3;

/// Bits per axis of the Hilbert keys.
const BITS: u32 = 16;
/// Rounds shorter than this are not split further.
const SMALLEST_ROUND: usize = 64;

/// A permutation of `0..points.len()`: rounds of doubling size, each along a Hilbert curve.
pub fn insertion_order(points: &[DVec3]) -> Vec<u32> {
    let keys = hilbert_keys(points);
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    let mut rng = XorShift::new(0x9e37_79b9);
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i as u32 + 1) as usize);
    }
    let mut end = order.len();
    while end > 0 {
        let start = if end > SMALLEST_ROUND { end / 2 } else { 0 };
        order[start..end].sort_unstable_by_key(|&i| keys[i as usize]);
        end = start;
    }
    order
}

/// Each point's position along a Hilbert curve through its bounding box (scaled to a cube per
/// axis, so flat sets still spread over the curve).
fn hilbert_keys(points: &[DVec3]) -> Vec<u64> {
    let lo = points.iter().fold(DVec3::INFINITY, |m, &p| m.min(p));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |m, &p| m.max(p));
    let cells = ((1u32 << BITS) - 1) as f64;
    let scale = (hi - lo).map(|e| if e > 0.0 { cells / e } else { 0.0 });
    points
        .iter()
        .map(|&p| {
            let q = ((p - lo) * scale).round();
            hilbert_key([q.x as u32, q.y as u32, q.z as u32])
        })
        .collect()
}

/// Skilling's transform ("Programming the Hilbert curve", 2004): axes to the transposed Hilbert
/// index, then the index's bits interleaved into one key.
fn hilbert_key(mut x: [u32; 3]) -> u64 {
    let mut q = 1u32 << (BITS - 1);
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= p;
            } else {
                let t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    x[1] ^= x[0];
    x[2] ^= x[1];
    let mut t = 0;
    q = 1 << (BITS - 1);
    while q > 1 {
        if x[2] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    let mut key = 0u64;
    for b in (0..BITS).rev() {
        for axis in x {
            key = (key << 1) | ((axis ^ t) >> b & 1) as u64;
        }
    }
    key
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Consecutive keys along the curve are cells that share a face: the Hilbert property.
    #[test]
    fn hilbert_keys_walk_neighbouring_cells() {
        let mut cells: Vec<([u32; 3], u64)> = Vec::new();
        for x in 0..4u32 {
            for y in 0..4u32 {
                for z in 0..4u32 {
                    let c = [x << (BITS - 2), y << (BITS - 2), z << (BITS - 2)];
                    cells.push(([x, y, z], hilbert_key(c)));
                }
            }
        }
        cells.sort_by_key(|c| c.1);
        for pair in cells.windows(2) {
            let d: u32 = (0..3).map(|i| pair[0].0[i].abs_diff(pair[1].0[i])).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", pair[0].0, pair[1].0);
        }
    }

    #[test]
    fn the_order_is_a_permutation() {
        let points: Vec<DVec3> = (0..1000).map(|i| DVec3::new(i as f64, (i * 7 % 13) as f64, 0.5)).collect();
        let mut order = insertion_order(&points);
        order.sort_unstable();
        assert!(order.iter().enumerate().all(|(i, &o)| i as u32 == o));
    }
}
