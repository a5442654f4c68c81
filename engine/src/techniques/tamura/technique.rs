//! The PRT scene technique: self-shadowed radiance per vertex (Sloan et al.), minus, with
//! regions, the light other groups block (Tamura et al. eq. (15)).
use super::dominant;

use super::dominant_maps::{self, DominantMaps};

use super::occlusion::{Occlusion, RegionSize};
use super::sheet::Sheet;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferUsage, Cmd, Context, Depth, DepthTest, Edge, GraphicsDesc,
    GraphicsPipeline, Sampler, Topology, VertexBuffer,
};
use crate::error::{Error, Result};
use crate::frame::bounds::{env_rotation, group_bounds};
use crate::frame::environment::GpuEnvironment;
use crate::frame::gpu_scene::{MESH_ATTRIBUTES, MESH_VERTICES};
use crate::frame::irradiance::gpu_irradiance;
use crate::frame::regions::Regions;
use crate::frame::scene_pass::{bind_lit, depth_prepass, depth_prepass_pipeline, lit_bindings};
use crate::frame::{FrameInputs, FrameState};
use crate::frame::{GpuScene, COLOR_FORMAT, DEPTH_FORMAT};

use crate::layouts::{bytes_of, constants, spirv, PrtDrawPush, ShCoeffs};
use crate::pass::Pass;
use crate::prt::TransferSet;
use crate::scene::Scene;

use crate::techniques::sloan::self_shadow::{transfer_vertex_buffer, SelfShadow, TRANSFER_STRIDE};
use crate::techniques::{Technique, TechniqueStats};
use glam::Mat4;
use std::sync::Arc;

/// How wide the penumbra of a shadow between groups is.
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Penumbra {
    /// The paper's: one box width per (receiver, occluder, region), s = sqrt(Ω_i)·R with R
    /// measured between the group centres (eqs. (12)–(13)).
    #[default]
    Fixed = 0,
    /// Beyond the paper: the same two 1D passes leave boxes of three widths, and each pixel
    /// takes a box as wide as sqrt(Ω_i) times its own distance to the occluder (interpolated
    /// between them), so shadows sharpen at contact and soften with distance.
    Adaptive = 1,
}

/// Settings of the occlusion between groups, each defined here once: the command line takes
/// those it exposes as options (these comments are their help), the C ABI as
/// `kage_technique_desc` fields.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct OcclusionSettings {
    /// Environment regions q of the Tamura technique (1 to 64) or of parallel-lights (1 to 128).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = OcclusionSettings::default().regions))]
    pub regions: usize,
    /// Side of a Tamura occlusion mask layer, texels.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = OcclusionSettings::default().mask_size))]
    pub mask_size: u32,
    /// Most layers filtered per frame.
    #[cfg_attr(feature = "clap", arg(skip = OcclusionSettings::default().max_layers))]
    pub max_layers: u32,
    /// Penumbra of the Tamura shadows: `fixed` (the paper's box width per group pair) or
    /// `adaptive` (a width per pixel from its distance to the occluder).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = OcclusionSettings::default().penumbra))]
    pub penumbra: Penumbra,
    /// Which solid angle sets a region's box width.
    #[cfg_attr(feature = "clap", arg(skip = OcclusionSettings::default().size))]
    pub size: RegionSize,
    /// Most dominant lights (small, bright parts of the map: a sun, lamps) Tamura takes out of
    /// the map and lights per pixel with soft shadows, 0 to 8; they count among the regions
    /// (0: the paper's technique).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = OcclusionSettings::default().dominant_lights))]
    pub dominant_lights: usize,
    /// Side of a group's depth map along a dominant light, texels (16 to 4096).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = OcclusionSettings::default().light_map_size))]
    pub light_map_size: u32,
    /// The unshadowed light per pixel, from the exact irradiance of L_s's map (`frame::irradiance`),
    /// only what the group hides of it interpolated from the vertices (beyond the paper, whose
    /// L_s is per vertex and in 3-band SH).
    #[cfg_attr(feature = "clap", arg(skip = OcclusionSettings::default().pixel_cosine))]
    pub pixel_cosine: bool,
}

