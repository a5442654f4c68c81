//! The CPU side of the scene BVH: building both levels from a [`Scene`], moving groups, and the
//! flattened arrays that [`super::GpuBvh`] uploads.
use super::aabb::Aabb;
use super::pairs;
use super::sah::{self, node_bounds};
use crate::error::{Error, Result};
use crate::layouts::{
    constants, BvhAlbedoMap, BvhInstance, BvhNode, BvhPair, BvhTexel, BvhTriangle, BvhTriangleAttributes,
};
use crate::scene::albedo_map::{AlbedoMap, Wrap};
use crate::scene::Scene;
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Triangles per bottom-level leaf, at most; the SAH may stop earlier.
const MAX_LEAF_TRIANGLES: usize = 4;

/// Where a BVH triangle came from in the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriangleOrigin {
    pub group: u32,
    pub mesh: u32,
    /// Index of the triangle within its mesh (its indices are `3 * triangle ..`).
    pub triangle: u32,
}

/// One bottom-level BVH per scene group (binned SAH over all its meshes' triangles, in the
/// group's object space) and a top level over the groups' world-space bounds.
#[derive(Clone, Debug)]
pub struct SceneBvh {
    /// The bottom-level trees as built, traversed on the CPU.
    pub(super) blas_nodes: Vec<BvhNode>,
    /// The same trees as the GPU reads them (see `pairs.rs`).
    pub(super) blas_pairs: Vec<BvhPair>,
    pub(super) tlas_nodes: Vec<BvhNode>,
    pub(super) instances: Vec<BvhInstance>,
    pub(super) triangles: Vec<BvhTriangle>,
    pub(super) attributes: Vec<BvhTriangleAttributes>,
    /// The meshes' albedo maps, entry 0 unused (no map), and their texels.
    pub(super) albedo_maps: Vec<BvhAlbedoMap>,
    pub(super) albedo_texels: Vec<BvhTexel>,
    origins: Vec<TriangleOrigin>,
}

