//! The scene's geometry on the GPU: one vertex and index buffer per mesh, one transform per
//! group, and the vertex layouts the techniques' pipelines read it with.
use crate::backend::{vk, Buffer, Context, VertexAttribute, VertexBuffer};
use crate::error::Result;
use crate::scene::clusters::{clustered, Cluster};
use crate::scene::Scene;
use glam::Mat4;
use std::sync::Arc;

/// Vertex layout of `GpuScene` meshes: position then normal, 3 floats each.
pub const VERTEX_STRIDE: u32 = 24;
pub const MESH_ATTRIBUTES: [VertexAttribute; 2] = [
    VertexAttribute { location: 0, format: vk::Format::R32G32B32_SFLOAT, offset: 0 },
    VertexAttribute { location: 1, format: vk::Format::R32G32B32_SFLOAT, offset: 12 },
];
pub const MESH_VERTICES: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: &MESH_ATTRIBUTES };
/// The same buffers read by shaders that need positions only.
pub const MESH_POSITIONS: VertexBuffer<'static> =
    VertexBuffer { stride: VERTEX_STRIDE, attributes: MESH_ATTRIBUTES.split_at(1).0 };

pub struct GpuMesh {
    /// `group.mesh`, for names and messages.
    pub name: String,
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    pub vertex_count: u32,
    pub albedo: [f32; 3],
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
}

impl GpuScene {
    pub fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<GpuScene> {
        let mut meshes = Vec::new();
        for (g, group) in scene.groups.iter().enumerate() {
            for (m, mesh) in group.meshes.iter().enumerate() {
                let vertices: Vec<u8> = mesh
                    .positions
                    .iter()
                    .zip(&mesh.normals)
                    .flat_map(|(p, n)| [p[0], p[1], p[2], n[0], n[1], n[2]])
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
                        vk::BufferUsageFlags::VERTEX_BUFFER,
                        &vertices,
                    )?,
                    indices: Buffer::with_data(
                        ctx,
                        &format!("{name}.indices"),
                        vk::BufferUsageFlags::INDEX_BUFFER,
                        &indices,
                    )?,
                    index_count: mesh.indices.len() as u32,
                    vertex_count: mesh.positions.len() as u32,
                    mesh: m,
                    albedo: mesh.albedo,
                    longest_edge: mesh.longest_edge(),
                    group: g,
                    clusters,
                });
            }
        }
        Ok(GpuScene { meshes, transforms: scene.groups.iter().map(|g| g.transform.matrix()).collect() })
    }
}
