//! Compute and graphics pipelines. Each owns its set layout (push descriptors, set 0) and
//! pipeline layout, and records its own binds so passes stay short.
use super::descriptor::{push_descriptors, push_descriptors_from, set_layout_bindings};
use super::Cmd;
use super::Format;
use super::{reflect, Binding, BindingKind, Context};
use crate::error::{Error, Result};
use ash::vk;
use std::sync::Arc;

pub(super) struct Layout {
    set: vk::DescriptorSetLayout,
    pub(super) pipeline: vk::PipelineLayout,
    pub(super) bindings: Vec<BindingKind>,
    /// Per binding, whether a shader of the pipeline may write it.
    pub(super) written: Vec<bool>,
    push_size: u32,
}

fn create_layout(
    ctx: &Context,
    name: &str,
    bindings: &[BindingKind],
    modules: &[&Module],
    push_size: u32,
) -> Result<Layout> {
    let written = (0..bindings.len() as u32)
        .map(|b| modules.iter().flat_map(|m| &m.used).any(|u| u.binding == b && u.written))
        .collect();
    let set_bindings = set_layout_bindings(bindings);
    let set_info = vk::DescriptorSetLayoutCreateInfo::default()
        .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
        .bindings(&set_bindings);
    // SAFETY: valid device and create info.
    let set = unsafe { ctx.device.create_descriptor_set_layout(&set_info, None) }
        .map_err(Error::vk("vkCreateDescriptorSetLayout"))?;
    ctx.set_name(set, &format!("{name}.set_layout"));
    let ranges =
        [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::ALL, offset: 0, size: push_size }];
    let sets = [set];
    let mut info = vk::PipelineLayoutCreateInfo::default().set_layouts(&sets);
    if push_size > 0 {
        info = info.push_constant_ranges(&ranges);
    }
    // SAFETY: valid device and create info.
    let pipeline = match unsafe { ctx.device.create_pipeline_layout(&info, None) } {
        Ok(p) => p,
        Err(e) => {
            // SAFETY: the set layout is unused.
            unsafe { ctx.device.destroy_descriptor_set_layout(set, None) };
            return Err(Error::vk("vkCreatePipelineLayout")(e));
        }
    };
    ctx.set_name(pipeline, &format!("{name}.layout"));
    Ok(Layout { set, pipeline, bindings: bindings.to_vec(), written, push_size })
}

fn destroy_layout(ctx: &Context, layout: &Layout) {
    // SAFETY: no pending submission uses the layouts.
    unsafe {
        ctx.device.destroy_pipeline_layout(layout.pipeline, None);
        ctx.device.destroy_descriptor_set_layout(layout.set, None);
    }
}

/// A shader module that lives only while its pipeline is created.
struct Module<'a> {
    ctx: &'a Context,
    raw: vk::ShaderModule,
    used: Vec<reflect::Used>,
}

impl<'a> Module<'a> {
    /// The module of `spirv`, after checking that the pipeline's `bindings` declare every
    /// descriptor the shader uses with its kind.
    fn new(ctx: &'a Context, name: &str, spirv: &[u8], bindings: &[BindingKind]) -> Result<Module<'a>> {
        let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
            .map_err(|e| Error::Internal(format!("SPIR-V of {name}: {e}")))?;
        let used = reflect::descriptor_bindings(&words)
            .and_then(|used| reflect::check(name, bindings, &used).map(|()| used))
            .map_err(|e| Error::Internal(format!("shader {name}: {e}")))?;
        let info = vk::ShaderModuleCreateInfo::default().code(&words);
        // SAFETY: the words are SPIR-V compiled by the build script.
        let raw = unsafe { ctx.device.create_shader_module(&info, None) }
            .map_err(Error::vk("vkCreateShaderModule"))?;
        ctx.set_name(raw, name);
        Ok(Module { ctx, raw, used })
    }
}

impl Drop for Module<'_> {
    fn drop(&mut self) {
        // SAFETY: modules may be destroyed once the pipelines using them are created.
        unsafe { self.ctx.device.destroy_shader_module(self.raw, None) };
    }
}

