//! Occlusion between groups (section 3.3.2): for each receiver group, occluder group and region,
//! the occluder is projected along the region's direction onto a plane (a mask layer), then
//! box-filtered in two 1D passes with the width s = sqrt(Ω_i)·R of eq. (13); the result V_o is
//! looked up per pixel in the scene pass. With [`Penumbra::Adaptive`] the same two passes leave
//! boxes of three widths side by side and the scene pass interpolates the width it wants per
//! pixel.
//!
//! Where this differs from the paper's text, on purpose:
//! - Each mask is fitted to the occluder, not to the receiver: its plane goes through the
//!   occluder's bounding-sphere centre and it covers the occluder's projected box plus the
//!   filter's reach. Only there can its shadow fall, and a large receiver (the floor) would
//!   otherwise spread the mask's texels over the whole floor.
//! - Masks have depth (the paper's tangent-plane construction never covered contact): the
//!   receiver is drawn first, depth only, and the occluder marks only the texels where it lies
//!   in front of the receiver's surface towards the light. So a teapot standing on the floor
//!   shadows the floor beside it under any light, and a floor never shadows what stands on it.
//! - The box width can come from the spread of the region's energy ([`Region::spread`]) rather
//!   than its solid angle: a sun alone in a large region of black sky casts a sharp shadow.
//! - Pairs and regions that cannot cast a shadow are skipped: black regions; regions no
//!   receiver normal faces (light from below for a floor); occluders lying wholly farther from
//!   the light than the receiver; occluders whose shadow cylinder misses the receiver's sphere.
//!   A group alone runs no occlusion pass at all.
use super::dominant::DominantLight;
use super::sheet::Sheet;
use super::technique::{OcclusionSettings, Penumbra};
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, Cmd, ComputePipeline, Context, Depth, DepthTest,
    Edge, Format, GraphicsDesc, GraphicsPipeline, Image, ImageDesc, ImageUsage, MemoryLocation, Sampler,
    Target, TexelBuffer, Topology,
};
use crate::error::Result;
use crate::frame::bounds::{box_corners, rotation_of, GroupBounds};
use crate::frame::gpu_scene::MESH_POSITIONS;
use crate::frame::regions::{Region, Regions};
use crate::frame::{GpuScene, DEPTH_FORMAT};
use crate::layouts::{
    bytes_of, bytes_of_slice, constants, spirv, BlurPush, MaskPush, OcclusionLayer, RegionBasis,
};
use crate::pass::Pass;
use crate::scene::clusters::{runs, Cluster};

use crate::sh;
use glam::{Mat3, Mat4, Vec3};
use std::sync::Arc;

struct Job {
    receiver: usize,
    layer: OcclusionLayer,
    weight: f64,
}

/// How wide a region's shadows are: which solid angle Ω_i eq. (13) takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RegionSize {
    /// The paper's: the region's solid angle.
    Geometric,
    /// The solid angle its energy spreads over ([`Region::spread`]).
    #[default]
    Energy,
}

impl RegionSize {
    fn of(self, region: &Region) -> f64 {
        match self {
            RegionSize::Geometric => region.solid_angle,
            RegionSize::Energy => region.spread,
        }
    }
}

pub struct Occlusion {
    /// The light sources whose shadows the layers hold: the q regions, then the dominant
    /// lights as area lights (their layers' region index is q + the light's).
    sources: Vec<Region>,
    /// q.
    regions: usize,
    bands: usize,
    bounds: Vec<GroupBounds>,
    /// Per group: the sheet it is, if it is one.
    sheets: Vec<Option<Sheet>>,
    pub resolution: u32,
    capacity: u32,
    pub penumbra: Penumbra,
    size: RegionSize,
    /// The receiver's depth, then the occluder's coverage in front of it.
    receiver_pipeline: GraphicsPipeline,
    mask_pipeline: GraphicsPipeline,
    /// The two filter passes: along the masks' rows, then along the columns.
    blur: [ComputePipeline; 2],
    mask: Image,
    mask_depth: Image,
    /// The horizontal pass's boxes (f32 RGBA per texel), which the vertical pass reads.
    temp: Buffer,
    /// V_o, one layer per (receiver, occluder, region) in use this frame.
    pub filtered: Image,
    pub sampler: Sampler,
    /// The filter passes' texel fetches.
    nearest: Sampler,
    /// `OcclusionLayer`s, sorted by receiver then region (a storage buffer for the mask and
    /// filter passes, a uniform buffer for the scene pass).
    pub layers: Buffer,
    /// B_i per region (rgb).
    pub energy: Buffer,
    /// `RegionBasis` per group and region, as texels: the scene pass's vertex shader reads
    /// every region's for every vertex (a texel buffer: vendor-notes.md).
    pub region_basis: TexelBuffer,
    /// Per receiver group: its first layer and layer count.
    pub ranges: Vec<(u32, u32)>,
    /// Per receiver group, bit s: an occluder sheet hides source s from the whole group, which
    /// loses it with no layer (`Sheet`).
    pub covered: Vec<[u32; 4]>,
    /// The layers in use this frame, as uploaded to `layers`.
    in_use: Vec<OcclusionLayer>,
    /// The receiver group of each layer in use.
    receivers: Vec<usize>,
    /// Pairs that were wanted but did not fit in `capacity` this frame (least energy first).
    pub dropped: usize,
}

