//! Occlusion between groups (section 3.3.2): for each receiver group, occluder group and region,
//! the occluder is projected along the region's direction onto a plane at the receiver (a mask
//! layer), then box-filtered in two 1D passes with the width s = sqrt(Ω_i)·R of eq. (13); the
//! result V_o is looked up per pixel in the scene pass. With [`Penumbra::Adaptive`] the same two
//! passes build a summed-area table instead and the scene pass picks the width per pixel.
//!
//! Two choices differ from the paper's text, on purpose:
//! - The plane goes through the receiver's bounding-sphere centre, not along the sphere's tangent
//!   plane. Projections along ω_i onto parallel planes give the same mask; only R differs, and
//!   for a large flat receiver (the floor) the tangent plane lies far from the surface, which
//!   would blur every contact shadow. R is the distance from the occluder's centre to that plane
//!   along ω_i.
//! - Occluder parts behind the receiver's plane (farther from the light than the receiver's
//!   centre) are clipped from the mask: a flat mask has no depth, and without the clip a floor
//!   would shadow, from above, what stands on it. For a receiver thick along ω_i this misses
//!   occluders between its centre and its far side; measured against the reference in
//!   BENCHMARKS.md.
//! - Pairs and regions that cannot cast a shadow are skipped: black regions; regions no
//!   receiver normal faces (light from below for a floor); occluders whose bounding box lies
//!   wholly behind the receiver's plane; occluders whose shadow cylinder misses the receiver's
//!   sphere. A group alone runs no occlusion pass at all.
use super::regions::Regions;
use super::self_shadow::rotation_of;
use super::technique::Penumbra;
use crate::backend::{
    vk, Binding, BindingKind, Buffer, BufferDesc, ComputePipeline, Context, DepthTest, Edge, GraphicsDesc,
    GraphicsPipeline, Image, ImageDesc, MemoryLocation, Sampler, Target,
};
use crate::error::Result;
use crate::layouts::{
    bytes_of, bytes_of_slice, constants, spirv, BlurPush, MaskPush, OcclusionLayer, RegionBasis,
};
use crate::pass::Pass;
use crate::renderer::GpuScene;
use crate::sh;
use crate::techniques::unshadowed::MESH_POSITIONS;
use glam::{Mat3, Mat4, Vec3};
use std::sync::Arc;

/// A group's bounds in its object space: what culling needs to know of it.
#[derive(Clone, Copy, Debug)]
pub struct GroupBounds {
    /// Bounding sphere.
    pub centre: Vec3,
    pub radius: f32,
    /// Axis-aligned box.
    pub min: Vec3,
    pub max: Vec3,
    /// The cone holding every vertex normal: unit axis and half-angle in radians (π or more:
    /// normals face every way).
    pub normal_axis: Vec3,
    pub normal_spread: f32,
}

impl GroupBounds {
    /// Whether no vertex of the group can receive light from object-space direction `w`.
    fn faces_away_from(&self, w: Vec3) -> bool {
        let angle = self.normal_axis.dot(w).clamp(-1.0, 1.0).acos();
        angle >= std::f32::consts::FRAC_PI_2 + self.normal_spread
    }

    /// The largest signed distance along `w` of the box's corners from `origin` (world space,
    /// with `transform` placing the group).
    fn reach_along(&self, transform: &Mat4, origin: Vec3, w: Vec3) -> f32 {
        (0..8)
            .map(|c| {
                let corner = Vec3::new(
                    if c & 1 == 0 { self.min.x } else { self.max.x },
                    if c & 2 == 0 { self.min.y } else { self.max.y },
                    if c & 4 == 0 { self.min.z } else { self.max.z },
                );
                (transform.transform_point3(corner) - origin).dot(w)
            })
            .fold(f32::NEG_INFINITY, f32::max)
    }
}

struct Job {
    receiver: usize,
    layer: OcclusionLayer,
    weight: f64,
}

