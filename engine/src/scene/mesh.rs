//! Triangle meshes: validation, vertex normals, and the vertex order every mesh is kept in.
use glam::Vec3;

use super::SceneError;

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
}

impl Mesh {
    /// Validates the data and brings it into the canonical vertex order. Without `normals` (or
    /// with normals that do not match the positions one to one), area-weighted vertex normals
    /// are computed.
    pub fn new(
        name: impl Into<String>,
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
        albedo: [f32; 3],
    ) -> Result<Mesh, SceneError> {
        let name = name.into();
        check_geometry(&name, &positions, &indices, albedo)?;
        let normals = match normals {
            Some(normals) if normals.len() == positions.len() => unit_normals(&name, normals)?,
            _ => area_weighted_normals(&positions, &indices),
        };
        let (positions, normals, indices) = in_first_use_order(positions, normals, indices);
        Ok(Mesh { name, positions, normals, indices, albedo })
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
        self.normals.iter().enumerate().try_for_each(|(at, n)| checked_normal(name, at, *n).map(|_| ()))
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

fn unit_normals(name: &str, normals: Vec<[f32; 3]>) -> Result<Vec<[f32; 3]>, SceneError> {
    normals
        .into_iter()
        .enumerate()
        .map(|(at, n)| {
            let v = checked_normal(name, at, n)?;
            // Already-unit normals stay bit-identical (see `Mesh`'s round-trip promise).
            Ok(if v.is_normalized() { n } else { v.normalize().to_array() })
        })
        .collect()
}

/// Sums each triangle's unnormalized face normal (length = twice its area) into its vertices.
/// A vertex whose sum is zero (only degenerate triangles, or normals that cancel) gets +Y: any
/// unit vector is as good as another there, and NaN is not.
pub(crate) fn area_weighted_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| Vec3::from(positions[i as usize]));
        let face = (b - a).cross(c - a);
        for &i in tri {
            sums[i as usize] += face;
        }
    }
    sums.into_iter().map(|n| n.try_normalize().unwrap_or(Vec3::Y).to_array()).collect()
}

fn in_first_use_order(
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>) {
    let mut new_index = vec![u32::MAX; positions.len()];
    let mut ordered_positions = Vec::with_capacity(positions.len());
    let mut ordered_normals = Vec::with_capacity(positions.len());
    let indices = indices
        .into_iter()
        .map(|old| {
            let slot = &mut new_index[old as usize];
            if *slot == u32::MAX {
                *slot = ordered_positions.len() as u32;
                ordered_positions.push(positions[old as usize]);
                ordered_normals.push(normals[old as usize]);
            }
            *slot
        })
        .collect();
    (ordered_positions, ordered_normals, indices)
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
        let zero_normal = Mesh::new("m", tri(), Some(vec![[0.0; 3]; 3]), vec![0, 1, 2], [0.5; 3]);
        assert!(zero_normal.unwrap_err().to_string().contains("normal"));
    }
}
