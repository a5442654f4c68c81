//! Triangle meshes: validation, vertex normals, and the vertex order every mesh is kept in.
use glam::Vec3;

use super::albedo_map::Texturing;
use super::SceneError;
use crate::host_memory::{self, OutOfHostMemory};

/// The most vertices one mesh may have: the GPU holds 32 bytes a vertex (position, normal,
/// texture coordinate) in buffers that shaders address with 32-bit offsets, at most 4 GiB.
pub const MAX_MESH_VERTICES: usize = u32::MAX as usize / 32;

/// The most triangles a scene may have: the ray tracer's BVH names a triangle in 28 bits.
pub const MAX_TRIANGLES: usize = 1 << 28;

/// Refuses a mesh of more than [`MAX_MESH_VERTICES`] vertices, before they are allocated.
pub fn check_vertex_count(vertices: usize) -> Result<(), SceneError> {
    if vertices > MAX_MESH_VERTICES {
        return Err(SceneError::invalid(format!(
            "{vertices} vertices, more than the {MAX_MESH_VERTICES} a mesh may have (32 bytes each on \
             the GPU, in buffers of at most 4 GiB)"
        )));
    }
    Ok(())
}

/// Refuses more indices than [`MAX_TRIANGLES`] triangles take (in a mesh, or a whole scene),
/// before they are allocated.
pub fn check_index_count(indices: usize) -> Result<(), SceneError> {
    if indices / 3 > MAX_TRIANGLES {
        return Err(SceneError::invalid(format!(
            "{indices} indices ({} triangles), more than the {MAX_TRIANGLES} triangles a scene may \
             have (its ray tracer names a triangle in 28 bits)",
            indices / 3
        )));
    }
    Ok(())
}

/// An indexed triangle mesh in object space with one diffuse albedo.
///
/// Meshes built by [`Mesh::new`] hold their vertices in the order the triangles first use them,
/// with no unused vertex. That is the order tobj's single-index OBJ loading produces, so a mesh
/// written as OBJ and read back comes out identical.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    /// Unit length, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Three per triangle, counter-clockwise seen from the side the normals point to.
    pub indices: Vec<u32>,
    /// Diffuse reflectance per channel, in [0, 1].
    pub albedo: [f32; 3],
    /// A texture the albedo is multiplied by per pixel, with a texture coordinate per
    /// position; `None` for one albedo over the whole mesh.
    pub texturing: Option<Texturing>,
}

impl Mesh {
    /// Validates the data and brings it into the canonical vertex order. Without `normals` (or
    /// with normals that do not match the positions one to one), area-weighted vertex normals
    /// are computed.
    ///
    /// Given normals are kept (normalized) where they are finite and non-zero. A zero or
    /// non-finite one (scanned meshes carry a few: the Stanford bunny users bring has a
    /// `vn 0 0 0`) is repaired rather than refused: that vertex gets the area-weighted normal of
    /// its faces, and a note on stderr names the mesh and how many were repaired. Where that
    /// normal is zero too (the vertex's faces are all degenerate, or their normals cancel) it
    /// gets +Y, like any computed normal there: a unit vector as good as another, and never NaN.
    /// [`Mesh::new_reporting`] does the same without the note.
    pub fn new(
        name: impl Into<String>,
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
        albedo: [f32; 3],
    ) -> Result<Mesh, SceneError> {
        noted(Mesh::build(name.into(), positions, normals, indices, albedo, None)?)
    }

    /// [`Mesh::new`] with an albedo map and its texture coordinates (one per position, finite).
    pub fn new_textured(
        name: impl Into<String>,
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
        albedo: [f32; 3],
        texturing: Texturing,
    ) -> Result<Mesh, SceneError> {
        noted(Mesh::build(name.into(), positions, normals, indices, albedo, Some(texturing))?)
    }

    /// [`Mesh::new`] without its note: the mesh and how many of the given normals were zero or
    /// not finite and were recomputed from the faces (0 without given normals).
    pub fn new_reporting(
        name: impl Into<String>,
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
        albedo: [f32; 3],
    ) -> Result<(Mesh, usize), SceneError> {
        Mesh::build(name.into(), positions, normals, indices, albedo, None)
    }

