//! The self-shadow pass (section 4.1 of the paper): L_s per vertex, one texel per vertex, drawn
//! as points carrying their transfer vectors. It reruns only for groups whose orientation
//! relative to the light changed since the last frame; other texels keep their values.
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, Context, DepthTest, Format, GraphicsDesc,
    GraphicsPipeline, Image, ImageDesc, ImageUsage, MemoryLocation, Topology, VertexAttribute, VertexBuffer,
};
use crate::error::{Error, Result};
use crate::frame::bounds::rotation_of;
use crate::frame::GpuScene;
use crate::layouts::{bytes_of, constants, spirv, GroupLight, SelfShadowPush};
use crate::pass::Pass;

use crate::prt::TransferSet;
use crate::sh::rotation;
use glam::{Mat3, Mat4};
use std::sync::Arc;

const TRANSFER_VEC4: usize = constants::TRANSFER_VEC4 as usize;
const WIDTH: u32 = constants::SELF_SHADOW_WIDTH;

/// The transfer vectors as vertex attributes: `TRANSFER_VEC4` vec4s per vertex, zero-padded.
const TRANSFER_ATTRIBUTES: [VertexAttribute; TRANSFER_VEC4] = {
    let mut a = [VertexAttribute { location: 0, format: Format::RGBA32_FLOAT, offset: 0 }; TRANSFER_VEC4];
    let mut i = 0;
    while i < TRANSFER_VEC4 {
        a[i].location = i as u32;
        a[i].offset = 16 * i as u32;
        i += 1;
    }
    a
};
pub const TRANSFER_STRIDE: u32 = 16 * TRANSFER_VEC4 as u32;

/// `TRANSFER_ATTRIBUTES` at another first location (the scene pass reads them after position
/// and normal).
pub fn transfer_vertex_buffer(first_location: u32) -> [VertexAttribute; TRANSFER_VEC4] {
    TRANSFER_ATTRIBUTES.map(|a| VertexAttribute { location: a.location + first_location, ..a })
}

pub struct SelfShadow {
    pipeline: GraphicsPipeline,
    /// Per `GpuScene` mesh: its transfer vectors, and its first texel.
    pub transfer: Vec<Buffer>,
    pub first_texel: Vec<u32>,
    pub texture: Image,
    lights: Buffer,
    /// The environment's SH in the map's frame, `bands²` coefficients.
    env: Vec<[f64; 3]>,
    bands: usize,
    /// The light-to-group rotation each group's texels were computed with.
    computed: Vec<Option<Mat3>>,
    dirty: Vec<bool>,
}