fn push_bytes(ctx: &Context, cmd: Cmd, layout: &Layout, bytes: &[u8]) {
    debug_assert_eq!(bytes.len() as u32, layout.push_size, "push constant size mismatch");
    if !bytes.is_empty() {
        // SAFETY: recording command buffer; the range was declared in the layout.
        unsafe {
            ctx.device.cmd_push_constants(cmd.raw, layout.pipeline, vk::ShaderStageFlags::ALL, 0, bytes)
        };
    }
}

pub struct ComputePipeline {
    ctx: Arc<Context>,
    raw: vk::Pipeline,
    layout: Layout,
}

impl ComputePipeline {
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        spirv: &[u8],
        bindings: &[BindingKind],
        push_size: u32,
    ) -> Result<ComputePipeline> {
        ComputePipeline::specialized(ctx, name, spirv, bindings, push_size, &[])
    }

    /// With specialization constants, `constant_id` 0, 1, … in order (see
    /// [`GraphicsDesc::constants`]).
    pub fn specialized(
        ctx: &Arc<Context>,
        name: &str,
        spirv: &[u8],
        bindings: &[BindingKind],
        push_size: u32,
        constants: &[u32],
    ) -> Result<ComputePipeline> {
        let module = Module::new(ctx, &format!("{name}.comp"), spirv, bindings)?;
        let layout = create_layout(ctx, name, bindings, &[&module], push_size)?;
        let (entries, constant_bytes) = specialization_entries(constants);
        let specialization = vk::SpecializationInfo::default().map_entries(&entries).data(&constant_bytes);
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.raw)
            .name(c"main")
            .specialization_info(&specialization);
        let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout.pipeline);
        // SAFETY: valid device, module and layout.
        let raw =
            match unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) } {
                Ok(p) => p[0],
                Err((_, e)) => {
                    destroy_layout(ctx, &layout);
                    return Err(Error::vk("vkCreateComputePipelines")(e));
                }
            };
        ctx.set_name(raw, name);
        Ok(ComputePipeline { ctx: ctx.clone(), raw, layout })
    }

    /// Binds the pipeline, its resources and push constants, then dispatches.
    pub fn dispatch(&self, cmd: Cmd, bindings: &[Binding], push: &[u8], groups: [u32; 3]) {
        // SAFETY: recording command buffer of this device.
        unsafe { self.ctx.device.cmd_bind_pipeline(cmd.raw, vk::PipelineBindPoint::COMPUTE, self.raw) };
        push_descriptors(&self.ctx, cmd, vk::PipelineBindPoint::COMPUTE, &self.layout, bindings);
        push_bytes(&self.ctx, cmd, &self.layout, push);
        // SAFETY: pipeline and descriptors bound above.
        unsafe { self.ctx.device.cmd_dispatch(cmd.raw, groups[0], groups[1], groups[2]) };
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: no pending submission uses the pipeline.
        unsafe { self.ctx.device.destroy_pipeline(self.raw, None) };
        destroy_layout(&self.ctx, &self.layout);
    }
}

/// One vertex attribute of a vertex buffer.
#[derive(Clone, Copy, Debug)]
pub struct VertexAttribute {
    pub location: u32,
    pub format: Format,
    pub offset: u32,
}

/// One interleaved vertex buffer; its binding number is its index in
/// `GraphicsDesc::vertex_buffers`.
#[derive(Clone, Copy, Debug)]
pub struct VertexBuffer<'a> {
    pub stride: u32,
    pub attributes: &'a [VertexAttribute],
}

