//! Descriptors: every pipeline has one set, written with push descriptors at record time, so
//! there are no pools or set lifetimes to manage. Binding `i` is the i-th entry of the list.
use super::pipeline::Layout;
use super::Cmd;
use super::{Buffer, Context, Image, Sampler, TexelBuffer};
use ash::vk;

/// What a shader binding is; the pipeline's set layout is built from a list of these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    UniformBuffer,
    StorageBuffer,
    SampledImage,
    StorageImage,
    TexelBuffer,
    /// A texel buffer the shader writes (`imageBuffer`).
    StorageTexelBuffer,
}

impl BindingKind {
    fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            BindingKind::TexelBuffer => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
            BindingKind::StorageTexelBuffer => vk::DescriptorType::STORAGE_TEXEL_BUFFER,
        }
    }
}

/// A resource bound at record time, in binding order.
#[derive(Clone, Copy)]
pub enum Binding<'a> {
    Uniform(&'a Buffer),
    Storage(&'a Buffer),
    Sampled(&'a Image, &'a Sampler),
    StorageImage(&'a Image),
    Texel(&'a TexelBuffer),
    StorageTexel(&'a TexelBuffer),
}

impl Binding<'_> {
    pub fn kind(&self) -> BindingKind {
        match self {
            Binding::Uniform(_) => BindingKind::UniformBuffer,
            Binding::Storage(_) => BindingKind::StorageBuffer,
            Binding::Sampled(..) => BindingKind::SampledImage,
            Binding::StorageImage(_) => BindingKind::StorageImage,
            Binding::Texel(_) => BindingKind::TexelBuffer,
            Binding::StorageTexel(_) => BindingKind::StorageTexelBuffer,
        }
    }
}

pub(crate) fn set_layout_bindings(kinds: &[BindingKind]) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, kind)| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(i as u32)
                .descriptor_type(kind.descriptor_type())
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::ALL)
        })
        .collect()
}

/// Binds `bindings` to set 0 of `layout`. Panics are impossible here; a binding list that does
/// not match the layout is a programming error that validation reports.
pub(super) fn push_descriptors(
    ctx: &Context,
    cmd: Cmd,
    bind_point: vk::PipelineBindPoint,
    layout: &Layout,
    bindings: &[Binding],
) {
    debug_assert_eq!(layout.bindings, bindings.iter().map(Binding::kind).collect::<Vec<_>>());
    push_descriptors_from(ctx, cmd, bind_point, layout, 0, bindings);
}

/// Binds `bindings` to bindings `first`, `first + 1`, … of set 0 of `layout`, leaving the others
/// as the last push left them (push descriptors update only what they write).
pub(super) fn push_descriptors_from(
    ctx: &Context,
    cmd: Cmd,
    bind_point: vk::PipelineBindPoint,
    layout: &Layout,
    first: u32,
    bindings: &[Binding],
) {
    for (i, binding) in bindings.iter().enumerate() {
        let written = layout.written.get(first as usize + i).copied().unwrap_or(false);
        match binding {
            Binding::Uniform(buffer) => buffer.touched(cmd, false),
            Binding::Storage(buffer) => buffer.touched(cmd, written),
            Binding::Sampled(image, _) => image.touched(cmd, false),
            Binding::StorageImage(image) => image.touched(cmd, written),
            Binding::Texel(texels) => texels.buffer().touched(cmd, false),
            Binding::StorageTexel(texels) => texels.buffer().touched(cmd, written),
        }
    }
    // A push with no writes is invalid (descriptorWriteCount must be at least 1): pipelines
    // without resources, such as the depth-only shadow pass, push nothing.
    if bindings.is_empty() {
        return;
    }
    let buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = bindings
        .iter()
        .map(|b| match b {
            Binding::Uniform(buf) | Binding::Storage(buf) => {
                [vk::DescriptorBufferInfo { buffer: buf.raw, offset: 0, range: vk::WHOLE_SIZE }]
            }
            _ => [vk::DescriptorBufferInfo::default()],
        })
        .collect();
    let image_infos: Vec<[vk::DescriptorImageInfo; 1]> = bindings
        .iter()
        .map(|b| match b {
            Binding::Sampled(image, sampler) => [vk::DescriptorImageInfo {
                sampler: sampler.raw,
                image_view: image.view,
                image_layout: vk::ImageLayout::GENERAL,
            }],
            Binding::StorageImage(image) => [vk::DescriptorImageInfo {
                sampler: vk::Sampler::null(),
                image_view: image.view,
                image_layout: vk::ImageLayout::GENERAL,
            }],
            _ => [vk::DescriptorImageInfo::default()],
        })
        .collect();
    let texel_views: Vec<[vk::BufferView; 1]> = bindings
        .iter()
        .map(|b| match b {
            Binding::Texel(texels) | Binding::StorageTexel(texels) => [texels.view],
            _ => [vk::BufferView::null()],
        })
        .collect();
    let writes: Vec<vk::WriteDescriptorSet> = bindings
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let write = vk::WriteDescriptorSet::default()
                .dst_binding(first + i as u32)
                .descriptor_type(b.kind().descriptor_type());
            match b {
                Binding::Uniform(_) | Binding::Storage(_) => write.buffer_info(&buffer_infos[i]),
                Binding::Texel(_) | Binding::StorageTexel(_) => write.texel_buffer_view(&texel_views[i]),
                Binding::Sampled(..) | Binding::StorageImage(_) => write.image_info(&image_infos[i]),
            }
        })
        .collect();
    // SAFETY: recording command buffer; the writes point at locals alive for the call, and the
    // set layout was created with the push-descriptor flag.
    unsafe { ctx.push_descriptor.cmd_push_descriptor_set(cmd.raw, bind_point, layout.pipeline, 0, &writes) };
}
