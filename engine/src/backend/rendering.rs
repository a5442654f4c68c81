//! Dynamic-rendering scopes (no render pass or framebuffer objects): one colour target, an
//! optional depth target, viewport and scissor covering the target.
use super::Cmd;
use super::{Context, Image};
use ash::vk;

/// One layer of an image used as an attachment.
#[derive(Clone, Copy)]
pub struct Target<'a> {
    pub image: &'a Image,
    pub layer: u32,
}

impl<'a> From<&'a Image> for Target<'a> {
    fn from(image: &'a Image) -> Target<'a> {
        Target { image, layer: 0 }
    }
}

/// A depth attachment: cleared to 1 (the far plane), or kept as an earlier pass left it (a
/// depth prepass).
#[derive(Clone, Copy)]
pub enum Depth<'a> {
    Clear(Target<'a>),
    Keep(Target<'a>),
}

impl<'a> Depth<'a> {
    fn target(self) -> Target<'a> {
        match self {
            Depth::Clear(t) | Depth::Keep(t) => t,
        }
    }
}

impl Context {
    /// Begins rendering into `color` (cleared to `clear` when given, else loaded) and `depth`.
    /// Either may be absent (depth-only shadow maps).
    pub fn begin_rendering(
        &self,
        cmd: Cmd,
        color: Option<Target>,
        clear: Option<[f32; 4]>,
        depth: Option<Depth>,
    ) {
        // Render targets count as written, loaded or cleared.
        for image in color.map(|t| t.image).into_iter().chain(depth.map(|d| d.target().image)) {
            image.touched(cmd, true);
        }
        let color_attachment: Vec<vk::RenderingAttachmentInfo> = color
            .iter()
            .map(|c| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(c.image.attachment_view(c.layer))
                    .image_layout(vk::ImageLayout::GENERAL)
                    .load_op(if clear.is_some() {
                        vk::AttachmentLoadOp::CLEAR
                    } else {
                        vk::AttachmentLoadOp::LOAD
                    })
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue { float32: clear.unwrap_or_default() },
                    })
            })
            .collect();
        let depth_attachment = depth.map(|d| {
            let load = match d {
                Depth::Clear(_) => vk::AttachmentLoadOp::CLEAR,
                Depth::Keep(_) => vk::AttachmentLoadOp::LOAD,
            };
            let d = d.target();
            vk::RenderingAttachmentInfo::default()
                .image_view(d.image.attachment_view(d.layer))
                .image_layout(vk::ImageLayout::GENERAL)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 },
                })
        });
        let size =
            color.or(depth.map(Depth::target)).map(|t| (t.image.width, t.image.height)).unwrap_or((1, 1));
        let area = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D { width: size.0, height: size.1 },
        };
        let mut info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&color_attachment);
        if let Some(d) = &depth_attachment {
            info = info.depth_attachment(d);
        }
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: size.0 as f32,
            height: size.1 as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: recording command buffer; attachments are alive, in GENERAL layout by policy.
        unsafe {
            self.dynamic_rendering.cmd_begin_rendering(cmd.raw, &info);
            self.device.cmd_set_viewport(cmd.raw, 0, &[viewport]);
            self.device.cmd_set_scissor(cmd.raw, 0, &[area]);
        }
    }

    pub fn end_rendering(&self, cmd: Cmd) {
        // SAFETY: closes the scope opened by begin_rendering.
        unsafe { self.dynamic_rendering.cmd_end_rendering(cmd.raw) };
    }

    /// Restricts the current rendering scope's viewport and scissor to the `side`² texels from
    /// `origin` (begin_rendering covers the whole target): several views drawn side by side
    /// into one image, such as a probe's cube faces or ASM's tiles.
    pub fn restrict_to_square(&self, cmd: Cmd, origin: [u32; 2], side: u32) {
        let (x, y) = (origin[0] as f32, origin[1] as f32);
        let viewport =
            vk::Viewport { x, y, width: side as f32, height: side as f32, min_depth: 0.0, max_depth: 1.0 };
        let scissor = vk::Rect2D {
            offset: vk::Offset2D { x: origin[0] as i32, y: origin[1] as i32 },
            extent: vk::Extent2D { width: side, height: side },
        };
        // SAFETY: recording command buffer inside a rendering scope.
        unsafe {
            self.device.cmd_set_viewport(cmd.raw, 0, &[viewport]);
            self.device.cmd_set_scissor(cmd.raw, 0, &[scissor]);
        }
    }

    /// Binds vertex buffers (binding i = `vertices[i]`) and a u32 index buffer and draws `count`
    /// indices.
    pub fn draw_indexed(&self, cmd: Cmd, vertices: &[&super::Buffer], indices: &super::Buffer, count: u32) {
        self.draw_indexed_range(cmd, vertices, indices, 0, count);
    }

    /// [`Context::draw_indexed`] of the `count` indices from index `first` on (gl_PrimitiveID
    /// counts from the first of them).
    pub fn draw_indexed_range(
        &self,
        cmd: Cmd,
        vertices: &[&super::Buffer],
        indices: &super::Buffer,
        first: u32,
        count: u32,
    ) {
        for buffer in vertices.iter().chain([&indices]) {
            buffer.touched(cmd, false);
        }
        let raw: Vec<vk::Buffer> = vertices.iter().map(|b| b.raw).collect();
        let offsets = vec![0; raw.len()];
        // SAFETY: recording command buffer inside a rendering scope with a pipeline bound.
        unsafe {
            self.device.cmd_bind_vertex_buffers(cmd.raw, 0, &raw, &offsets);
            self.device.cmd_bind_index_buffer(cmd.raw, indices.raw, 0, vk::IndexType::UINT32);
            self.device.cmd_draw_indexed(cmd.raw, count, 1, first, 0, 0);
        }
    }

    /// Binds vertex buffers (binding i = `vertices[i]`, possibly none) and draws `count`
    /// vertices.
    pub fn draw(&self, cmd: Cmd, vertices: &[&super::Buffer], count: u32) {
        for buffer in vertices {
            buffer.touched(cmd, false);
        }
        let raw: Vec<vk::Buffer> = vertices.iter().map(|b| b.raw).collect();
        // SAFETY: recording command buffer inside a rendering scope with a pipeline bound.
        unsafe {
            if !raw.is_empty() {
                self.device.cmd_bind_vertex_buffers(cmd.raw, 0, &raw, &vec![0; raw.len()]);
            }
            self.device.cmd_draw(cmd.raw, count, 1, 0, 0);
        }
    }
}
