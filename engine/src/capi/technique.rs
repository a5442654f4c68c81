//! Choosing a technique and its parameters, and the precomputation it needs.
use super::args;
use super::context::kage_context;
use super::handles;
use super::result::{boundary, kage_result, Failure};
use super::scene::kage_scene;
use crate::prt::{transfer, PrtParams};
use crate::techniques::asm::technique::AsmTest;
use crate::techniques::asm::AsmSettings;
use crate::techniques::description::{TechniqueKind, TechniqueSettings};
use crate::techniques::probes::{
    CaptureSettings, CapturedLight, Dering, ProbeInterpolation, ProbePlacement, ProbeSettings,
    StaticLighting, DEFAULT_GRID, DEFAULT_TOLERANCE,
};
use crate::techniques::tamura::technique::Penumbra;
use glam::DVec3;
use std::sync::Arc;

/// The lighting techniques (the values of `kage_technique_desc.technique`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_technique {
    /// SH irradiance, no shadows.
    Unshadowed = 0,
    /// Sloan et al. 2002: per-vertex PRT, self-shadowing within each group only. Needs
    /// `kage_precompute`.
    SloanSelf = 1,
    /// Tamura, Johan, Nishita: PRT plus soft shadows between moving groups from `regions`
    /// environment regions, the `dominant_lights` brightest small lights of the map (a sun,
    /// lamps) taken out and lit per pixel with soft shadows. Needs `kage_precompute`.
    Tamura = 2,
    /// Baseline: `regions` environment regions as directional lights with binary shadow maps.
    ParallelLights = 3,
    /// Morishige 2014: light probes (`probe_placement`), captured as SH when the renderer is
    /// created, light the scene's first group (the moving one); the other groups are lit as
    /// `probe_statics` says.
    Probes = 4,
    /// The scene's point and spot lights with hard shadows from one conventional shadow map of
    /// `shadow_map_size`² texels per light (1 to 8 lights).
    ShadowMap = 5,
    /// Adaptive shadow maps (Fernando et al. 2001) for the scene's one point or spot light:
    /// a quadtree of tiles in a page pool of `asm_budget_mb`, refined where the eye sees shadow
    /// edges coarser than its pixels, `asm_time_ms` of tile rendering per frame.
    Asm = 6,
    /// Sloan et al. 2002 as the Tamura paper compares against: per-vertex PRT with the whole
    /// scene's visibility at its pose when `kage_precompute` ran (shadows between groups baked
    /// into the vertices; they stay where they were when groups move). Needs `kage_precompute`.
    SloanScene = 7,
    /// Tamura, Johan, Nishita as the paper has it: `regions` regions, the fixed penumbra from
    /// each region's solid angle, no dominant lights (`penumbra` and `dominant_lights` are not
    /// read). Needs `kage_precompute`.
    TamuraPaper = 8,
}

/// What the light probes capture (the values of `kage_technique_desc.probe_light`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_probe_light {
    /// The environment where the probe sees it, plus the static groups as Kage's ray caster
    /// lights them (environment and local lights with shadows, one bounce between them).
    SkyAndWalls = 0,
    /// The environment where the probe sees it; the static groups only occlude it.
    Sky = 1,
}

/// The shadow test of adaptive shadow maps (the values of `kage_technique_desc.asm_test`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_asm_test {
    /// The depth comparison with a slope-scaled bias.
    Bias = 0,
    /// The paper's polygon-ID comparison, depth with bias as fallback.
    Id = 1,
}

/// Width of Tamura's penumbrae (the values of `kage_technique_desc.penumbra`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_penumbra {
    /// The paper's: one filter width per group pair and region.
    Fixed = 0,
    /// A width per pixel from its distance to the occluder.
    Adaptive = 1,
}

/// Where the light probes go (the values of `kage_technique_desc.probe_placement`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_probe_placement {
    /// `probe_grid` probes at the cell centres of that grid over the static groups' bounding box.
    Grid = 0,
    /// Candidates at the cell centres of a grid (`probe_candidates`; all 0: 8 along the box's
    /// longest side, proportionally fewer along the others) outside solids are captured, then
    /// those the others reproduce within `probe_tolerance` are dropped, the kept ones moved to
    /// nearby candidates while that lowers the error over all of them and their SH fitted to
    /// every capture; `kage_renderer_get_stats` reports how many remain.
    Auto = 1,
    /// The `probe_position_count` world positions at `probe_positions`.
    Positions = 2,
}