pub struct Occlusion {
    regions: Regions,
    bands: usize,
    bounds: Vec<GroupBounds>,
    pub resolution: u32,
    capacity: u32,
    pub penumbra: Penumbra,
    mask_pipeline: GraphicsPipeline,
    blur: ComputePipeline,
    mask: Image,
    temp: Image,
    /// V_o, one layer per (receiver, occluder, region) in use this frame.
    pub filtered: Image,
    pub sampler: Sampler,
    /// `OcclusionLayer`s, sorted by receiver then region (a storage buffer for the mask and
    /// filter passes, a uniform buffer for the scene pass).
    pub layers: Buffer,
    /// B_i per region (rgb).
    pub energy: Buffer,
    /// `RegionBasis` per group and region.
    pub region_basis: Buffer,
    /// Per receiver group: its first layer and layer count.
    pub ranges: Vec<(u32, u32)>,
    /// The layers in use this frame, as uploaded to `layers`.
    in_use: Vec<OcclusionLayer>,
    /// Pairs that were wanted but did not fit in `capacity` this frame (least energy first).
    pub dropped: usize,
}

const MASK_FORMAT: vk::Format = vk::Format::R32G32_SFLOAT;
// The scene pass reads the layers from a uniform buffer (16 KiB on every device) and keeps one
// bit per layer in 32-bit words.
const _: () = assert!(constants::MAX_OCCLUSION_LAYERS as usize * size_of::<OcclusionLayer>() <= 16 * 1024);
const _: () = assert!(constants::MAX_OCCLUSION_LAYERS % 32 == 0);

fn layered(
    ctx: &Arc<Context>,
    name: &str,
    size: u32,
    layers: u32,
    usage: vk::ImageUsageFlags,
) -> Result<Image> {
    Image::new(
        ctx,
        &ImageDesc::square_array(name, size, layers, MASK_FORMAT, usage | vk::ImageUsageFlags::STORAGE),
    )
}

fn host_buffer(ctx: &Arc<Context>, name: &str, size: usize) -> Result<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc {
            name,
            size: size.max(16) as u64,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::UNIFORM_BUFFER,
            location: MemoryLocation::CpuToGpu,
        },
    )
}

/// Two unit vectors completing `w` to an orthonormal basis.
fn plane_axes(w: Vec3) -> (Vec3, Vec3) {
    let helper = if w.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let u = helper.cross(w).normalize();
    (u, w.cross(u))
}