/// The masks: coverage, and coverage × occluder height.
const MASK_FORMAT: Format = Format::RG32_FLOAT;
/// The filtered layers: up to three box widths side by side, and the occluder heights. Half
/// floats: the scene pass reads one per layer per pixel, and coverage needs no more than their
/// 2^-10 of relative precision.
pub const FILTERED_FORMAT: Format = Format::RGBA16_FLOAT;
// The scene pass reads the layers from a uniform buffer (16 KiB on every device) and keeps one
// bit per layer in 32-bit words.
const _: () = assert!(constants::MAX_OCCLUSION_LAYERS as usize * size_of::<OcclusionLayer>() <= 16 * 1024);
const _: () = assert!(constants::MAX_OCCLUSION_LAYERS % 32 == 0);
const _: () = assert!(constants::LAYER_UVEC4 * 128 >= constants::MAX_OCCLUSION_LAYERS);
/// Texels of margin on each side of a mask beyond the occluder and its filter's reach.
const MASK_MARGIN_TEXELS: f32 = 1.5;
/// How far behind the receiver's surface, in mask texels, an occluder fragment still counts as
/// behind it: surfaces that touch (a teapot's base on the floor) must not shadow each other.
const CONTACT_BIAS_TEXELS: f32 = 0.25;

/// One of the two filter passes (occlusion_blur.comp): along the masks' rows, or `vertical`ly.
/// Bindings: the layers, the masks (sampled), the horizontal pass's boxes (storage buffer, f32
/// RGBA per texel), the filtered layers (storage image).
pub fn filter_pipeline(ctx: &Arc<Context>, penumbra: Penumbra, vertical: bool) -> Result<ComputePipeline> {
    ComputePipeline::specialized(
        ctx,
        if vertical { "occlusion_blur.vertical" } else { "occlusion_blur.horizontal" },
        spirv::OCCLUSION_BLUR_COMP,
        &[
            BindingKind::StorageBuffer,
            BindingKind::SampledImage,
            BindingKind::StorageBuffer,
            BindingKind::StorageImage,
        ],
        size_of::<BlurPush>() as u32,
        &[(penumbra == Penumbra::Adaptive) as u32, vertical as u32],
    )
}

/// `layers` square layers of `size`² texels of `format`, read by the filter passes' texel fetches.
fn layered(
    ctx: &Arc<Context>,
    name: &str,
    size: u32,
    layers: u32,
    format: Format,
    usage: ImageUsage,
) -> Result<Image> {
    Image::new(ctx, &ImageDesc::square_array(name, size, layers, format, usage | ImageUsage::SAMPLED))
}

fn host_buffer(ctx: &Arc<Context>, name: &str, size: usize) -> Result<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc {
            name,
            size: size.max(16) as u64,
            usage: BufferUsage::STORAGE | BufferUsage::UNIFORM,
            location: MemoryLocation::CpuToGpu,
        },
    )
}

/// Two unit vectors completing `w` to an orthonormal basis.
pub fn plane_axes(w: Vec3) -> (Vec3, Vec3) {
    let helper = if w.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let u = helper.cross(w).normalize();
    (u, w.cross(u))
}