/// How the light between probes is found (the values of `kage_technique_desc.probe_interpolation`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_probe_interpolation {
    /// Barycentric weights of the Delaunay tetrahedron holding the point (Morishige 2014).
    Tetrahedral = 0,
    /// Trilinear weights of the grid cell holding the point: `KAGE_PROBE_PLACEMENT_GRID` only.
    Trilinear = 1,
}

/// The window on each probe's SH against ringing (the values of `kage_technique_desc.probe_dering`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_probe_dering {
    /// The SH as captured; the shading clamps negative irradiance at 0.
    Off = 0,
    /// The gentlest window that keeps every probe's irradiance nonnegative.
    NonNegative = 1,
    /// Hanning window of width `probe_dering_width` bands (Sloan 2008).
    Hanning = 2,
    /// Lanczos window of width `probe_dering_width` bands (Sloan 2008).
    Lanczos = 3,
}

/// How the probes technique lights the static groups (the values of
/// `kage_technique_desc.probe_statics`).
#[repr(u32)]
#[derive(Clone, Copy)]
pub enum kage_static_lighting {
    /// The environment's SH irradiance, unshadowed.
    Unshadowed = 0,
    /// Sloan's PRT, self-shadowed among the static groups.
    Sloan = 1,
}

/// A technique and all its parameters; each technique reads the fields it uses and ignores the
/// rest. Start from `kage_technique_desc_default` and change what you need: fields added in
/// later versions come with defaults there, so such a host needs no other change than a
/// recompile.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct kage_technique_desc {
    /// A `kage_technique` value.
    pub technique: u32,
    /// SH bands of the PRT transfer (Sloan, Tamura), 2 to 5; default 3.
    pub sh_bands: u32,
    /// Visibility rays per vertex of the PRT precomputation, 1 to 1048576; default 2048.
    pub prt_rays: u32,
    /// q, environment regions: Tamura 1 to 64, parallel-lights 1 to 128; default 32.
    pub regions: u32,
    /// Side of a Tamura occlusion mask layer in texels; default 128.
    pub mask_size: u32,
    /// A `kage_penumbra` value (Tamura); default fixed.
    pub penumbra: u32,
    /// Side of a shadow map in texels: parallel-lights 16 to 2048, shadowmap 16 to 8192;
    /// default 512.
    pub shadow_map_size: u32,
    /// Light probes along X, Y and Z, 2 to 64 each, at the cell centres of that grid over the
    /// static groups' bounding box; default 3, 2, 3.
    pub probe_grid: [u32; 3],
    /// Texels per side of a probe's cube-map face, 8 to 256; default 128.
    pub probe_cube_size: u32,
    /// A `kage_probe_light` value; default sky and walls.
    pub probe_light: u32,
    /// Adaptive shadow maps: the page pool's budget in MB (MiB), never exceeded; default 16.
    pub asm_budget_mb: f64,
    /// Adaptive shadow maps: tile rendering time per frame in ms; default 8.
    pub asm_time_ms: f64,
    /// A `kage_asm_test` value; default bias.
    pub asm_test: u32,
    /// A `kage_probe_placement` value; default grid.
    pub probe_placement: u32,
    /// Automatic placement's candidate grid along X, Y and Z (2 to 64 each), or all 0 for its
    /// default; default 0, 0, 0.
    pub probe_candidates: [u32; 3],
    /// Automatic placement's tolerance: the relative irradiance error below which a probe the
    /// others reproduce is dropped; default 0.05.
    pub probe_tolerance: f32,
    /// `KAGE_PROBE_PLACEMENT_POSITIONS`: x, y, z of each probe, read during
    /// `kage_renderer_create` only; default NULL.
    pub probe_positions: *const f32,
    /// Probes at `probe_positions`; default 0.
    pub probe_position_count: u32,
    /// A `kage_probe_interpolation` value; default tetrahedral.
    pub probe_interpolation: u32,
    /// Reflections of the walls' light the probes capture (sky and walls): 1 or 2; default 2.
    pub probe_bounces: u32,
    /// Monte Carlo samples per wall vertex and bounce of the probes' capture; default 256.
    pub probe_samples: u32,
    /// A `kage_probe_dering` value; default off.
    pub probe_dering: u32,
    /// The Hanning or Lanczos window's width in bands (> 0); default 0 (unused).
    pub probe_dering_width: f32,
    /// A `kage_static_lighting` value: how the probes technique lights the static groups;
    /// default unshadowed. Sloan's PRT needs `kage_precompute` (with `sh_bands`, `prt_rays`).
    pub probe_statics: u32,
    /// Tamura: most dominant lights lit per pixel, 0 to 8 (they count among `regions`);
    /// default 4.
    pub dominant_lights: u32,
    /// Tamura: side of a group's depth map along a dominant light in texels, 16 to 4096;
    /// default 512.
    pub light_map_size: u32,
}