/// How a graphics pipeline tests and writes depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthTest {
    /// No test, no write.
    Off,
    /// Nearer fragments pass and write their depth.
    Less,
    /// Fragments nearer than the stored depth pass, writing nothing: a surface drawn earlier
    /// with `Less` decides where later ones count (an occlusion mask's receiver).
    Nearer,
    /// Only fragments at exactly the depth a prepass stored pass, writing nothing: one fragment
    /// per pixel is shaded whatever the draw order. The prepass must compute `gl_Position` with
    /// the same operations on the same inputs, `precise` (shaders-glsl/depth_prepass.vert).
    Equal,
    /// Fragments at or nearer than the stored depth pass and write theirs: over a prepass'
    /// depth, one fragment per pixel is shaded as with `Equal`; into a cleared target it draws
    /// as `Less` does (for a pipeline used both ways).
    LessOrEqual,
}

/// What a draw's vertices make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topology {
    Triangles,
    Points,
}

pub struct GraphicsDesc<'a> {
    pub name: &'a str,
    pub vertex_spirv: &'a [u8],
    pub fragment_spirv: &'a [u8],
    pub bindings: &'a [BindingKind],
    pub push_size: u32,
    /// Vertex buffers, bound in this order; none means vertices are made in the shader.
    pub vertex_buffers: &'a [VertexBuffer<'a>],
    pub topology: Topology,
    pub color_formats: &'a [Format],
    pub depth_format: Option<Format>,
    pub depth: DepthTest,
    /// Write the colour targets; false draws depth only into a scope that has colour targets
    /// (the fragment shader's outputs are dropped).
    pub write_color: bool,
    /// Specialization constants of both stages, `constant_id` 0, 1, … in order (a stage ignores
    /// the ids it does not declare): choices fixed for the pipeline's life, so the shader
    /// compiler removes the branches not taken and sizes arrays to what is used (llvmpipe runs
    /// both sides of a branch that depends on a uniform value, and interpolates every declared
    /// fragment input).
    pub constants: &'a [u32],
}

/// The map entries and data of 32-bit specialization constants with ids 0, 1, … in order.
fn specialization_entries(constants: &[u32]) -> (Vec<vk::SpecializationMapEntry>, Vec<u8>) {
    let entries = (0..constants.len() as u32)
        .map(|id| vk::SpecializationMapEntry { constant_id: id, offset: 4 * id, size: 4 })
        .collect();
    (entries, constants.iter().flat_map(|c| c.to_ne_bytes()).collect())
}

pub struct GraphicsPipeline {
    ctx: Arc<Context>,
    raw: vk::Pipeline,
    layout: Layout,
    depth: DepthTest,
}

