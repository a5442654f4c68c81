//! What every shadow-map technique keeps and records first: a D32 array of square maps, one
//! layer per light, each rendered depth-only with every mesh of the scene from that light's
//! view, and read back with nearest-texel lookups. Shared by the parallel-lights baseline
//! (orthographic maps), the shadowmap technique (perspective maps of local lights) and adaptive
//! shadow maps (its page pool: one tile per layer).
use super::gpu_scene::MESH_POSITIONS;
use crate::backend::{
    Binding, BindingKind, Cmd, Context, Depth, DepthTest, Edge, GraphicsDesc, GraphicsPipeline, Image,
    ImageDesc, ImageUsage, Sampler, Target, Topology,
};
use crate::error::Result;
use crate::frame::{GpuMesh, GpuScene, DEPTH_FORMAT};
use crate::layouts::{bytes_of, spirv, ShadowDepthPush};
use crate::pass::Pass;

use glam::Mat4;
use std::sync::Arc;

pub struct ShadowMaps {
    pipeline: GraphicsPipeline,
    /// One layer per light.
    maps: Image,
    nearest: Sampler,
    /// World to clip space of each layer's light this frame (set by the technique's update).
    pub view_projs: Vec<Mat4>,
}

/// A depth-only pipeline drawing mesh positions with `vertex_spirv` (its resources `bindings`,
/// push constants of `push_size` bytes) and a fragment stage that writes nothing.
pub fn depth_only_pipeline(
    ctx: &Arc<Context>,
    name: &str,
    vertex_spirv: &[u8],
    bindings: &[BindingKind],
    push_size: usize,
) -> Result<GraphicsPipeline> {
    GraphicsPipeline::new(
        ctx,
        &GraphicsDesc {
            name,
            vertex_spirv,
            fragment_spirv: spirv::SHADOW_DEPTH_FRAG,
            bindings,
            push_size: push_size as u32,
            vertex_buffers: &[MESH_POSITIONS],
            topology: Topology::Triangles,
            color_formats: &[],
            depth_format: Some(DEPTH_FORMAT),
            depth: DepthTest::Less,
            write_color: true,
            constants: &[],
        },
    )
}

impl ShadowMaps {
    /// `layers` maps of `size`² texels; `name` prefixes the debug names of its objects.
    pub fn new(ctx: &Arc<Context>, name: &str, size: u32, layers: u32) -> Result<ShadowMaps> {
        let pipeline = depth_only_pipeline(
            ctx,
            &format!("{name}.depth"),
            spirv::SHADOW_DEPTH_VERT,
            &[],
            size_of::<ShadowDepthPush>(),
        )?;
        let usage = ImageUsage::DEPTH_ATTACHMENT | ImageUsage::SAMPLED;
        let maps_name = format!("{name}.maps");
        let desc = ImageDesc::square_array(&maps_name, size, layers, DEPTH_FORMAT, usage);
        Ok(ShadowMaps {
            pipeline,
            maps: Image::new(ctx, &desc)?,
            nearest: Sampler::new(ctx, &format!("{name}.sampler"), false, Edge::Clamp, Edge::Clamp)?,
            view_projs: Vec::new(),
        })
    }

    /// Bytes of the maps: side² × 4 (D32) per layer.
    pub fn byte_size(&self) -> u64 {
        self.maps.byte_size()
    }

    /// The maps as a scene shader samples them (`sampler2DArray`, nearest texel).
    pub fn binding(&self) -> Binding<'_> {
        Binding::Sampled(&self.maps, &self.nearest)
    }

    /// The maps' image.
    pub fn image(&self) -> &Image {
        &self.maps
    }

    /// Map `layer` as a depth attachment.
    pub fn target(&self, layer: u32) -> Target<'_> {
        Target { image: &self.maps, layer }
    }

    /// The `shadow_maps` pass: layer i from `view_projs[i]`.
    pub fn pass<'a>(&'a self, ctx: &'a Context, scene: &'a GpuScene) -> Pass<'a> {
        Pass::new("shadow_maps", move |cmd| {
            for (layer, view_proj) in self.view_projs.iter().enumerate() {
                let whole = scene.meshes.iter().map(|m| (m, 0, m.index_count));
                self.record(ctx, cmd, scene, layer as u32, view_proj, whole);
            }
        })
    }

    /// Records one rendering scope that clears map `layer` and draws into it, with `view_proj`
    /// (world to the map's clip space), the runs of `scene`'s index buffers `draws` names:
    /// (mesh, first index, index count).
    pub fn record<'m>(
        &self,
        ctx: &Context,
        cmd: Cmd,
        scene: &GpuScene,
        layer: u32,
        view_proj: &Mat4,
        draws: impl IntoIterator<Item = (&'m GpuMesh, u32, u32)>,
    ) {
        self.begin(ctx, cmd, layer);
        self.draw(ctx, cmd, scene, view_proj, draws);
        ctx.end_rendering(cmd);
    }

    /// Opens a rendering scope that clears map `layer`, with the depth pipeline bound, for
    /// [`ShadowMaps::draw`]s (in parts of it: `Context::restrict_to_square`).
    pub fn begin(&self, ctx: &Context, cmd: Cmd, layer: u32) {
        ctx.begin_rendering(cmd, None, None, Some(Depth::Clear(self.target(layer))));
        self.pipeline.bind(cmd, &[]);
    }

    /// Draws, inside [`ShadowMaps::begin`]'s scope, the runs `draws` names with `view_proj`.
    pub fn draw<'m>(
        &self,
        ctx: &Context,
        cmd: Cmd,
        scene: &GpuScene,
        view_proj: &Mat4,
        draws: impl IntoIterator<Item = (&'m GpuMesh, u32, u32)>,
    ) {
        for (mesh, first, count) in draws {
            let push = ShadowDepthPush {
                model: scene.transforms[mesh.group].to_cols_array_2d(),
                view_proj: view_proj.to_cols_array_2d(),
            };
            self.pipeline.push(cmd, bytes_of(&push));
            ctx.draw_indexed_range(cmd, &[&mesh.vertices], &mesh.indices, first, count);
        }
    }
}