impl Occlusion {
    /// `regions` may be empty (Sloan's PRT: no occlusion between groups); `resolution` is the
    /// side of a mask layer in texels; at most `capacity` layers are filtered per frame.
    pub fn new(
        ctx: &Arc<Context>,
        regions: Regions,
        bands: usize,
        bounds: Vec<GroupBounds>,
        resolution: u32,
        capacity: u32,
        penumbra: Penumbra,
    ) -> Result<Occlusion> {
        let q = regions.regions.len();
        let groups = bounds.len();
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
            mask_pipeline: GraphicsPipeline::new(
                ctx,
                &GraphicsDesc {
                    name: "occluder_mask",
                    vertex_spirv: spirv::OCCLUDER_MASK_VERT,
                    fragment_spirv: spirv::OCCLUDER_MASK_FRAG,
                    bindings: &[BindingKind::StorageBuffer],
                    push_size: size_of::<MaskPush>() as u32,
                    vertex_buffers: &[MESH_POSITIONS],
                    topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                    color_formats: &[MASK_FORMAT],
                    depth_format: None,
                    depth: DepthTest::Off,
                    additive: false,
                    constants: &[],
                },
            )?,
            blur: ComputePipeline::new(
                ctx,
                "occlusion_blur",
                spirv::OCCLUSION_BLUR_COMP,
                &[BindingKind::StorageBuffer, BindingKind::StorageImage, BindingKind::StorageImage],
                size_of::<BlurPush>() as u32,
            )?,
            mask: layered(
                ctx,
                "occlusion.mask",
                resolution,
                layer_count,
                vk::ImageUsageFlags::COLOR_ATTACHMENT,
            )?,
            temp: layered(ctx, "occlusion.temp", resolution, layer_count, vk::ImageUsageFlags::empty())?,
            filtered: layered(
                ctx,
                "occlusion.filtered",
                resolution,
                layer_count,
                vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_SRC,
            )?,
            // The fixed penumbra samples filtered coverage (the edge texel continues it); the
            // adaptive one a summed-area table (zero before its first texel).
            sampler: match penumbra {
                Penumbra::Fixed => Sampler::new(ctx, "occlusion.sampler", true, Edge::Clamp, Edge::Clamp)?,
                Penumbra::Adaptive => Sampler::new(ctx, "occlusion.sampler", true, Edge::Black, Edge::Black)?,
            },
            penumbra,
            layers: host_buffer(ctx, "occlusion.layers", layer_count as usize * size_of::<OcclusionLayer>())?,
            energy,
            region_basis: host_buffer(ctx, "occlusion.region_basis", groups * q * size_of::<RegionBasis>())?,
            ranges: vec![(0, 0); groups],
            in_use: Vec::new(),
            dropped: 0,
            regions,
            bands,
            bounds,
            resolution,
            capacity,
        })
    }

    /// This frame's layers, in the order of the layer images.
    pub fn layers_in_use(&self) -> &[OcclusionLayer] {
        &self.in_use
    }

    pub fn region_count(&self) -> usize {
        self.regions.regions.len()
    }

    /// Chooses this frame's layers and uploads them, with each group's region basis.
    pub fn update(&mut self, transforms: &[Mat4], env: Mat3) -> Result<()> {
        let q = self.region_count();
        let world: Vec<(Vec3, f32)> = self
            .bounds
            .iter()
            .zip(transforms)
            .map(|(b, t)| (t.transform_point3(b.centre), b.radius * t.x_axis.truncate().length()))
            .collect();
        let directions: Vec<Vec3> =
            self.regions.regions.iter().map(|r| env * r.direction.as_vec3()).collect();

        let mut jobs = Vec::new();
        for (r, &(receiver_centre, receiver_radius)) in world.iter().enumerate() {
            let to_object = rotation_of(&transforms[r]).transpose();
            for (i, region) in self.regions.regions.iter().enumerate() {
                let energy = region.energy.iter().sum::<f64>();
                let w = directions[i];
                if energy <= 0.0 || self.bounds[r].faces_away_from(to_object * w) {
                    continue;
                }
                for (o, &(occluder_centre, occluder_radius)) in
                    world.iter().enumerate().filter(|&(o, _)| o != r)
                {
                    if self.bounds[o].reach_along(&transforms[o], receiver_centre, w) <= 0.0 {
                        continue;
                    }
                    let offset = occluder_centre - receiver_centre;
                    let along = offset.dot(w);
                    let root_omega = (region.solid_angle as f32).sqrt();
                    // Fixed: the box width of eq. (13). Adaptive: the widest box a pixel can
                    // ask for (blocker search), from the occluder's top to the receiver's bottom.
                    let width = match self.penumbra {
                        Penumbra::Fixed => root_omega * along.max(0.0),
                        Penumbra::Adaptive => {
                            root_omega
                                * (self.bounds[o].reach_along(&transforms[o], receiver_centre, w)
                                    + receiver_radius)
                        }
                    };
                    if (offset - along * w).length() > occluder_radius + receiver_radius + 0.5 * width {
                        continue;
                    }
                    let half_extent = receiver_radius + 0.5 * width;
                    let texels = width / (2.0 * half_extent) * self.resolution as f32;
                    let odd = 2.0 * (0.5 * texels).round() + 1.0;
                    let (u, v) = plane_axes(w);
                    let scale = 1.0 / (2.0 * half_extent);
                    // The box (or blocker search) reaches half its odd width beyond the
                    // occluder's silhouette, and bilinear filtering one texel more.
                    let reach = occluder_radius * scale + (0.5 * odd + 1.0) / self.resolution as f32;
                    jobs.push(Job {
                        receiver: r,
                        weight: energy,
                        layer: OcclusionLayer {
                            centre: receiver_centre.extend(scale).to_array(),
                            axis_u: u.extend(odd).to_array(),
                            axis_v: v.extend(root_omega).to_array(),
                            footprint: [offset.dot(u) * scale + 0.5, offset.dot(v) * scale + 0.5, reach, 0.0],
                            ids: [i as u32, r as u32, o as u32, 0],
                        },
                    });
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
        jobs.sort_by_key(|j| (j.receiver, j.layer.ids[0]));
        self.ranges.iter_mut().for_each(|r| *r = (0, 0));
        for (l, job) in jobs.iter().enumerate() {
            let range = &mut self.ranges[job.receiver];
            if range.1 == 0 {
                range.0 = l as u32;
            }
            range.1 += 1;
        }
        self.in_use = jobs.iter().map(|j| j.layer).collect();
        if !self.in_use.is_empty() {
            self.layers.write(0, bytes_of_slice(&self.in_use))?;
        }

        // The SH basis at each region's direction in each group's frame (exact, on the host).
        let mut basis = Vec::with_capacity(transforms.len() * q);
        let mut y = [0.0f32; 25];
        for transform in transforms {
            let to_object = rotation_of(transform).transpose();
            for w in &directions {
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
        let blur = move |cmd, horizontal: bool, source: &Image, target: &Image| {
            let mode = (self.penumbra == Penumbra::Adaptive) as u32;
            let push = BlurPush { params: [u32::from(!horizontal), self.resolution, count, mode] };
            self.blur.dispatch(
                cmd,
                &[
                    Binding::Storage(&self.layers),
                    Binding::StorageImage(source),
                    Binding::StorageImage(target),
                ],
                bytes_of(&push),
                groups,
            );
        };
        vec![
            Pass::new("occluder_masks", &[], &["occlusion_masks"], move |cmd| {
                for (l, layer) in self.in_use.iter().enumerate() {
                    let occluder = layer.ids[2] as usize;
                    let target = Target { image: &self.mask, layer: l as u32 };
                    ctx.begin_rendering(cmd, Some(target), Some([0.0; 4]), None);
                    self.mask_pipeline.bind(cmd, &[Binding::Storage(&self.layers)]);
                    for mesh in scene.meshes.iter().filter(|m| m.group == occluder) {
                        let push = MaskPush {
                            model: scene.transforms[occluder].to_cols_array_2d(),
                            layer: [l as u32, 0, 0, 0],
                        };
                        self.mask_pipeline.push(cmd, bytes_of(&push));
                        ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
                    }
                    ctx.end_rendering(cmd);
                }
            }),
            Pass::new("blur_horizontal", &["occlusion_masks"], &["occlusion_half"], move |cmd| {
                blur(cmd, true, &self.mask, &self.temp)
            }),
            Pass::new("blur_vertical", &["occlusion_half"], &["occlusion"], move |cmd| {
                blur(cmd, false, &self.temp, &self.filtered)
            }),
        ]
    }
}

/// The object-space bounds of every group.
pub fn group_bounds(scene: &crate::scene::Scene) -> Vec<GroupBounds> {
    scene
        .groups
        .iter()
        .map(|g| {
            let points = || g.meshes.iter().flat_map(|m| m.positions.iter().map(|p| Vec3::from_array(*p)));
            let normals = || g.meshes.iter().flat_map(|m| m.normals.iter().map(|n| Vec3::from_array(*n)));
            let (min, max) =
                points().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
            let (min, max) = if min.x <= max.x { (min, max) } else { (Vec3::ZERO, Vec3::ZERO) };
            let centre = 0.5 * (min + max);
            let radius = points().map(|p| p.distance(centre)).fold(0.0, f32::max);
            let sum: Vec3 = normals().sum();
            let normal_axis = sum.try_normalize().unwrap_or(Vec3::Y);
            let normal_spread = if sum.length_squared() > 0.0 {
                normals().map(|n| normal_axis.dot(n).clamp(-1.0, 1.0).acos()).fold(0.0, f32::max)
            } else {
                std::f32::consts::PI
            };
            GroupBounds { centre, radius, min, max, normal_axis, normal_spread }
        })
        .collect()
}