impl Default for OcclusionSettings {
    fn default() -> Self {
        OcclusionSettings {
            regions: 32,
            mask_size: 128,
            max_layers: constants::MAX_OCCLUSION_LAYERS,
            penumbra: Penumbra::Fixed,
            size: RegionSize::Energy,
            dominant_lights: 4,
            light_map_size: dominant_maps::DEFAULT_MAP_SIZE,
            pixel_cosine: true,
        }
    }
}

impl OcclusionSettings {
    /// The technique as published: q = `regions` regions on masks of `mask_size`² texels, one
    /// box width per group pair from each region's solid angle, no dominant lights, the cosine
    /// per vertex.
    pub fn paper(regions: usize, mask_size: u32) -> OcclusionSettings {
        OcclusionSettings {
            regions,
            mask_size,
            penumbra: Penumbra::Fixed,
            size: RegionSize::Geometric,
            dominant_lights: 0,
            pixel_cosine: false,
            ..OcclusionSettings::default()
        }
    }

    /// Checks every setting (0 regions is Sloan's PRT: see [`crate::techniques::sloan`]).
    pub fn validated(self) -> Result<OcclusionSettings> {
        let invalid = |message: String| Err(Error::InvalidArgument(message));
        if self.regions > constants::MAX_REGIONS as usize {
            return invalid(format!(
                "{} regions: the Tamura technique interpolates at most {} per vertex",
                self.regions,
                constants::MAX_REGIONS
            ));
        }
        if self.max_layers > constants::MAX_OCCLUSION_LAYERS {
            return invalid(format!(
                "{} occlusion layers: at most {} fit the uniform buffer",
                self.max_layers,
                constants::MAX_OCCLUSION_LAYERS
            ));
        }
        if !(8..=2048).contains(&self.mask_size) {
            return invalid(format!("mask size {} must be 8 to 2048 texels", self.mask_size));
        }
        let max = constants::MAX_DOMINANT_LIGHTS as usize;
        if self.dominant_lights > max {
            return invalid(format!(
                "dominant lights: {} is more than the {max} Tamura lights per pixel",
                self.dominant_lights
            ));
        }
        let sizes = dominant_maps::MAP_SIZES;
        if !sizes.contains(&self.light_map_size) {
            return invalid(format!(
                "light map size {} must be {} to {} texels",
                self.light_map_size,
                sizes.start(),
                sizes.end()
            ));
        }
        Ok(self)
    }
}

pub struct PrtTechnique {
    /// The groups it lights, by index: all (`None`) unless another technique lights some (see
    /// `for_groups`).
    drawn: Option<Vec<bool>>,
    self_shadow: SelfShadow,
    occlusion: Occlusion,
    dominant: DominantMaps,
    scene_pipeline: GraphicsPipeline,
    /// Lays the depth down before the scene pass, whose fragments are costly (a loop over the
    /// occlusion layers): hidden surfaces then cost no shading, whatever the draw order.
    prepass_pipeline: GraphicsPipeline,
    nearest: Sampler,
    /// The first 9 SH coefficients of the light L_s is made of (`ShCoeffs`, the map's frame).
    light_sh: Buffer,
    /// The exact irradiance of that light, read per pixel where `pixel_cosine` is on (else one
    /// unread texel).
    irradiance: GpuEnvironment,
}

