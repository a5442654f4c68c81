//! Generated meshes: a floor grid, a UV sphere and sets of boxes, counter-clockwise seen from
//! outside.
use std::f32::consts::{PI, TAU};

use glam::Vec3;

use super::{Mesh, SceneError};

/// Upper bound on grid vertices per side and sphere segments: far beyond any scene Kage renders,
/// low enough that a typo cannot ask for gigabytes.
pub const MAX_RESOLUTION: u32 = 4096;

/// A grid in the XZ plane centred at the origin, normal +Y. `size` is the extent along X and Z,
/// `vertices` the number of grid vertices along X and Z (at least 2 each).
pub fn plane(name: &str, size: [f32; 2], vertices: [u32; 2], albedo: [f32; 3]) -> Result<Mesh, SceneError> {
    if size.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(SceneError::invalid(format!("plane size {size:?} must be finite and greater than zero")));
    }
    if vertices.iter().any(|n| !(2..=MAX_RESOLUTION).contains(n)) {
        return Err(SceneError::invalid(format!(
            "plane vertices {vertices:?} must be between 2 and {MAX_RESOLUTION} along each side"
        )));
    }
    let [nx, nz] = vertices;
    let coordinate = |i: u32, n: u32, extent: f32| (i as f32 / (n - 1) as f32 - 0.5) * extent;
    let mut positions = Vec::with_capacity((nx * nz) as usize);
    for k in 0..nz {
        for i in 0..nx {
            positions.push([coordinate(i, nx, size[0]), 0.0, coordinate(k, nz, size[1])]);
        }
    }
    let at = |i: u32, k: u32| k * nx + i;
    let mut indices = Vec::with_capacity(((nx - 1) * (nz - 1) * 6) as usize);
    for k in 0..nz - 1 {
        for i in 0..nx - 1 {
            // (x, z), (x, z + dz), (x + dx, z) turns counter-clockwise seen from +Y.
            indices.extend([at(i, k), at(i, k + 1), at(i + 1, k)]);
            indices.extend([at(i + 1, k), at(i, k + 1), at(i + 1, k + 1)]);
        }
    }
    let normals = vec![[0.0, 1.0, 0.0]; positions.len()];
    Mesh::new(name, positions, Some(normals), indices, albedo)
}

/// A UV sphere centred at the origin: `segments` vertices around each ring, `segments / 2`
/// bands from pole to pole, one vertex at each pole so that no triangle is degenerate.
pub fn sphere(name: &str, radius: f32, segments: u32, albedo: [f32; 3]) -> Result<Mesh, SceneError> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(SceneError::invalid(format!(
            "sphere radius {radius} must be finite and greater than zero"
        )));
    }
    if !(3..=MAX_RESOLUTION).contains(&segments) {
        return Err(SceneError::invalid(format!(
            "sphere segments {segments} must be between 3 and {MAX_RESOLUTION}"
        )));
    }
    let bands = (segments / 2).max(2);
    // Same angles as the environment map's mapping: theta from +Y down, phi from -Z towards +X.
    let direction = |band: u32, i: u32| {
        let (sin_theta, cos_theta) = (PI * band as f32 / bands as f32).sin_cos();
        let (sin_phi, cos_phi) = (TAU * i as f32 / segments as f32).sin_cos();
        Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
    };
    let mut normals = vec![Vec3::Y];
    for band in 1..bands {
        normals.extend((0..segments).map(|i| direction(band, i)));
    }
    normals.push(Vec3::NEG_Y);
    let top = 0;
    let bottom = normals.len() as u32 - 1;
    let ring = |band: u32, i: u32| 1 + (band - 1) * segments + i % segments;

    // Going along +phi then down in theta turns counter-clockwise seen from outside.
    let mut indices = Vec::new();
    for i in 0..segments {
        indices.extend([top, ring(1, i + 1), ring(1, i)]);
    }
    for band in 1..bands - 1 {
        for i in 0..segments {
            indices.extend([ring(band, i), ring(band, i + 1), ring(band + 1, i)]);
            indices.extend([ring(band, i + 1), ring(band + 1, i + 1), ring(band + 1, i)]);
        }
    }
    for i in 0..segments {
        indices.extend([ring(bands - 1, i), ring(bands - 1, i + 1), bottom]);
    }
    let positions = normals.iter().map(|n| (*n * radius).to_array()).collect();
    let normals = normals.iter().map(|n| n.to_array()).collect();
    Mesh::new(name, positions, Some(normals), indices, albedo)
}

/// Most boxes one [`boxes`] mesh may hold (24 vertices each).
pub const MAX_BOXES: usize = 65_536;