impl GraphicsPipeline {
    pub fn new(ctx: &Arc<Context>, desc: &GraphicsDesc) -> Result<GraphicsPipeline> {
        let vs = Module::new(ctx, &format!("{}.vert", desc.name), desc.vertex_spirv, desc.bindings)?;
        let fs = Module::new(ctx, &format!("{}.frag", desc.name), desc.fragment_spirv, desc.bindings)?;
        let layout = create_layout(ctx, desc.name, desc.bindings, &[&vs, &fs], desc.push_size)?;
        let (entries, constant_bytes) = specialization_entries(desc.constants);
        let specialization = vk::SpecializationInfo::default().map_entries(&entries).data(&constant_bytes);
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vs.raw)
                .name(c"main")
                .specialization_info(&specialization),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs.raw)
                .name(c"main")
                .specialization_info(&specialization),
        ];
        let vertex_bindings: Vec<vk::VertexInputBindingDescription> = desc
            .vertex_buffers
            .iter()
            .enumerate()
            .map(|(b, buffer)| vk::VertexInputBindingDescription {
                binding: b as u32,
                stride: buffer.stride,
                input_rate: vk::VertexInputRate::VERTEX,
            })
            .collect();
        let attributes: Vec<vk::VertexInputAttributeDescription> = desc
            .vertex_buffers
            .iter()
            .enumerate()
            .flat_map(|(b, buffer)| {
                buffer.attributes.iter().map(move |a| vk::VertexInputAttributeDescription {
                    location: a.location,
                    binding: b as u32,
                    format: a.format.raw,
                    offset: a.offset,
                })
            })
            .collect();
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&vertex_bindings)
            .vertex_attribute_descriptions(&attributes);
        let topology = match desc.topology {
            Topology::Triangles => vk::PrimitiveTopology::TRIANGLE_LIST,
            Topology::Points => vk::PrimitiveTopology::POINT_LIST,
        };
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(topology);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        // Kage's surfaces are two-sided (open meshes such as the teapot show their inside), so
        // nothing is culled; shaders flip normals on back faces.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth != DepthTest::Off)
            .depth_write_enable(matches!(desc.depth, DepthTest::Less | DepthTest::LessOrEqual))
            .depth_compare_op(match desc.depth {
                DepthTest::Equal => vk::CompareOp::EQUAL,
                DepthTest::LessOrEqual => vk::CompareOp::LESS_OR_EQUAL,
                DepthTest::Off | DepthTest::Less | DepthTest::Nearer => vk::CompareOp::LESS,
            });
        let blend_attachment =
            vk::PipelineColorBlendAttachmentState::default().color_write_mask(if desc.write_color {
                vk::ColorComponentFlags::RGBA
            } else {
                vk::ColorComponentFlags::empty()
            });
        let blend_attachments = vec![blend_attachment; desc.color_formats.len()];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let color_formats: Vec<vk::Format> = desc.color_formats.iter().map(|f| f.raw).collect();
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&color_formats)
            .depth_attachment_format(desc.depth_format.map_or(vk::Format::UNDEFINED, |f| f.raw));
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout.pipeline)
            .push_next(&mut rendering);
        // SAFETY: every pointer in the create info refers to locals alive for the call.
        let raw =
            match unsafe { ctx.device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) } {
                Ok(p) => p[0],
                Err((_, e)) => {
                    destroy_layout(ctx, &layout);
                    return Err(Error::vk("vkCreateGraphicsPipelines")(e));
                }
            };
        ctx.set_name(raw, desc.name);
        Ok(GraphicsPipeline { ctx: ctx.clone(), raw, layout, depth: desc.depth })
    }

    pub fn depth(&self) -> DepthTest {
        self.depth
    }

    /// Binds the pipeline and its resources (call inside a rendering scope).
    pub fn bind(&self, cmd: Cmd, bindings: &[Binding]) {
        // SAFETY: recording command buffer of this device.
        unsafe { self.ctx.device.cmd_bind_pipeline(cmd.raw, vk::PipelineBindPoint::GRAPHICS, self.raw) };
        push_descriptors(&self.ctx, cmd, vk::PipelineBindPoint::GRAPHICS, &self.layout, bindings);
    }

    /// Binds `binding` at index `at` of the pipeline's bindings in place of what [`bind`] gave
    /// it (a per-draw resource), keeping the others.
    ///
    /// [`bind`]: GraphicsPipeline::bind
    pub fn rebind(&self, cmd: Cmd, at: u32, binding: Binding) {
        debug_assert_eq!(self.layout.bindings.get(at as usize), Some(&binding.kind()));
        let bind_point = vk::PipelineBindPoint::GRAPHICS;
        push_descriptors_from(&self.ctx, cmd, bind_point, &self.layout, at, &[binding]);
    }

    /// How many resources the pipeline binds.
    pub fn binding_count(&self) -> u32 {
        self.layout.bindings.len() as u32
    }

    pub fn push(&self, cmd: Cmd, bytes: &[u8]) {
        push_bytes(&self.ctx, cmd, &self.layout, bytes);
    }
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        // SAFETY: no pending submission uses the pipeline.
        unsafe { self.ctx.device.destroy_pipeline(self.raw, None) };
        destroy_layout(&self.ctx, &self.layout);
    }
}