impl PrtTechnique {
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        transfer: &TransferSet,
        settings: OcclusionSettings,
    ) -> Result<PrtTechnique> {
        let settings = settings.validated()?;
        let bands = transfer.params.bands as usize;
        // Without regions (Sloan's PRT) the whole map is the self-shadowed light.
        let max_lights = if settings.regions == 0 { 0 } else { settings.dominant_lights };
        let split = dominant::split(&scene.environment, max_lights);
        let residual = &split.residual;
        let env = crate::sh::project_equirect(residual.width(), residual.height(), residual.pixels(), bands)?;
        let region_count = settings.regions.saturating_sub(split.lights.len());
        let regions = if region_count == 0 {
            Regions { regions: Vec::new(), texel_region: Vec::new() }
        } else {
            Regions::new(residual, region_count)?
        };
        let lights = split.lights.len() as u32;
        let mut light_sh = ShCoeffs::default();
        for (c, rgb) in light_sh.c.iter_mut().zip(&env) {
            *c = [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, 0.0];
        }
        let transfer_attributes = transfer_vertex_buffer(MESH_ATTRIBUTES.len() as u32);
        let bounds = group_bounds(scene);
        let sheets = scene.groups.iter().map(Sheet::of).collect();
        // prt_scene.vert's pipeline constants: vec4s of region transfers and of SH coefficients.
        let region_vec4 = regions.regions.len().div_ceil(4).max(1) as u32;
        let basis_vec4 = (bands * bands).div_ceil(4) as u32;
        Ok(PrtTechnique {
            drawn: None,
            self_shadow: SelfShadow::new(ctx, gpu, transfer, env)?,
            occlusion: Occlusion::new(ctx, regions, &split.lights, bands, bounds.clone(), sheets, &settings)?,
            dominant: DominantMaps::new(ctx, split.lights, bounds, settings.light_map_size)?,
            scene_pipeline: GraphicsPipeline::new(
                ctx,
                &GraphicsDesc {
                    name: "scene_prt",
                    vertex_spirv: spirv::PRT_SCENE_VERT,
                    fragment_spirv: spirv::PRT_SCENE_FRAG,
                    bindings: &lit_bindings(&[
                        BindingKind::UniformBuffer,
                        BindingKind::SampledImage,
                        BindingKind::TexelBuffer,
                        BindingKind::UniformBuffer,
                        BindingKind::SampledImage,
                        BindingKind::UniformBuffer,
                        BindingKind::UniformBuffer,
                        BindingKind::SampledImage,
                        BindingKind::UniformBuffer,
                        BindingKind::SampledImage,
                    ]),
                    push_size: size_of::<PrtDrawPush>() as u32,
                    vertex_buffers: &[
                        MESH_VERTICES,
                        VertexBuffer { stride: TRANSFER_STRIDE, attributes: &transfer_attributes },
                    ],
                    topology: Topology::Triangles,
                    color_formats: &[COLOR_FORMAT],
                    depth_format: Some(DEPTH_FORMAT),
                    depth: DepthTest::LessOrEqual,
                    write_color: true,
                    constants: &[
                        (settings.penumbra == Penumbra::Adaptive) as u32,
                        region_vec4,
                        basis_vec4,
                        lights,
                        settings.pixel_cosine as u32,
                    ],
                },
            )?,
            prepass_pipeline: depth_prepass_pipeline(ctx, "prt.depth_prepass", size_of::<PrtDrawPush>())?,
            nearest: Sampler::new(ctx, "self_shadow.sampler", false, Edge::Clamp, Edge::Clamp)?,
            light_sh: Buffer::with_data(ctx, "prt.light_sh", BufferUsage::UNIFORM, bytes_of(&light_sh))?,
            irradiance: gpu_irradiance(ctx, settings.pixel_cosine.then_some(residual))?,
        })
    }
}

impl Technique for PrtTechnique {
    fn stats(&self) -> TechniqueStats {
        TechniqueStats {
            dropped_layers: self.occlusion.dropped + self.dominant.dropped,
            ..Default::default()
        }
    }