    fn build(
        name: String,
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
        albedo: [f32; 3],
        texturing: Option<Texturing>,
    ) -> Result<(Mesh, usize), SceneError> {
        check_geometry(&name, &positions, &indices, albedo)?;
        if let Some(t) = &texturing {
            check_uvs(&name, &t.uvs, positions.len())?;
        }
        let in_mesh = |e: OutOfHostMemory| SceneError::from(e).within(&format!("mesh \"{name}\""));
        let (normals, repaired) = match normals {
            Some(normals) if normals.len() == positions.len() => {
                repaired_normals(normals, &positions, &indices)
            }
            _ => (area_weighted_normals(&positions, &indices), 0),
        };
        let normals = normals.map_err(in_mesh)?;
        let (order, indices) = first_use_order(positions.len(), &indices).map_err(in_mesh)?;
        let texturing = match texturing {
            Some(t) => Some(Texturing {
                uvs: reordered(&t.uvs, &order, "texture coordinates").map_err(in_mesh)?,
                ..t
            }),
            None => None,
        };
        let mesh = Mesh {
            positions: reordered(&positions, &order, "positions").map_err(in_mesh)?,
            normals: reordered(&normals, &order, "normals").map_err(in_mesh)?,
            name,
            indices,
            albedo,
            texturing,
        };
        Ok((mesh, repaired))
    }

    /// Checks what [`Mesh::new`] guarantees, for a mesh whose public fields were filled or
    /// changed by hand: triangles, indices in range, finite positions, one finite non-zero
    /// normal per position, albedo in [0, 1]. The error names the mesh and the first fault.
    pub fn validate(&self) -> Result<(), SceneError> {
        let name = &self.name;
        check_geometry(name, &self.positions, &self.indices, self.albedo)?;
        if self.normals.len() != self.positions.len() {
            return Err(SceneError::invalid(format!(
                "mesh \"{name}\" has {} normals for {} positions",
                self.normals.len(),
                self.positions.len()
            )));
        }
        self.normals.iter().enumerate().try_for_each(|(at, n)| checked_normal(name, at, *n).map(|_| ()))?;
        match &self.texturing {
            Some(t) => check_uvs(name, &t.uvs, self.positions.len()),
            None => Ok(()),
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The longest edge of any triangle (object units): every point of a triangle lies within
    /// it of each of the triangle's corners.
    pub fn longest_edge(&self) -> f32 {
        let at = |i: u32| Vec3::from(self.positions[i as usize]);
        self.indices
            .chunks_exact(3)
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| at(a).distance(at(b)))
            .fold(0.0, f32::max)
    }
}

/// The checks of [`Mesh::new`] and [`Mesh::validate`] that do not involve normals.
fn check_geometry(
    name: &str,
    positions: &[[f32; 3]],
    indices: &[u32],
    albedo: [f32; 3],
) -> Result<(), SceneError> {
    let counted = |e: SceneError| e.within(&format!("mesh \"{name}\""));
    check_vertex_count(positions.len()).map_err(counted)?;
    check_index_count(indices.len()).map_err(counted)?;
    if indices.is_empty() {
        return Err(SceneError::invalid(format!("mesh \"{name}\" is empty: it has no triangles")));
    }
    if indices.len() % 3 != 0 {
        return Err(SceneError::invalid(format!(
            "mesh \"{name}\" has {} indices, not a whole number of triangles",
            indices.len()
        )));
    }
    if let Some((at, index)) = indices.iter().enumerate().find(|(_, i)| **i as usize >= positions.len()) {
        return Err(SceneError::invalid(format!(
            "mesh \"{name}\": triangle {} uses vertex index {index}, out of range for {} vertices",
            at / 3,
            positions.len()
        )));
    }
    if let Some((at, p)) = positions.iter().enumerate().find(|(_, p)| p.iter().any(|c| !c.is_finite())) {
        return Err(SceneError::invalid(format!("mesh \"{name}\": vertex {at} is NaN or infinite: {p:?}")));
    }
    if albedo.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(SceneError::invalid(format!("mesh \"{name}\": albedo {albedo:?} is outside [0, 1]")));
    }
    Ok(())
}

fn checked_normal(name: &str, at: usize, n: [f32; 3]) -> Result<Vec3, SceneError> {
    let v = Vec3::from(n);
    if !v.is_finite() || v.length_squared() == 0.0 {
        return Err(SceneError::invalid(format!(
            "mesh \"{name}\": normal {at} is {n:?}; normals must be finite and non-zero"
        )));
    }
    Ok(v)
}

/// The given normals, normalized, with each zero or non-finite one replaced by the vertex's
/// area-weighted normal; and how many were replaced.
fn repaired_normals(
    mut normals: Vec<[f32; 3]>,
    positions: &[[f32; 3]],
    indices: &[u32],
) -> (Result<Vec<[f32; 3]>, OutOfHostMemory>, usize) {
    let unit = |n: [f32; 3]| {
        let v = Vec3::from(n);
        // Scaled to its largest component first, so that no finite non-zero normal over- or
        // underflows on the way to unit length.
        let largest = v.abs().max_element();
        (v.is_finite() && largest > 0.0).then(|| (v / largest).normalize())
    };
    let repaired = normals.iter().filter(|n| unit(**n).is_none()).count();
    let computed = match (repaired > 0).then(|| area_weighted_normals(positions, indices)).transpose() {
        Ok(computed) => computed,
        Err(e) => return (Err(e), repaired),
    };
    for (at, n) in normals.iter_mut().enumerate() {
        *n = match unit(*n) {
            // Already-unit normals stay bit-identical (see `Mesh`'s round-trip promise).
            Some(_) if Vec3::from(*n).is_normalized() => *n,
            Some(v) => v.to_array(),
            None => computed.as_ref().map_or([0.0, 1.0, 0.0], |c| c[at]),
        };
    }
    (Ok(normals), repaired)
}

