//! Vertices buried inside their own mesh. Modelled objects are often unions of closed parts
//! that pierce each other (a teapot's spout and handle reach into its body); a vertex of the
//! spout inside the body sees nothing, so its transfer is zero, and the rasterizer spreads that
//! zero over every visible triangle it shares: dark, blocky patches on a lit surface.
//!
//! The transfer shader counts the rays whose closest hit is the back of a surface. A vertex is
//! buried when at least [`BURIED_SHARE`] of its rays end so: a point inside a closed surface
//! sees only its inside, while a point in a deep crease or under a lid's rim still sees some
//! front faces (the Utah teapot's rim and handle joints reach 60–89 %, its buried vertices
//! 95–100 %). A buried vertex takes the mean transfer of its mesh neighbours that are not
//! buried, ring by ring inwards; a wholly buried part (one with no such neighbour) keeps its
//! own, as nothing shows it.
use super::{mesh_layout, PrtParams};
use crate::scene::Scene;

/// Smallest share of a vertex's rays ending on a back face for it to count as buried.
pub const BURIED_SHARE: f64 = 0.95;

/// Fills the transfer of every buried vertex of `scene` (`coefficients` in scene order, as the
/// shader wrote them).
pub(crate) fn fill(scene: &Scene, params: PrtParams, back_hits: &[u32], coefficients: &mut [f32]) {
    let n = params.coeffs();
    let threshold = BURIED_SHARE * f64::from(params.rays);
    let mut first = 0;
    for ((_, mesh), (_, _, vertices)) in scene.meshes().zip(mesh_layout(scene)) {
        let buried: Vec<bool> =
            back_hits[first..first + vertices].iter().map(|&b| f64::from(b) >= threshold).collect();
        fill_mesh(&mesh.indices, &buried, &mut coefficients[first * n..(first + vertices) * n], n);
        first += vertices;
    }
}

/// One mesh: `coefficients` holds `n` per vertex. Each round gives every buried vertex with a
/// known neighbour the mean of those neighbours, then counts it known (so the result does not
/// depend on the vertex order).
fn fill_mesh(indices: &[u32], buried: &[bool], coefficients: &mut [f32], n: usize) -> usize {
    let mut neighbours = vec![Vec::new(); buried.len()];
    for tri in indices.chunks_exact(3) {
        for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
            neighbours[a as usize].push(b as usize);
            neighbours[b as usize].push(a as usize);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let mut known: Vec<bool> = buried.iter().map(|b| !b).collect();
    let mut filled = 0;
    loop {
        let round: Vec<(usize, Vec<f32>)> = (0..buried.len())
            .filter(|&v| !known[v])
            .filter_map(|v| {
                let from: Vec<usize> = neighbours[v].iter().copied().filter(|&u| known[u]).collect();
                (!from.is_empty()).then(|| {
                    let mut mean = vec![0.0; n];
                    for &u in &from {
                        for (m, c) in mean.iter_mut().zip(&coefficients[u * n..(u + 1) * n]) {
                            *m += c / from.len() as f32;
                        }
                    }
                    (v, mean)
                })
            })
            .collect();
        if round.is_empty() {
            return filled;
        }
        filled += round.len();
        for (v, mean) in round {
            coefficients[v * n..(v + 1) * n].copy_from_slice(&mean);
            known[v] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buried_vertices_take_their_known_neighbours_ring_by_ring() {
        // A strip (0,1,2), (1,2,3), (2,3,4), (3,4,5); 3, 4 and 5 buried, one coefficient each.
        let indices = [0, 1, 2, 1, 2, 3, 2, 3, 4, 3, 4, 5];
        let buried = [false, false, false, true, true, true];
        let mut c = [1.0, 2.0, 3.0, 0.0, 0.0, 0.0];
        assert_eq!(fill_mesh(&indices, &buried, &mut c, 1), 3);
        // First ring: 3 from 1 and 2 (each once, though edge 1-2 and 2-3 are shared), 4 from
        // 2; then 5 from 3 and 4, filled in the round before.
        assert_eq!(c, [1.0, 2.0, 3.0, 2.5, 3.0, 2.75]);
    }

    #[test]
    fn a_wholly_buried_part_keeps_its_own_transfer() {
        let indices = [0, 1, 2, 3, 4, 5];
        let buried = [false, false, false, true, true, true];
        let mut c = [1.0, 1.0, 1.0, 0.0, 0.1, 0.2];
        assert_eq!(fill_mesh(&indices, &buried, &mut c, 1), 0);
        assert_eq!(c, [1.0, 1.0, 1.0, 0.0, 0.1, 0.2]);
    }
}