    fn update(&mut self, state: &FrameState) -> Result<()> {
        let env = env_rotation(state.env_rotation);
        let drawn = &self.drawn;
        self.self_shadow.update(state.transforms, env, |g| draws(drawn, g))?;
        self.dominant.update(state.transforms, env)?;
        self.occlusion.update(state.transforms, env)
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, uniforms, scene, targets) = (inputs.ctx, inputs.uniforms, inputs.scene, inputs.targets);
        let mut passes = self.prepasses(ctx, scene);
        passes.push(depth_prepass(inputs, &self.prepass_pipeline, move |_, model: &Mat4| PrtDrawPush {
            model: model.to_cols_array_2d(),
            ..Default::default()
        }));
        passes.push(Pass::new("scene", move |cmd| {
            ctx.begin_rendering(
                cmd,
                Some((&targets.color).into()),
                None,
                Some(Depth::Keep((&targets.depth).into())),
            );
            self.record_draws(ctx, cmd, uniforms, scene);
            ctx.end_rendering(cmd);
        }));
        passes
    }
}

/// Whether a [`PrtTechnique`] whose `drawn` is `drawn` lights group `group`.
fn draws(drawn: &Option<Vec<bool>>, group: usize) -> bool {
    drawn.as_ref().is_none_or(|drawn| drawn.get(group).copied().unwrap_or(false))
}

impl PrtTechnique {
    /// The technique lighting only the groups `drawn` keeps, by index (a group beyond its end is
    /// not drawn); their self-shadow texels are the only ones kept up to date.
    pub fn for_groups(self, drawn: Vec<bool>) -> PrtTechnique {
        PrtTechnique { drawn: Some(drawn), ..self }
    }

    /// The passes before the scene's: the self-shadow texels of the groups that turned, and
    /// the occlusion layers between groups (none for Sloan's PRT).
    pub fn prepasses<'a>(&'a self, ctx: &'a Arc<Context>, scene: &'a GpuScene) -> Vec<Pass<'a>> {
        let mut passes: Vec<Pass> = self.self_shadow.pass(ctx, scene).into_iter().collect();
        passes.extend(self.dominant.pass(ctx, scene));
        passes.extend(self.occlusion.passes(ctx, scene));
        passes
    }

    /// Records, inside a rendering scope, the meshes of the groups it lights with eq. (15)
    /// (Sloan's PRT where there are no regions).
    pub fn record_draws(&self, ctx: &Context, cmd: Cmd, uniforms: &Buffer, scene: &GpuScene) {
        let (occlusion, self_shadow) = (&self.occlusion, &self.self_shadow);
        let [lights, shadow] = self.dominant.bindings();
        bind_lit(
            cmd,
            &self.scene_pipeline,
            scene,
            &[
                Binding::Uniform(uniforms),
                Binding::Sampled(&self_shadow.texture, &self.nearest),
                Binding::Texel(&occlusion.region_basis),
                Binding::Uniform(&occlusion.energy),
                Binding::Sampled(&occlusion.filtered, &occlusion.sampler),
                Binding::Uniform(&occlusion.layers),
                lights,
                shadow,
                Binding::Uniform(&self.light_sh),
                Binding::Sampled(&self.irradiance.image, &self.irradiance.sampler),
            ],
        );
        let q = occlusion.region_count() as u32;
        for (i, mesh) in scene.meshes.iter().enumerate().filter(|(_, m)| draws(&self.drawn, m.group)) {
            let (first_layer, layer_count) = occlusion.ranges[mesh.group];
            let model = scene.transforms[mesh.group];
            // Groups scale uniformly (scene::Transform).
            let reach = mesh.longest_edge * model.x_axis.truncate().length();
            let push = PrtDrawPush {
                model: model.to_cols_array_2d(),
                albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], reach],
                mesh: [self_shadow.first_texel[i], constants::SELF_SHADOW_WIDTH, mesh.group as u32, q],
                layers: [first_layer, layer_count, self.dominant.slot(mesh.group), occlusion.resolution],
                covered: occlusion.covered[mesh.group],
            };
            scene.bind_albedo_map(cmd, &self.scene_pipeline, mesh);
            self.scene_pipeline.push(cmd, bytes_of(&push));
            ctx.draw_indexed(
                cmd,
                &[&mesh.vertices, &self_shadow.transfer[i]],
                &mesh.indices,
                mesh.index_count,
            );
        }
    }
}