/// Sums each triangle's unnormalized face normal (length = twice its area) into its vertices.
/// A vertex whose sum is zero (only degenerate triangles, or normals that cancel) gets +Y: any
/// unit vector is as good as another there, and NaN is not.
pub(crate) fn area_weighted_normals(
    positions: &[[f32; 3]],
    indices: &[u32],
) -> Result<Vec<[f32; 3]>, OutOfHostMemory> {
    let mut sums = host_memory::filled([0.0; 3], positions.len(), "vertex normals")?;
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| Vec3::from(positions[i as usize]));
        let face = (b - a).cross(c - a);
        for &i in tri {
            let sum = &mut sums[i as usize];
            *sum = (Vec3::from(*sum) + face).to_array();
        }
    }
    for n in &mut sums {
        *n = Vec3::from(*n).try_normalize().unwrap_or(Vec3::Y).to_array();
    }
    Ok(sums)
}

/// The note [`Mesh::new`] prints where normals were repaired.
fn noted((mesh, repaired): (Mesh, usize)) -> Result<Mesh, SceneError> {
    if repaired > 0 {
        eprintln!(
            "kage: note: mesh \"{}\": {repaired} normal(s) were zero or not finite; recomputed from the faces around them",
            mesh.name
        );
    }
    Ok(mesh)
}

/// One finite texture coordinate per position.
fn check_uvs(name: &str, uvs: &[[f32; 2]], positions: usize) -> Result<(), SceneError> {
    if uvs.len() != positions {
        return Err(SceneError::invalid(format!(
            "mesh \"{name}\" has {} texture coordinates for {positions} positions",
            uvs.len()
        )));
    }
    match uvs.iter().position(|uv| !uv[0].is_finite() || !uv[1].is_finite()) {
        Some(at) => Err(SceneError::invalid(format!(
            "mesh \"{name}\": texture coordinate {at} is NaN or infinite: {:?}",
            uvs[at]
        ))),
        None => Ok(()),
    }
}

/// The old index of each vertex in the order the triangles first use them (unused ones
/// dropped), and the indices renumbered to that order.
fn first_use_order(vertex_count: usize, indices: &[u32]) -> Result<(Vec<u32>, Vec<u32>), OutOfHostMemory> {
    let mut new_index = host_memory::filled(u32::MAX, vertex_count, "the vertex order")?;
    let mut order = host_memory::with_room(vertex_count, "the vertex order")?;
    let indices = host_memory::collect(
        indices.iter().map(|&old| {
            let slot = &mut new_index[old as usize];
            if *slot == u32::MAX {
                *slot = order.len() as u32;
                // Within the room reserved: each vertex is pushed once.
                order.push(old);
            }
            *slot
        }),
        "indices",
    )?;
    Ok((order, indices))
}