impl kage_technique_desc {
    /// # Safety
    /// With `KAGE_PROBE_PLACEMENT_POSITIONS`, `probe_positions` must be NULL or readable for
    /// `probe_position_count` × 3 floats.
    pub(crate) unsafe fn settings(&self) -> Result<TechniqueSettings, Failure> {
        use kage_technique as T;
        let kind = args::enumeration(
            self.technique,
            "technique",
            &[
                (T::Unshadowed as u32, TechniqueKind::Unshadowed),
                (T::SloanSelf as u32, TechniqueKind::SloanSelf),
                (T::SloanScene as u32, TechniqueKind::SloanScene),
                (T::Tamura as u32, TechniqueKind::Tamura),
                (T::TamuraPaper as u32, TechniqueKind::TamuraPaper),
                (T::ParallelLights as u32, TechniqueKind::ParallelLights),
                (T::ShadowMap as u32, TechniqueKind::ShadowMap),
                (T::Probes as u32, TechniqueKind::Probes),
                (T::Asm as u32, TechniqueKind::Asm),
            ],
        )?;
        let probe_light = args::enumeration(
            self.probe_light,
            "probe_light",
            &[
                (kage_probe_light::SkyAndWalls as u32, CapturedLight::SkyAndWalls),
                (kage_probe_light::Sky as u32, CapturedLight::Sky),
            ],
        )?;
        let asm_test = args::enumeration(
            self.asm_test,
            "asm_test",
            &[(kage_asm_test::Bias as u32, AsmTest::Bias), (kage_asm_test::Id as u32, AsmTest::Id)],
        )?;
        let penumbra = args::enumeration(
            self.penumbra,
            "penumbra",
            &[
                (kage_penumbra::Fixed as u32, Penumbra::Fixed),
                (kage_penumbra::Adaptive as u32, Penumbra::Adaptive),
            ],
        )?;
        let placement = match args::enumeration(
            self.probe_placement,
            "probe_placement",
            &[
                (kage_probe_placement::Grid as u32, kage_probe_placement::Grid),
                (kage_probe_placement::Auto as u32, kage_probe_placement::Auto),
                (kage_probe_placement::Positions as u32, kage_probe_placement::Positions),
            ],
        )? {
            kage_probe_placement::Grid => ProbePlacement::Grid(self.probe_grid),
            kage_probe_placement::Auto => ProbePlacement::Auto {
                tolerance: self.probe_tolerance,
                candidates: (self.probe_candidates != [0; 3]).then_some(self.probe_candidates),
            },
            kage_probe_placement::Positions => {
                let count = self.probe_position_count as usize;
                // SAFETY: the caller promises NULL or `count` × 3 readable floats.
                let points = unsafe { args::chunks::<3>(self.probe_positions, count, "probe_positions") }?;
                ProbePlacement::Positions(points.iter().map(|&p| DVec3::from(p.map(f64::from))).collect())
            }
        };
        let interpolation = args::enumeration(
            self.probe_interpolation,
            "probe_interpolation",
            &[
                (kage_probe_interpolation::Tetrahedral as u32, ProbeInterpolation::Tetrahedral),
                (kage_probe_interpolation::Trilinear as u32, ProbeInterpolation::Trilinear),
            ],
        )?;
        let width = self.probe_dering_width;
        let dering = args::enumeration(
            self.probe_dering,
            "probe_dering",
            &[
                (kage_probe_dering::Off as u32, Dering::Off),
                (kage_probe_dering::NonNegative as u32, Dering::NonNegative),
                (kage_probe_dering::Hanning as u32, Dering::Hanning(width)),
                (kage_probe_dering::Lanczos as u32, Dering::Lanczos(width)),
            ],
        )?;
        Ok(TechniqueSettings {
            kind,
            prt: PrtParams { bands: self.sh_bands, rays: self.prt_rays, ..PrtParams::DEFAULT },
            regions: self.regions as usize,
            mask_size: self.mask_size,
            penumbra,
            dominant_lights: self.dominant_lights as usize,
            light_map_size: self.light_map_size,
            shadow_map_size: self.shadow_map_size,
            probes: ProbeSettings {
                placement,
                capture: CaptureSettings {
                    cube_size: self.probe_cube_size,
                    light: probe_light,
                    bounces: self.probe_bounces,
                    samples: self.probe_samples,
                    dering,
                },
                interpolation,
                statics: args::enumeration(
                    self.probe_statics,
                    "probe_statics",
                    &[
                        (kage_static_lighting::Unshadowed as u32, StaticLighting::Unshadowed),
                        (kage_static_lighting::Sloan as u32, StaticLighting::Sloan),
                    ],
                )?,
            },
            asm: AsmSettings { budget_mb: self.asm_budget_mb, time_ms: self.asm_time_ms, test: asm_test },
        }
        .validated()?)
    }
}