impl SceneBvh {
    pub fn build(scene: &Scene) -> Result<SceneBvh> {
        scene.validate()?;
        let mut bvh = SceneBvh {
            blas_nodes: Vec::new(),
            blas_pairs: Vec::new(),
            tlas_nodes: Vec::new(),
            instances: Vec::with_capacity(scene.groups.len()),
            triangles: Vec::with_capacity(scene.triangle_count()),
            attributes: Vec::with_capacity(scene.triangle_count()),
            albedo_maps: vec![BvhAlbedoMap::default()],
            albedo_texels: Vec::new(),
            origins: Vec::with_capacity(scene.triangle_count()),
        };
        let mut maps_added: Vec<*const AlbedoMap> = Vec::new();
        for (g, group) in scene.groups.iter().enumerate() {
            let mut triangles = Vec::new();
            let mut attributes = Vec::new();
            let mut origins = Vec::new();
            for (m, mesh) in group.meshes.iter().enumerate() {
                let map = match &mesh.texturing {
                    Some(t) => bvh.albedo_map_index(&mut maps_added, &t.map)?,
                    None => 0,
                };
                let albedo = [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], f32::from_bits(map)];
                for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
                    let p = |k: usize| Vec3::from(mesh.positions[tri[k] as usize]).extend(0.0).to_array();
                    let n = |k: usize| Vec3::from(mesh.normals[tri[k] as usize]).extend(0.0).to_array();
                    let uv = |k: usize| mesh.texturing.as_ref().map_or([0.0; 2], |t| t.uvs[tri[k] as usize]);
                    let ([u0, v0], [u1, v1], [u2, v2]) = (uv(0), uv(1), uv(2));
                    triangles.push(BvhTriangle { v0: p(0), v1: p(1), v2: p(2) });
                    attributes.push(BvhTriangleAttributes {
                        n0: n(0),
                        n1: n(1),
                        n2: n(2),
                        albedo,
                        uv01: [u0, v0, u1, v1],
                        uv2: [u2, v2, 0.0, 0.0],
                    });
                    origins.push(TriangleOrigin { group: g as u32, mesh: m as u32, triangle: t as u32 });
                }
            }
            let boxes: Vec<Aabb> = triangles.iter().map(triangle_bounds).collect();
            let tree = sah::build(&boxes, MAX_LEAF_TRIANGLES);
            let root = to_u32(bvh.blas_nodes.len(), "BVH nodes")?;
            let first = to_u32(bvh.triangles.len(), "triangles")?;
            bvh.blas_nodes.extend(tree.nodes.iter().map(|n| {
                let (index, count) = sah::node_range(n);
                // Interior nodes point at children, leaves at triangles: both move with their
                // arrays into the scene-wide buffers.
                let index = if count > 0 { first + index } else { root + index };
                sah::node(node_bounds(n), index, count)
            }));
            let root_pair = to_u32(bvh.blas_pairs.len(), "BVH nodes")?;
            bvh.blas_pairs.extend(pairs::pairs(&tree.nodes, first, root_pair)?);
            for &i in &tree.order {
                bvh.triangles.push(triangles[i as usize]);
                bvh.attributes.push(attributes[i as usize]);
                bvh.origins.push(origins[i as usize]);
            }
            let matrix = group.transform.matrix();
            bvh.instances.push(BvhInstance {
                object_to_world: matrix.to_cols_array_2d(),
                world_to_object: matrix.inverse().to_cols_array_2d(),
                info: [root, first, to_u32(triangles.len(), "triangles")?, root_pair],
            });
        }
        bvh.rebuild_top_level();
        Ok(bvh)
    }

    /// Moves group `group` to `transform` (object to world: uniform scale, rotation,
    /// translation) and rebuilds the top level over the groups' moved bounds; the bottom-level
    /// trees stay as they are.
    pub fn set_transform(&mut self, group: usize, transform: Mat4) -> Result<()> {
        let count = self.instances.len();
        let instance = self.instances.get_mut(group).ok_or_else(|| {
            Error::InvalidArgument(format!(
                "set_transform: group {group} does not exist (the scene has {count})"
            ))
        })?;
        check_rigid(&transform).map_err(|problem| {
            Error::InvalidArgument(format!("set_transform of group {group}: {problem}"))
        })?;
        instance.object_to_world = transform.to_cols_array_2d();
        instance.world_to_object = transform.inverse().to_cols_array_2d();
        self.rebuild_top_level();
        Ok(())
    }

    /// The index of `map` in the albedo map buffer, added with its texels the first time.
    fn albedo_map_index(&mut self, added: &mut Vec<*const AlbedoMap>, map: &Arc<AlbedoMap>) -> Result<u32> {
        if let Some(at) = added.iter().position(|m| *m == Arc::as_ptr(map)) {
            return Ok(at as u32 + 1);
        }
        let wrap = |w| match w {
            Wrap::Repeat => constants::WRAP_REPEAT,
            Wrap::MirroredRepeat => constants::WRAP_MIRROR,
            Wrap::ClampToEdge => constants::WRAP_CLAMP,
        };
        let flags = wrap(map.wrap[0]) | wrap(map.wrap[1]) << 2 | u32::from(map.filter.magnify_linear) << 4;
        let first = to_u32(self.albedo_texels.len(), "albedo map texels")?;
        self.albedo_texels.extend(map.texels.iter().map(|t| BvhTexel { rgba: u32::from_le_bytes(*t) }));
        self.albedo_maps.push(BvhAlbedoMap { info: [first, map.width, map.height, flags] });
        added.push(Arc::as_ptr(map));
        Ok(added.len() as u32)
    }

    /// Nodes of both levels as the GPU holds them: the bottom level's pairs (one per interior
    /// node) and the top level's nodes.
    pub fn node_count(&self) -> usize {
        self.blas_pairs.len() + self.tlas_nodes.len()
    }

    /// Bytes of all its GPU buffers together.
    pub fn byte_size(&self) -> usize {
        size_of_val(self.blas_pairs.as_slice())
            + size_of_val(self.tlas_nodes.as_slice())
            + size_of_val(self.instances.as_slice())
            + size_of_val(self.triangles.as_slice())
            + size_of_val(self.attributes.as_slice())
            + size_of_val(self.albedo_maps.as_slice())
            + size_of_val(self.albedo_texels.as_slice())
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The world-space box of every group as placed (the top level's root); `None` without
    /// triangles.
    pub fn bounds(&self) -> Option<Aabb> {
        let root = self.tlas_nodes.first().map(node_bounds)?;
        (!self.triangles.is_empty() && !root.is_empty()).then_some(root)
    }

    /// The scene group, mesh and mesh triangle behind BVH triangle `triangle` (a
    /// `RayHit.triangle`).
    pub fn triangle_origin(&self, triangle: u32) -> Option<TriangleOrigin> {
        self.origins.get(triangle as usize).copied()
    }

    /// Bottom-level nodes of every group, in the layout documented in [`super`].
    pub fn blas_nodes(&self) -> &[BvhNode] {
        &self.blas_nodes
    }

    pub fn tlas_nodes(&self) -> &[BvhNode] {
        &self.tlas_nodes
    }

    pub fn instances(&self) -> &[BvhInstance] {
        &self.instances
    }

    pub fn triangles(&self) -> &[BvhTriangle] {
        &self.triangles
    }

    pub fn attributes(&self) -> &[BvhTriangleAttributes] {
        &self.attributes
    }

    /// One leaf per non-empty group, so the node count never changes with transforms and the
    /// GPU buffer can be rewritten in place.
    fn rebuild_top_level(&mut self) {
        let placed: Vec<(u32, Aabb)> = self
            .instances
            .iter()
            .enumerate()
            .filter(|(_, inst)| inst.info[2] > 0)
            .map(|(i, inst)| {
                let root = node_bounds(&self.blas_nodes[inst.info[0] as usize]);
                (i as u32, root.transformed(Mat4::from_cols_array_2d(&inst.object_to_world)))
            })
            .collect();
        let boxes: Vec<Aabb> = placed.iter().map(|p| p.1).collect();
        let tree = sah::build(&boxes, 1);
        self.tlas_nodes = tree
            .nodes
            .iter()
            .map(|n| match sah::node_range(n) {
                (_, 0) => *n,
                (index, _) => sah::node(node_bounds(n), placed[tree.order[index as usize] as usize].0, 1),
            })
            .collect();
    }
}

fn triangle_bounds(t: &BvhTriangle) -> Aabb {
    Aabb::of_points(&[t.v0, t.v1, t.v2].map(|v| Vec3::from_slice(&v[..3])))
}

fn to_u32(n: usize, what: &str) -> Result<u32> {
    u32::try_from(n)
        .map_err(|_| Error::InvalidArgument(format!("the scene has too many {what} for a BVH ({n})")))
}

/// The shaders carry normals with the matrix's upper 3×3 and keep t across spaces, which needs
/// a finite, invertible similarity transform.
fn check_rigid(m: &Mat4) -> std::result::Result<(), String> {
    if !m.is_finite() {
        return Err(format!("the matrix is not finite: {m}"));
    }
    if m.row(3) != glam::Vec4::W {
        return Err("the matrix is not affine (its last row is not 0 0 0 1)".into());
    }
    let axes = [m.x_axis.truncate(), m.y_axis.truncate(), m.z_axis.truncate()];
    let scale = axes[0].length();
    if scale == 0.0 {
        return Err("the scale is zero".into());
    }
    let tolerance = 1e-3 * scale;
    let uniform = axes.iter().all(|a| (a.length() - scale).abs() <= tolerance);
    let orthogonal = (0..3).all(|i| axes[i].dot(axes[(i + 1) % 3]).abs() <= tolerance * scale);
    if !(uniform && orthogonal) {
        return Err("the matrix is not a uniform scale, rotation and translation".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{shapes, Camera, EnvMap, Group, Transform};

    fn two_spheres() -> Scene {
        let sphere = |name: &str, x: f32| {
            Group::new(
                name,
                vec![shapes::sphere(name, 1.0, 12, [0.5; 3]).unwrap()],
                Transform { translation: Vec3::new(x, 0.0, 0.0), ..Transform::default() },
            )
        };
        Scene::new(
            "spheres",
            vec![sphere("a", -2.0), sphere("b", 2.0)],
            EnvMap::constant([1.0; 3]),
            Camera { position: Vec3::Z * 5.0, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 },
        )
    }

    #[test]
    fn triangles_map_back_to_the_scene() {
        let scene = two_spheres();
        let bvh = SceneBvh::build(&scene).unwrap();
        assert_eq!(bvh.triangle_count(), scene.triangle_count());
        for (i, t) in bvh.triangles().iter().enumerate() {
            let o = bvh.triangle_origin(i as u32).unwrap();
            let mesh = &scene.groups[o.group as usize].meshes[o.mesh as usize];
            let corner = mesh.indices[3 * o.triangle as usize] as usize;
            assert_eq!(t.v0[..3], mesh.positions[corner]);
        }
        assert_eq!(bvh.triangle_origin(bvh.triangle_count() as u32), None);
    }

    #[test]
    fn set_transform_moves_only_the_top_level_and_rejects_non_similarities() {
        let scene = two_spheres();
        let mut bvh = SceneBvh::build(&scene).unwrap();
        let blas = bvh.blas_nodes().to_vec();
        let tlas_len = bvh.tlas_nodes().len();
        let moved = Mat4::from_translation(Vec3::new(0.0, 5.0, 0.0));
        bvh.set_transform(1, moved).unwrap();
        assert_eq!(bvh.blas_nodes(), blas.as_slice());
        assert_eq!(bvh.tlas_nodes().len(), tlas_len);
        // The moved sphere is hit where it now is, and no longer where it was.
        let down = bvh.closest_hit(Vec3::new(0.0, 10.0, 0.0), Vec3::NEG_Y, 1e30);
        assert!(down.is_some_and(|h| h.instance == 1 && (h.t - 4.0).abs() < 0.05));
        assert!(!bvh.occluded(Vec3::new(2.0, 0.0, 5.0), Vec3::NEG_Z, 1e30));

        for bad in [
            Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)),
            Mat4::from_scale(Vec3::ZERO),
            Mat4::from_translation(Vec3::new(f32::NAN, 0.0, 0.0)),
            Mat4::from_cols_array(&[1.0; 16]),
        ] {
            assert!(bvh.set_transform(0, bad).is_err(), "{bad} accepted");
        }
        let err = bvh.set_transform(2, Mat4::IDENTITY).unwrap_err().to_string();
        assert!(err.contains("group 2"), "{err}");
    }
}