/// Axis-aligned boxes, each given by its minimum and maximum corner, as one mesh with flat
/// faces (4 vertices per face, so edges stay sharp): lattices and rods built from bars.
pub fn boxes(name: &str, corners: &[([f32; 3], [f32; 3])], albedo: [f32; 3]) -> Result<Mesh, SceneError> {
    if !(1..=MAX_BOXES).contains(&corners.len()) {
        return Err(SceneError::invalid(format!(
            "a box mesh holds 1 to {MAX_BOXES} boxes, got {}",
            corners.len()
        )));
    }
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for &(lo, hi) in corners {
        let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
        if !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
            return Err(SceneError::invalid(format!(
                "box from {lo} to {hi}: the corners must be finite, the first below the second on every axis"
            )));
        }
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                // The face's normal n and two in-plane axes u, v with u × v = n, so the
                // corners taken in (u, v) order turn counter-clockwise seen from outside.
                let n = sign * Vec3::AXES[axis];
                let u = Vec3::AXES[(axis + 1) % 3];
                let v = n.cross(u);
                let centre = 0.5 * (lo + hi) + n * 0.5 * (hi - lo);
                let half = 0.5 * (hi - lo);
                let first = positions.len() as u32;
                for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    positions.push((centre + a * u * half + b * v * half).to_array());
                    normals.push(n.to_array());
                }
                indices.extend([first, first + 1, first + 2, first, first + 2, first + 3]);
            }
        }
    }
    Mesh::new(name, positions, Some(normals), indices, albedo)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's winding normal must agree with its vertex normals and be non-degenerate.
    fn assert_ccw_along_normals(mesh: &Mesh) {
        for tri in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| Vec3::from(mesh.positions[i as usize]));
            let face = (b - a).cross(c - a);
            assert!(face.length() > 0.0, "degenerate triangle {tri:?}");
            for &i in tri {
                assert!(
                    face.dot(Vec3::from(mesh.normals[i as usize])) > 0.0,
                    "triangle {tri:?} winds clockwise"
                );
            }
        }
    }

    #[test]
    fn plane_faces_up_with_the_requested_grid() {
        let mesh = plane("floor", [6.0, 4.0], [31, 21], [0.6; 3]).unwrap();
        assert_eq!(mesh.vertex_count(), 31 * 21);
        assert_eq!(mesh.triangle_count(), 30 * 20 * 2);
        assert_ccw_along_normals(&mesh);
        let max_x = mesh.positions.iter().map(|p| p[0]).fold(f32::MIN, f32::max);
        let min_z = mesh.positions.iter().map(|p| p[2]).fold(f32::MAX, f32::min);
        assert_eq!((max_x, min_z), (3.0, -2.0));
    }

    #[test]
    fn sphere_normals_point_outwards() {
        let mesh = sphere("ball", 2.0, 16, [0.5; 3]).unwrap();
        assert_eq!(mesh.vertex_count(), 7 * 16 + 2);
        assert_ccw_along_normals(&mesh);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((Vec3::from(*p) - 2.0 * Vec3::from(*n)).length() < 1e-5);
            assert!((Vec3::from(*n).length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn boxes_are_closed_and_face_outwards() {
        let mesh = boxes("bars", &[([0.0; 3], [1.0, 2.0, 3.0]), ([-1.0; 3], [-0.5; 3])], [0.5; 3]).unwrap();
        assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (48, 24));
        assert_ccw_along_normals(&mesh);
        // The first box's corners are exactly its extremes, its faces' normals point away.
        let first = &mesh.positions[..24];
        let max = first.iter().fold([f32::MIN; 3], |m, p| std::array::from_fn(|k| m[k].max(p[k])));
        assert_eq!(max, [1.0, 2.0, 3.0]);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals).take(24) {
            let centre = Vec3::new(0.5, 1.0, 1.5);
            assert!((Vec3::from(*p) - centre).dot(Vec3::from(*n)) > 0.0);
        }
    }

    #[test]
    fn bad_shapes_are_rejected() {
        assert!(boxes("b", &[], [0.5; 3]).is_err());
        assert!(boxes("b", &[([0.0; 3], [1.0, 0.0, 1.0])], [0.5; 3]).is_err());
        assert!(boxes("b", &[([f32::NAN; 3], [1.0; 3])], [0.5; 3]).is_err());
        assert!(plane("p", [0.0, 1.0], [2, 2], [0.5; 3]).is_err());
        assert!(plane("p", [1.0, 1.0], [1, 2], [0.5; 3]).is_err());
        assert!(sphere("s", -1.0, 8, [0.5; 3]).is_err());
        assert!(sphere("s", 1.0, 2, [0.5; 3]).is_err());
    }
}