/// Fills `*desc` with `technique` and the default of every parameter.
///
/// # Safety
/// `desc` must be NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_technique_desc_default(
    technique: u32,
    desc: *mut kage_technique_desc,
) -> kage_result {
    boundary(|| {
        // SAFETY: the caller promises NULL or writable.
        let desc = unsafe { args::out(desc, "desc") }?;
        let d = TechniqueSettings::default();
        let filled = kage_technique_desc {
            technique,
            sh_bands: d.prt.bands,
            prt_rays: d.prt.rays,
            regions: d.regions as u32,
            mask_size: d.mask_size,
            penumbra: kage_penumbra::Fixed as u32,
            shadow_map_size: d.shadow_map_size,
            probe_grid: DEFAULT_GRID,
            probe_cube_size: d.probes.capture.cube_size,
            probe_light: kage_probe_light::SkyAndWalls as u32,
            asm_budget_mb: d.asm.budget_mb,
            asm_time_ms: d.asm.time_ms,
            asm_test: match d.asm.test {
                AsmTest::Bias => kage_asm_test::Bias as u32,
                AsmTest::Id => kage_asm_test::Id as u32,
            },
            probe_placement: kage_probe_placement::Grid as u32,
            probe_candidates: [0; 3],
            probe_tolerance: DEFAULT_TOLERANCE,
            probe_positions: std::ptr::null(),
            probe_position_count: 0,
            probe_interpolation: kage_probe_interpolation::Tetrahedral as u32,
            probe_bounces: d.probes.capture.bounces,
            probe_samples: d.probes.capture.samples,
            probe_dering: kage_probe_dering::Off as u32,
            probe_dering_width: 0.0,
            probe_statics: kage_static_lighting::Unshadowed as u32,
            dominant_lights: d.dominant_lights as u32,
            light_map_size: d.light_map_size,
        };
        // An unknown technique is reported here already, not at the first use.
        // SAFETY: the default places no probes at positions.
        unsafe { filled.settings() }?;
        *desc = filled;
        Ok(())
    })
}

/// Computes on the context's device what `technique` needs before its first frame, and keeps
/// it in the scene for `kage_renderer_create`: for Sloan and Tamura the per-vertex PRT transfer
/// (seconds to minutes: it casts `prt_rays` rays per vertex; for `KAGE_TECHNIQUE_SLOAN_SCENE`
/// against the whole scene as its group transforms stand); for the other techniques nothing.
/// A later call replaces what an earlier one computed.
///
/// The scene keeps no reference to the context.
///
/// # Safety
/// `context` and `scene` must be NULL or handles not in use by another thread; `technique` NULL
/// or a valid desc.
#[no_mangle]
pub unsafe extern "C" fn kage_precompute(
    context: *const kage_context,
    scene: *mut kage_scene,
    technique: *const kage_technique_desc,
) -> kage_result {
    boundary(|| {
        // SAFETY: the host does not destroy or share the handles during the call.
        let (context, scene) =
            unsafe { (handles::get(context, "context")?, handles::get_mut(scene, "scene")?) };
        // SAFETY: the caller promises NULL or a valid desc (its probe positions included).
        let settings = unsafe { args::value(technique, "technique")?.settings() }?;
        if let Some(params) = settings.precomputation() {
            let set = transfer::precompute(&context.ctx, &scene.scene, params, &mut |_, _| {});
            kage_context::check_validation(&context.ctx)?;
            scene.transfer = Some(Arc::new(set?));
        }
        Ok(())
    })
}