/// The mask pipelines: the receiver's surface (depth only), then the occluder's coverage in
/// front of it.
fn mask_pipeline(ctx: &Arc<Context>, name: &str, occluder: bool) -> Result<GraphicsPipeline> {
    GraphicsPipeline::new(
        ctx,
        &GraphicsDesc {
            name,
            vertex_spirv: spirv::OCCLUDER_MASK_VERT,
            fragment_spirv: spirv::OCCLUDER_MASK_FRAG,
            bindings: &[BindingKind::StorageBuffer],
            push_size: size_of::<MaskPush>() as u32,
            vertex_buffers: &[MESH_POSITIONS],
            topology: Topology::Triangles,
            color_formats: &[MASK_FORMAT],
            depth_format: Some(DEPTH_FORMAT),
            depth: if occluder { DepthTest::Nearer } else { DepthTest::Less },
            write_color: occluder,
            constants: &[],
        },
    )
}

impl Occlusion {
    /// `regions` may be empty (Sloan's PRT: no occlusion between groups). Of `settings`: the
    /// mask size, the most layers, the penumbra and the region size.
    pub fn new(
        ctx: &Arc<Context>,
        regions: Regions,
        lights: &[DominantLight],
        bands: usize,
        bounds: Vec<GroupBounds>,
        sheets: Vec<Option<Sheet>>,
        settings: &OcclusionSettings,
    ) -> Result<Occlusion> {
        let (resolution, penumbra, size) = (settings.mask_size, settings.penumbra, settings.size);
        let q = regions.regions.len();
        // Layer images hold no more layers than the scene can ask for: one per ordered pair of
        // groups and source (the two-group default scene at q = 32 needs 64, not 192), within
        // the settings' budget.
        let groups = bounds.len();
        let wanted = groups * groups.saturating_sub(1) * (q + lights.len());
        let capacity = wanted.min(settings.max_layers as usize) as u32;
        // A dominant light as an area light: a disk of its radius, its energy's spread.
        let disks = lights.iter().map(|l| Region {
            energy: l.energy,
            direction: l.direction,
            solid_angle: std::f64::consts::TAU * (1.0 - l.radius.cos()),
            spread: std::f64::consts::PI * l.radius * l.radius,
        });
        let sources: Vec<Region> = regions.regions.iter().cloned().chain(disks).collect();
        let layer_count = capacity.max(1);
        // Sized for the shader's whole array: the scene pass reads it as uniforms.
        let mut energy = host_buffer(ctx, "occlusion.region_energy", constants::MAX_REGIONS as usize * 16)?;
        let rgb: Vec<u8> = regions
            .regions
            .iter()
            .flat_map(|r| [r.energy[0] as f32, r.energy[1] as f32, r.energy[2] as f32, 0.0])
            .flat_map(f32::to_ne_bytes)
            .collect();
        energy.write(0, &rgb)?;
        Ok(Occlusion {
            receiver_pipeline: mask_pipeline(ctx, "occluder_mask.receiver", false)?,
            mask_pipeline: mask_pipeline(ctx, "occluder_mask", true)?,
            blur: [filter_pipeline(ctx, penumbra, false)?, filter_pipeline(ctx, penumbra, true)?],
            mask: layered(
                ctx,
                "occlusion.mask",
                resolution,
                layer_count,
                MASK_FORMAT,
                ImageUsage::COLOR_ATTACHMENT,
            )?,
            mask_depth: Image::new(
                ctx,
                &ImageDesc::square_array(
                    "occlusion.mask_depth",
                    resolution,
                    layer_count,
                    DEPTH_FORMAT,
                    ImageUsage::DEPTH_ATTACHMENT,
                ),
            )?,
            temp: Buffer::new(
                ctx,
                &BufferDesc {
                    name: "occlusion.temp",
                    size: u64::from(layer_count)
                        * u64::from(resolution * resolution)
                        * size_of::<[u16; 4]>() as u64, // four half floats per texel
                    usage: BufferUsage::STORAGE,
                    location: MemoryLocation::GpuOnly,
                },
            )?,
            filtered: layered(
                ctx,
                "occlusion.filtered",
                resolution,
                layer_count,
                FILTERED_FORMAT,
                ImageUsage::STORAGE | ImageUsage::TRANSFER_SRC,
            )?,
            sampler: Sampler::new(ctx, "occlusion.sampler", true, Edge::Clamp, Edge::Clamp)?,
            nearest: Sampler::new(ctx, "occlusion.nearest", false, Edge::Clamp, Edge::Clamp)?,
            penumbra,
            size,
            layers: host_buffer(ctx, "occlusion.layers", layer_count as usize * size_of::<OcclusionLayer>())?,
            energy,
            region_basis: TexelBuffer::new(
                ctx,
                "occlusion.region_basis",
                (groups * q).max(1) as u64 * size_of::<RegionBasis>() as u64,
                MemoryLocation::CpuToGpu,
            )?,
            ranges: vec![(0, 0); groups],
            covered: vec![[0; 4]; groups],
            in_use: Vec::new(),
            receivers: Vec::new(),
            dropped: 0,
            sources,
            regions: q,
            bands,
            bounds,
            sheets,
            resolution,
            capacity,
        })
    }