impl SelfShadow {
    pub fn new(
        ctx: &Arc<Context>,
        scene: &GpuScene,
        transfer: &TransferSet,
        env: Vec<[f64; 3]>,
    ) -> Result<SelfShadow> {
        let coeffs = transfer.params.coeffs();
        let mut buffers = Vec::new();
        let mut first_texel = Vec::new();
        let mut next = 0u32;
        for mesh in &scene.meshes {
            let data = transfer
                .meshes
                .iter()
                .find(|m| m.group == mesh.group && m.mesh == mesh.mesh)
                .filter(|m| m.coefficients.len() == mesh.vertex_count as usize * coeffs)
                .ok_or_else(|| {
                    Error::InvalidArgument(format!(
                        "the PRT transfer does not match mesh {} of group {} ({} vertices)",
                        mesh.mesh, mesh.group, mesh.vertex_count
                    ))
                })?;
            let mut padded = vec![0.0f32; mesh.vertex_count as usize * 4 * TRANSFER_VEC4];
            for (v, c) in data.coefficients.chunks_exact(coeffs).enumerate() {
                padded[v * 4 * TRANSFER_VEC4..][..coeffs].copy_from_slice(c);
            }
            let bytes: Vec<u8> = padded.iter().flat_map(|f| f.to_ne_bytes()).collect();
            buffers.push(Buffer::with_data(
                ctx,
                &format!("{}.transfer", mesh.name),
                BufferUsage::VERTEX,
                &bytes,
            )?);
            first_texel.push(next);
            next += mesh.vertex_count;
        }
        let texture = Image::new(
            ctx,
            &ImageDesc {
                name: "self_shadow",
                width: WIDTH,
                height: next.div_ceil(WIDTH).max(1),
                layers: 1,
                levels: 1,
                array: false,
                format: Format::RGBA32_FLOAT,
                usage: ImageUsage::COLOR_ATTACHMENT | ImageUsage::SAMPLED,
            },
        )?;
        let groups = scene.transforms.len();
        let lights = Buffer::new(
            ctx,
            &BufferDesc {
                name: "self_shadow.group_lights",
                size: (groups.max(1) * size_of::<GroupLight>()) as u64,
                usage: BufferUsage::STORAGE,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        let pipeline = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "self_shadow",
                vertex_spirv: spirv::SELF_SHADOW_VERT,
                fragment_spirv: spirv::SELF_SHADOW_FRAG,
                bindings: &[BindingKind::StorageBuffer],
                push_size: size_of::<SelfShadowPush>() as u32,
                vertex_buffers: &[VertexBuffer { stride: TRANSFER_STRIDE, attributes: &TRANSFER_ATTRIBUTES }],
                topology: Topology::Points,
                color_formats: &[Format::RGBA32_FLOAT],
                depth_format: None,
                depth: DepthTest::Off,
                write_color: true,
                constants: &[],
            },
        )?;
        Ok(SelfShadow {
            pipeline,
            transfer: buffers,
            first_texel,
            texture,
            lights,
            env,
            bands: transfer.params.bands as usize,
            computed: vec![None; groups],
            dirty: vec![false; groups],
        })
    }

    /// Marks the groups `drawn` keeps whose orientation relative to the light changed, and
    /// rotates the environment's SH into their frames: g(ω) = L_map(R_envᵀ R_group ω).
    pub fn update(&mut self, transforms: &[Mat4], env: Mat3, drawn: impl Fn(usize) -> bool) -> Result<()> {
        for (g, transform) in transforms.iter().enumerate() {
            if !drawn(g) {
                self.dirty[g] = false;
                continue;
            }
            let relative = env.transpose() * rotation_of(transform);
            let unchanged = self.computed[g].is_some_and(|c| c.abs_diff_eq(relative, 1e-6));
            self.dirty[g] = !unchanged;
            if unchanged {
                continue;
            }
            let rotated = rotation::rotate(&self.env, self.bands, relative.as_dmat3());
            let mut light = GroupLight::default();
            for (i, c) in rotated.iter().enumerate() {
                light.red[i / 4][i % 4] = c[0] as f32;
                light.green[i / 4][i % 4] = c[1] as f32;
                light.blue[i / 4][i % 4] = c[2] as f32;
            }
            self.lights.write((g * size_of::<GroupLight>()) as u64, bytes_of(&light))?;
            self.computed[g] = Some(relative);
        }
        Ok(())
    }

    /// The pass, when any group needs its texels again.
    pub fn pass<'a>(&'a self, ctx: &'a Arc<Context>, scene: &'a GpuScene) -> Option<Pass<'a>> {
        if !self.dirty.iter().any(|&d| d) {
            return None;
        }
        // Every group at once (first frame, a turned light): clear, so no texel is undefined.
        let clear = self.dirty.iter().all(|&d| d).then_some([0.0; 4]);
        Some(Pass::new("self_shadow", move |cmd| {
            ctx.begin_rendering(cmd, Some((&self.texture).into()), clear, None);
            self.pipeline.bind(cmd, &[Binding::Storage(&self.lights)]);
            for (i, mesh) in scene.meshes.iter().enumerate().filter(|(_, m)| self.dirty[m.group]) {
                let push = SelfShadowPush {
                    target: [self.first_texel[i], WIDTH, self.texture.height, mesh.group as u32],
                    albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
                };
                self.pipeline.push(cmd, bytes_of(&push));
                ctx.draw(cmd, &[&self.transfer[i]], mesh.vertex_count);
            }
            ctx.end_rendering(cmd);
        }))
    }
}
