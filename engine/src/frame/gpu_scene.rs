//! The scene's geometry on the GPU: one vertex and index buffer per mesh, one transform per
//! group, the albedo maps, and the vertex layouts the techniques' pipelines read it with.
use super::albedo_maps::GpuAlbedoMaps;
use crate::backend::{
    Binding, Buffer, BufferUsage, Cmd, Context, Format, GraphicsPipeline, VertexAttribute, VertexBuffer,
};
use crate::error::Result;
use crate::scene::clusters::{clustered, Cluster};
use crate::scene::Scene;
use glam::Mat4;
use std::sync::Arc;

/// Vertex layout of `GpuScene` meshes: position and normal, 3 floats each, then the albedo
/// map's texture coordinate, 2 floats (0 without a map).
pub const VERTEX_STRIDE: u32 = 32;
// The vertex limit of a mesh is what this stride leaves of 4 GiB.
const _: () = assert!(crate::scene::MAX_MESH_VERTICES as u64 * VERTEX_STRIDE as u64 <= u32::MAX as u64);
pub const MESH_ATTRIBUTES: [VertexAttribute; 3] = [
    VertexAttribute { location: 0, format: Format::RGB32_FLOAT, offset: 0 },
    VertexAttribute { location: 1, format: Format::RGB32_FLOAT, offset: 12 },
    VertexAttribute { location: 2, format: Format::RG32_FLOAT, offset: 24 },
];
pub const MESH_VERTICES: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: &MESH_ATTRIBUTES };
/// The same buffers read by shaders that need positions only.
pub const MESH_POSITIONS: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: MESH_ATTRIBUTES.split_at(1).0 };
/// Positions and texture coordinates, with the other attributes from other buffers.
pub const MESH_POSITIONS_UVS: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: &[MESH_ATTRIBUTES[0], MESH_ATTRIBUTES[2]] };

pub struct GpuMesh {
    /// `group.mesh`, for names and messages.
    pub name: String,
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    pub vertex_count: u32,
    pub albedo: [f32; 3],
    /// Its albedo map in [`GpuScene::albedo_maps`] (0: none, a white texel).
    pub albedo_map: usize,
    /// [`crate::scene::Mesh::longest_edge`], object units.
    pub longest_edge: f32,
    pub group: usize,
    /// Index of the mesh within its group.
    pub mesh: usize,
    /// The index buffer's runs of triangles and their object-space bounds (the buffer holds the
    /// triangles in cluster order, `scene::clusters`).
    pub clusters: Vec<Cluster>,
}

/// Geometry on the GPU: one vertex and index buffer per mesh, one transform per group.
pub struct GpuScene {
    pub meshes: Vec<GpuMesh>,
    pub transforms: Vec<Mat4>,
    pub albedo_maps: GpuAlbedoMaps,
}

impl GpuScene {
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<GpuScene> {
        let (albedo_maps, mut map_of_mesh) = GpuAlbedoMaps::new(ctx, scene)?;
        let mut map_of_mesh = map_of_mesh.drain(..);
        let mut meshes = Vec::new();
        for (g, group) in scene.groups.iter().enumerate() {
            for (m, mesh) in group.meshes.iter().enumerate() {
                let uv = |v: usize| mesh.texturing.as_ref().map_or([0.0; 2], |t| t.uvs[v]);
                let vertices: Vec<u8> = (0..mesh.positions.len())
                    .flat_map(|v| {
                        let (p, n, uv) = (mesh.positions[v], mesh.normals[v], uv(v));
                        [p[0], p[1], p[2], n[0], n[1], n[2], uv[0], uv[1]]
                    })
                    .flat_map(f32::to_ne_bytes)
                    .collect();
                let (indices, clusters) = clustered(mesh);
                let indices: Vec<u8> = indices.iter().flat_map(|i| i.to_ne_bytes()).collect();
                let name = format!("{}.{}", group.name, mesh.name);
                meshes.push(GpuMesh {
                    name: name.clone(),
                    vertices: Buffer::with_data(
                        ctx,
                        &format!("{name}.vertices"),
                        BufferUsage::VERTEX,
                        &vertices,
                    )?,
                    indices: Buffer::with_data(
                        ctx,
                        &format!("{name}.indices"),
                        BufferUsage::INDEX,
                        &indices,
                    )?,
                    index_count: mesh.indices.len() as u32,
                    vertex_count: mesh.positions.len() as u32,
                    mesh: m,
                    albedo: mesh.albedo,
                    albedo_map: map_of_mesh.next().unwrap_or(0),
                    longest_edge: mesh.longest_edge(),
                    group: g,
                    clusters,
                });
            }
        }
        let transforms = scene.groups.iter().map(|g| g.transform.matrix()).collect();
        Ok(GpuScene { meshes, transforms, albedo_maps })
    }

    /// `mesh`'s albedo map, for a lit pipeline's last binding.
    pub fn albedo_map(&self, mesh: &GpuMesh) -> Binding<'_> {
        self.albedo_maps.binding(mesh.albedo_map)
    }

    /// Binds `mesh`'s albedo map as the last binding of `pipeline`, a lit pipeline
    /// ([`super::scene_pass::lit_bindings`]).
    pub fn bind_albedo_map(&self, cmd: Cmd, pipeline: &GraphicsPipeline, mesh: &GpuMesh) {
        pipeline.rebind(cmd, pipeline.binding_count() - 1, self.albedo_map(mesh));
    }
}