    /// This frame's layers, in the order of the layer images.
    pub fn layers_in_use(&self) -> &[OcclusionLayer] {
        &self.in_use
    }

    pub fn region_count(&self) -> usize {
        self.regions
    }

    /// The layer of `region` (world direction `w`) for the occluder group `o` over the
    /// receiver group `r`, or `None` when `o` cannot shadow `r` from there.
    fn layer(
        &self,
        transforms: &[Mat4],
        r: usize,
        o: usize,
        region: usize,
        w: Vec3,
    ) -> Option<OcclusionLayer> {
        let place = |g: usize| {
            let t = &transforms[g];
            (t.transform_point3(self.bounds[g].centre), self.bounds[g].radius * t.x_axis.truncate().length())
        };
        let ((receiver_centre, receiver_radius), (centre, radius)) = (place(r), place(o));
        // Distances along w (towards the light) from the occluder's centre.
        let (occluder_low, occluder_high) = self.bounds[o].extent_along(&transforms[o], centre, w);
        let (receiver_low, receiver_high) = self.bounds[r].extent_along(&transforms[r], centre, w);
        if occluder_high <= receiver_low {
            return None; // wholly farther from the light than the receiver
        }
        if self.bounds[o].behind_along_an_axis(&transforms[o], &self.bounds[r], &transforms[r], w) {
            return None;
        }
        let offset = centre - receiver_centre;
        let along = offset.dot(w);
        let root_omega = (self.size.of(&self.sources[region]) as f32).sqrt();
        // The widest shadow: from the occluder's top to the receiver's bottom (adaptive); the
        // paper's one width, R from the occluder's centre to the plane through the receiver's.
        let width = match self.penumbra {
            Penumbra::Fixed => root_omega * along.max(0.0),
            Penumbra::Adaptive => root_omega * (occluder_high - receiver_low),
        };
        if (offset - along * w).length() > radius + receiver_radius + 0.5 * width {
            return None; // the shadow cylinder misses the receiver
        }
        let (u, v) = plane_axes(w);
        let corners = self.bounds[o].corners(&transforms[o]);
        let (mut lo, mut hi) = (glam::Vec2::splat(f32::INFINITY), glam::Vec2::splat(f32::NEG_INFINITY));
        for c in corners {
            let p = glam::Vec2::new((c - centre).dot(u), (c - centre).dot(v));
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        // Every vertex lies in the bounding sphere too.
        let (lo, hi) = (lo.max(glam::Vec2::splat(-radius)), hi.min(glam::Vec2::splat(radius)));
        let res = self.resolution as f32;
        let reach = lo.abs().max(hi.abs()).max_element();
        let half_extent = (reach + 0.5 * width) / (1.0 - 2.0 * MASK_MARGIN_TEXELS / res);
        let scale = 1.0 / (2.0 * half_extent);
        let odd = |texels: f32| 2.0 * (0.5 * texels).round() + 1.0;
        let widest = odd(width * scale * res);
        // Adaptive: boxes of 1, the geometric mean and the widest side by side (see
        // occlusion_blur.comp); fixed: the one box.
        let middle = match self.penumbra {
            Penumbra::Fixed => widest,
            Penumbra::Adaptive => odd(widest.sqrt()),
        };
        // The box reaches half its odd width beyond the occluder's silhouette, and bilinear
        // filtering one texel more.
        let filter = (0.5 * widest + 1.0) / res;
        let depth_range = [occluder_low, occluder_high, receiver_low, receiver_high]
            .iter()
            .fold(0.0f32, |m, d| m.max(d.abs()))
            * 1.01
            + 1e-6;
        Some(OcclusionLayer {
            centre: centre.extend(scale).to_array(),
            axis_u: u.extend(middle).to_array(),
            axis_v: v.extend(widest).to_array(),
            footprint: [
                lo.x * scale + 0.5 - filter,
                lo.y * scale + 0.5 - filter,
                hi.x * scale + 0.5 + filter,
                hi.y * scale + 0.5 + filter,
            ],
            region: region as u32,
            occluder: o as u32,
            widen: root_omega * scale * res,
            depth_range,
        })
    }

    /// Whether occluder `o`, a sheet, hides the whole receiver `r` from direction `w`, with the
    /// penumbra `layer` would give (half its box, and the bilinear read's texel) to spare.
    fn hides(&self, transforms: &[Mat4], r: usize, o: usize, w: Vec3, layer: &OcclusionLayer) -> bool {
        let Some(sheet) = &self.sheets[o] else { return false };
        let texel = 1.0 / (layer.centre[3] * self.resolution as f32);
        let widest = layer.axis_v[3] * texel;
        // The adaptive box grows with the distance to the occluder (up to the widest); the
        // paper's is one width.
        let margin = |distance: f32| match self.penumbra {
            Penumbra::Fixed => 0.5 * widest + texel,
            Penumbra::Adaptive => 0.5 * (layer.widen * texel * distance).min(widest) + texel,
        };
        sheet.hides(&transforms[o], &self.bounds[r].corners(&transforms[r]), w, margin)
    }

    /// Chooses this frame's layers and uploads them, with each group's region basis.
    pub fn update(&mut self, transforms: &[Mat4], env: Mat3) -> Result<()> {
        let q = self.region_count();
        let directions: Vec<Vec3> =
            self.sources.iter().map(|r| (env * r.direction.as_vec3()).normalize()).collect();

        let mut jobs = Vec::new();
        self.covered.iter_mut().for_each(|c| *c = [0; 4]);
        for r in 0..transforms.len() {
            let to_object = rotation_of(&transforms[r]).transpose();
            for (i, region) in self.sources.iter().enumerate() {
                let energy = region.energy.iter().sum::<f64>();
                let w = directions[i];
                if energy <= 0.0 || self.bounds[r].faces_away_from(to_object * w) {
                    continue;
                }
                let wanted = jobs.len();
                for o in (0..transforms.len()).filter(|&o| o != r) {
                    if let Some(layer) = self.layer(transforms, r, o, i, w) {
                        if self.hides(transforms, r, o, w, &layer) {
                            // The source is gone whole: no other occluder can take more of it.
                            self.covered[r][i / 32] |= 1 << (i % 32);
                            jobs.truncate(wanted);
                            break;
                        }
                        jobs.push(Job { receiver: r, weight: energy, layer });
                    }
                }
            }
        }
        // Over capacity: keep the brightest regions' layers, and say how many were left out.
        if jobs.len() > self.capacity as usize {
            jobs.sort_by(|a, b| b.weight.total_cmp(&a.weight));
            self.dropped = jobs.len() - self.capacity as usize;
            jobs.truncate(self.capacity as usize);
        } else {
            self.dropped = 0;
        }
        // The scene pass walks a receiver's layers region by region.
        jobs.sort_by_key(|j| (j.receiver, j.layer.region));
        self.ranges.iter_mut().for_each(|r| *r = (0, 0));
        for (l, job) in jobs.iter().enumerate() {
            let range = &mut self.ranges[job.receiver];
            if range.1 == 0 {
                range.0 = l as u32;
            }
            range.1 += 1;
        }
        self.in_use = jobs.iter().map(|j| j.layer).collect();
        self.receivers = jobs.iter().map(|j| j.receiver).collect();
        if !self.in_use.is_empty() {
            self.layers.write(0, bytes_of_slice(&self.in_use))?;
        }

        // The SH basis at each region's direction in each group's frame (exact, on the host).
        let mut basis = Vec::with_capacity(transforms.len() * q);
        let mut y = [0.0f32; 25];
        for transform in transforms {
            let to_object = rotation_of(transform).transpose();
            for w in &directions[..q] {
                sh::eval_basis(self.bands, (to_object * *w).normalize(), &mut y);
                let mut b = RegionBasis::default();
                for (k, value) in y.iter().take(self.bands * self.bands).enumerate() {
                    b.y[k / 4][k % 4] = *value;
                }
                basis.push(b);
            }
        }
        if !basis.is_empty() {
            self.region_basis.write(0, bytes_of_slice(&basis))?;
        }
        Ok(())
    }

    /// Masks and the two filter passes; none when no pair can cast a shadow.
    pub fn passes<'a>(&'a self, ctx: &'a Arc<Context>, scene: &'a GpuScene) -> Vec<Pass<'a>> {
        if self.in_use.is_empty() {
            return Vec::new();
        }
        let count = self.in_use.len() as u32;
        let groups = [self.resolution.div_ceil(constants::BLUR_GROUP), count, 1];
        let blur = move |cmd: Cmd<'_>, pipeline: &ComputePipeline| {
            let push = BlurPush { params: [0, self.resolution, count, 0] };
            pipeline.dispatch(
                cmd,
                &[
                    Binding::Storage(&self.layers),
                    Binding::Sampled(&self.mask, &self.nearest),
                    Binding::Storage(&self.temp),
                    Binding::StorageImage(&self.filtered),
                ],
                bytes_of(&push),
                groups,
            );
        };
        let draw = move |cmd: Cmd<'_>, pipeline: &GraphicsPipeline, l: usize, group: usize, role: u32| {
            let layer = &self.in_use[l];
            let bias = CONTACT_BIAS_TEXELS / (layer.centre[3] * self.resolution as f32);
            pipeline.bind(cmd, &[Binding::Storage(&self.layers)]);
            let model = scene.transforms[group];
            for mesh in scene.meshes.iter().filter(|m| m.group == group) {
                let push = MaskPush {
                    model: model.to_cols_array_2d(),
                    layer: [l as u32, role, 0, 0],
                    bias: [bias, 0.0, 0.0, 0.0],
                };
                pipeline.push(cmd, bytes_of(&push));
                if role == 1 {
                    ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
                    continue;
                }
                // The receiver's depth matters only under the occluder: its triangle clusters
                // beyond the footprint are not drawn (most of a floor is).
                for (first, count) in runs_within(layer, &model, &mesh.clusters) {
                    ctx.draw_indexed_range(cmd, &[&mesh.vertices], &mesh.indices, first, count);
                }
            }
        };
        vec![
            Pass::new("occluder_masks", move |cmd| {
                for (l, (layer, &receiver)) in self.in_use.iter().zip(&self.receivers).enumerate() {
                    let target = Target { image: &self.mask, layer: l as u32 };
                    let depth = Depth::Clear(Target { image: &self.mask_depth, layer: l as u32 });
                    ctx.begin_rendering(cmd, Some(target), Some([0.0; 4]), Some(depth));
                    draw(cmd, &self.receiver_pipeline, l, receiver, 0);
                    draw(cmd, &self.mask_pipeline, l, layer.occluder as usize, 1);
                    ctx.end_rendering(cmd);
                }
            }),
            Pass::new("blur_horizontal", move |cmd| blur(cmd, &self.blur[0])),
            Pass::new("blur_vertical", move |cmd| blur(cmd, &self.blur[1])),
        ]
    }
}

/// The index runs of `clusters` (a mesh's, placed by `model`) whose bounds reach `layer`'s
/// footprint, neighbours merged: (first index, count).
fn runs_within(layer: &OcclusionLayer, model: &Mat4, clusters: &[Cluster]) -> Vec<(u32, u32)> {
    let centre = Vec3::from_slice(&layer.centre[..3]);
    let axes = [Vec3::from_slice(&layer.axis_u[..3]), Vec3::from_slice(&layer.axis_v[..3])];
    let f = &layer.footprint;
    let reaches = |c: &&Cluster| {
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for corner in box_corners(c.min, c.max, model) {
            for k in 0..2 {
                let uv = (corner - centre).dot(axes[k]) * layer.centre[3] + 0.5;
                (lo[k], hi[k]) = (lo[k].min(uv), hi[k].max(uv));
            }
        }
        hi[0] >= f[0] && lo[0] <= f[2] && hi[1] >= f[1] && lo[1] <= f[3]
    };
    runs(clusters.iter().filter(reaches))
}