fn reordered<T: Copy>(items: &[T], order: &[u32], what: &str) -> Result<Vec<T>, OutOfHostMemory> {
    host_memory::collect(order.iter().map(|&old| items[old as usize]), what)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertices_are_reordered_by_first_use_and_unused_ones_dropped() {
        let positions = vec![[9.0, 9.0, 9.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let mesh = Mesh::new("t", positions, None, vec![3, 1, 2], [0.5; 3]).unwrap();
        assert_eq!(mesh.positions, vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]);
        assert_eq!(mesh.indices, vec![0, 1, 2]);
        assert_eq!(mesh.normals, vec![[0.0, 1.0, 0.0]; 3]);
    }

    #[test]
    fn degenerate_triangles_get_unit_normals() {
        let mesh = Mesh::new("t", vec![[1.0, 2.0, 3.0]; 3], None, vec![0, 1, 2], [0.5; 3]).unwrap();
        for n in mesh.normals {
            assert!((Vec3::from(n).length() - 1.0).abs() < 1e-6);
        }
    }

    /// Counts beyond what the GPU buffers and the BVH hold are refused by the count alone,
    /// naming it and the limit, so that a caller can refuse them before allocating.
    #[test]
    fn counts_beyond_the_limits_are_refused_before_allocation() {
        assert!(check_vertex_count(MAX_MESH_VERTICES).is_ok());
        let vertices = check_vertex_count(u32::MAX as usize).unwrap_err().to_string();
        assert!(vertices.contains("4294967295 vertices") && vertices.contains("134217727"), "{vertices}");
        assert!(check_index_count(3 * MAX_TRIANGLES + 2).is_ok());
        let indices = check_index_count(3 * MAX_TRIANGLES + 3).unwrap_err().to_string();
        assert!(indices.contains("805306371 indices") && indices.contains("268435456"), "{indices}");
    }

    #[test]
    fn bad_meshes_are_rejected() {
        let tri = || vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let err = |positions, indices, albedo| {
            Mesh::new("m", positions, None, indices, albedo).unwrap_err().to_string()
        };
        assert!(err(tri(), vec![], [0.5; 3]).contains("empty"));
        assert!(err(tri(), vec![0, 1], [0.5; 3]).contains("whole number"));
        assert!(err(tri(), vec![0, 1, 3], [0.5; 3]).contains("out of range"));
        assert!(err(vec![[0.0, f32::NAN, 0.0]; 3], vec![0, 1, 2], [0.5; 3]).contains("NaN"));
        assert!(err(tri(), vec![0, 1, 2], [1.5, 0.5, 0.5]).contains("albedo"));
    }

    /// A zero, NaN or infinite given normal is recomputed from the vertex's faces (area-weighted)
    /// and counted; the good ones are kept, unit ones bit for bit, others normalized.
    #[test]
    fn zero_and_non_finite_normals_are_recomputed_from_the_faces() {
        // Two triangles folded along the edge 0-1: vertex 0's faces face +Y and +Z.
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 2.0, 0.0]];
        let indices = vec![0, 1, 2, 0, 1, 3];
        let given = vec![[0.0; 3], [f32::NAN, 0.0, 1.0], [0.0, 3.0, 0.0], [0.6, 0.0, 0.8]];
        let (mesh, repaired) =
            Mesh::new_reporting("m", positions.clone(), Some(given), indices.clone(), [0.5; 3]).unwrap();
        assert_eq!(repaired, 2);
        let computed = area_weighted_normals(&positions, &indices).unwrap();
        assert_eq!(mesh.normals, vec![computed[0], computed[1], [0.0, 1.0, 0.0], [0.6, 0.0, 0.8]]);
        // Areas 0.5 (+Y) and 1 (+Z): the repaired normal leans to the larger face.
        let expected = Vec3::new(0.0, 1.0, 2.0).normalize();
        assert!(Vec3::from(mesh.normals[0]).distance(expected) < 1e-6, "{:?}", mesh.normals[0]);
        mesh.validate().unwrap();

        let infinite = vec![[f32::INFINITY, 0.0, 0.0]; 4];
        let (_, repaired) = Mesh::new_reporting("m", positions, Some(infinite), indices, [0.5; 3]).unwrap();
        assert_eq!(repaired, 4);
    }

    /// Tiny and huge finite normals are directions like any other: normalized, not repaired.
    #[test]
    fn extreme_finite_normals_are_normalized() {
        let tri = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
        let given = vec![[0.0, 1e-30, 0.0], [0.0, 3e38, 3e38], [1e-45, 0.0, 0.0]];
        let (mesh, repaired) = Mesh::new_reporting("m", tri, Some(given), vec![0, 1, 2], [0.5; 3]).unwrap();
        assert_eq!(repaired, 0);
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert_eq!(mesh.normals[0], [0.0, 1.0, 0.0]);
        assert!(Vec3::from(mesh.normals[1]).distance(Vec3::new(0.0, h, h)) < 1e-6);
        assert_eq!(mesh.normals[2], [1.0, 0.0, 0.0]);
    }

    /// A bad normal at a vertex whose faces are all degenerate has no face normal to take: it
    /// gets +Y, as a computed normal there does.
    #[test]
    fn a_bad_normal_among_degenerate_faces_gets_plus_y() {
        let (mesh, repaired) = Mesh::new_reporting(
            "m",
            vec![[1.0, 2.0, 3.0]; 3],
            Some(vec![[0.0; 3]; 3]),
            vec![0, 1, 2],
            [0.5; 3],
        )
        .unwrap();
        assert_eq!(repaired, 3);
        assert_eq!(mesh.normals, vec![[0.0, 1.0, 0.0]; 3]);
    }

    /// Hand-filled meshes are checked, not repaired: `validate` still refuses a zero normal.
    #[test]
    fn validate_refuses_a_zero_normal() {
        let mut mesh =
            Mesh::new("m", vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]], None, vec![0, 1, 2], [0.5; 3])
                .unwrap();
        mesh.normals[1] = [0.0; 3];
        let error = mesh.validate().unwrap_err().to_string();
        assert!(error.contains("normal 1") && error.contains("non-zero"), "{error}");
    }
}
