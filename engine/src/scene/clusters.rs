//! Triangle clusters: a mesh's triangles reordered along a Morton curve of their centroids and
//! cut into runs of [`CLUSTER_TRIANGLES`], each with its bounds, so that a draw that sees only
//! part of space (an adaptive shadow map tile, a few thousandths of the light's view) can skip
//! the runs outside it. Mesh files keep no spatial order (the bunny's 128-triangle runs span
//! its whole box), so the runs are made here.
use super::Mesh;
use glam::Vec3;

/// Triangles per cluster (the last one of a mesh may have fewer).
pub const CLUSTER_TRIANGLES: usize = 64;

/// A run of a clustered index list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cluster {
    /// First index of the run (three per triangle).
    pub first: u32,
    /// Indices in the run.
    pub count: u32,
    /// Object-space bounds of its triangles.
    pub min: Vec3,
    pub max: Vec3,
}

/// `mesh`'s triangles in cluster order (its index list, reordered; the same triangles and
/// windings), and the clusters.
pub fn clustered(mesh: &Mesh) -> (Vec<u32>, Vec<Cluster>) {
    let corner = |t: &[u32], k: usize| Vec3::from(mesh.positions[t[k] as usize]);
    let (lo, hi) = mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p)))
    });
    let extent = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
    let mut triangles: Vec<(u32, &[u32])> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            let centroid = (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3.0;
            (morton((centroid - lo) / extent), t)
        })
        .collect();
    // Stable: equal codes keep the file's order.
    triangles.sort_by_key(|&(code, _)| code);
    let indices: Vec<u32> = triangles.iter().flat_map(|(_, t)| t.iter().copied()).collect();
    let clusters = indices
        .chunks(3 * CLUSTER_TRIANGLES)
        .enumerate()
        .map(|(i, run)| {
            let (min, max) = run.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| {
                let p = Vec3::from(mesh.positions[v as usize]);
                (lo.min(p), hi.max(p))
            });
            Cluster { first: (i * 3 * CLUSTER_TRIANGLES) as u32, count: run.len() as u32, min, max }
        })
        .collect();
    (indices, clusters)
}

/// The Morton code of a point of the unit cube: 10 bits per axis, interleaved.
fn morton(p: Vec3) -> u32 {
    let spread = |c: f32| {
        let mut x = (c.clamp(0.0, 1.0) * 1023.0) as u32;
        x = (x | x << 16) & 0x0300_00ff;
        x = (x | x << 8) & 0x0300_f00f;
        x = (x | x << 4) & 0x030c_30c3;
        (x | x << 2) & 0x0924_9249
    };
    spread(p.x) | spread(p.y) << 1 | spread(p.z) << 2
}

/// The index runs of `clusters` (in buffer order), neighbours merged: (first index, count).
pub fn runs<'a>(clusters: impl IntoIterator<Item = &'a Cluster>) -> Vec<(u32, u32)> {
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for c in clusters {
        match runs.last_mut() {
            Some(last) if last.0 + last.1 == c.first => last.1 += c.count,
            _ => runs.push((c.first, c.count)),
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shapes;

    /// The clusters hold every triangle once, with its winding, and bound their triangles; on a
    /// finely meshed plane each is a small part of it.
    #[test]
    fn clusters_keep_every_triangle_and_bound_a_small_part_of_the_mesh() {
        let mesh = shapes::plane("floor", [8.0, 8.0], [32, 32], [0.5; 3]).unwrap();
        let (indices, clusters) = clustered(&mesh);
        let key = |t: &[u32]| {
            // A triangle as its rotation starting at its smallest index (winding kept).
            let m = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
        };
        let mut before: Vec<[u32; 3]> = mesh.indices.chunks_exact(3).map(key).collect();
        let mut after: Vec<[u32; 3]> = indices.chunks_exact(3).map(key).collect();
        before.sort_unstable();
        after.sort_unstable();
        assert_eq!(before, after);
        assert_eq!(clusters.iter().map(|c| c.count).sum::<u32>() as usize, indices.len());
        let mut sides: Vec<f32> = Vec::new();
        for c in &clusters {
            for &v in &indices[c.first as usize..(c.first + c.count) as usize] {
                let p = Vec3::from(mesh.positions[v as usize]);
                assert!(p.cmpge(c.min).all() && p.cmple(c.max).all());
            }
            sides.push((c.max - c.min).max_element());
        }
        // 64 of 1922 triangles: runs in the plane's index order (row by row) span all 8 of its
        // width; most of a Morton curve's runs stay within a few of its quads (one that crosses
        // a coarse cell's border reaches further).
        sides.sort_by(f32::total_cmp);
        let median = sides[sides.len() / 2];
        assert!(median <= 8.0 / 3.0, "clusters span {median} of the plane's 8 (median)");
    }
}
