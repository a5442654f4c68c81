//! Choosing a technique and its parameters, and the precomputation it needs.
use super::args;
use super::context::kage_context;
use super::handles;
use super::result::{boundary, kage_result, Failure};
use super::scene::kage_scene;
use crate::host_memory;
use crate::prt::{cache, transfer, PrtParams};
use crate::techniques::asm::technique::AsmTest;
use crate::techniques::asm::{AsmSettings, AsmTimeBudget};
use crate::techniques::description::{TechniqueDesc, TechniqueKind, TechniqueParams};
use crate::techniques::parallel_lights::DEFAULT_SHADOW_MAP_SIZE;
use crate::techniques::probes::{
    self, CaptureSettings, CapturedLight, Dering, ProbeInterpolation, ProbePlacement, ProbeSettings,
    ProbeVisibility, StaticLighting, DEFAULT_GRID, DEFAULT_TOLERANCE,
};
use crate::techniques::tamura::technique::{OcclusionSettings, Penumbra};
use glam::DVec3;
use std::ffi::{c_char, c_void};
use std::path::PathBuf;
use std::sync::Arc;

/// Where the light probes go (the values of `kage_technique_desc.probe_placement`).
#[repr(u32)]
#[derive(Clone, Copy, strum::FromRepr)]
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

/// The window on each probe's SH against ringing (the values of `kage_technique_desc.probe_dering`).
#[repr(u32)]
#[derive(Clone, Copy, strum::FromRepr)]
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

/// A technique and all its parameters; each technique reads the fields it uses and ignores the
/// rest. Start from `kage_technique_desc_default` and change what you need: fields added in
/// later versions come with defaults there, so such a host needs no other change than a
/// recompile.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct kage_technique_desc {
    /// `sizeof(kage_technique_desc)` as the host's kage.h declares it: checked, so that a host built
    /// against another version of the header gets an error instead of a misread struct.
    pub size: u32,
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
    /// Adaptive shadow maps: tile rendering time per frame in ms; default 16 (as
    /// `kage_technique_desc_default` sets it).
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
    /// A `kage_probe_visibility` value: whether a moving group's probe lookup leaves out the
    /// probes its centre cannot see through the static groups; default rays.
    pub probe_visibility: u32,
    /// Adaptive shadow maps: levels of refinement asked for at shadow edges beyond the one
    /// whose texels match the eye pixel, 0 to 8; default 4.
    pub asm_extra_levels: u32,
    /// Adaptive shadow maps: tile rendering time per frame as a share of the GPU time of the
    /// frame's other passes, above 0 and at most 100 (the lesser of this and `asm_time_ms`
    /// bounds the tiles); default 1.
    pub asm_time_share: f64,
}

impl kage_technique_desc {
    /// The technique this desc names, with the fields it reads (the others are ignored),
    /// checked.
    ///
    /// # Safety
    /// With `KAGE_PROBE_PLACEMENT_POSITIONS`, `probe_positions` must be NULL or readable for
    /// `probe_position_count` × 3 floats.
    pub(crate) unsafe fn desc(&self) -> Result<TechniqueDesc, Failure> {
        // Checked here too for the desc inside a `kage_renderer_desc`.
        args::check_size::<kage_technique_desc>(self.size, "technique")?;
        let kind = args::enumeration(self.technique, "technique", TechniqueKind::from_repr)?;
        Ok(TechniqueDesc::from_params(kind, &HostParams(self))?.validated()?)
    }

    /// The probe fields.
    ///
    /// # Safety
    /// As [`Self::desc`].
    unsafe fn probe_settings(&self) -> Result<ProbeSettings, Failure> {
        let placement = match args::enumeration(
            self.probe_placement,
            "probe_placement",
            kage_probe_placement::from_repr,
        )? {
            kage_probe_placement::Grid => ProbePlacement::Grid(self.probe_grid),
            kage_probe_placement::Auto => ProbePlacement::Auto {
                tolerance: self.probe_tolerance,
                candidates: (self.probe_candidates != [0; 3]).then_some(self.probe_candidates),
            },
            kage_probe_placement::Positions => {
                let count = self.probe_position_count as usize;
                probes::check_count(count)
                    .map_err(|e| Failure::invalid(format!("probe_position_count: {e}")))?;
                // SAFETY: the caller promises NULL or `count` × 3 readable floats.
                let points = unsafe { args::chunks::<3>(self.probe_positions, count, "probe_positions") }?;
                let points = points.iter().map(|&p| DVec3::from(p.map(f64::from)));
                ProbePlacement::Positions(host_memory::collect(points, "probe_positions")?.into())
            }
        };
        let width = self.probe_dering_width;
        let dering = match args::enumeration(self.probe_dering, "probe_dering", kage_probe_dering::from_repr)?
        {
            kage_probe_dering::Off => Dering::Off,
            kage_probe_dering::NonNegative => Dering::NonNegative,
            kage_probe_dering::Hanning => Dering::Hanning(width),
            kage_probe_dering::Lanczos => Dering::Lanczos(width),
        };
        Ok(ProbeSettings {
            placement,
            capture: CaptureSettings {
                cube_size: self.probe_cube_size,
                light: args::enumeration(self.probe_light, "probe_light", CapturedLight::from_repr)?,
                bounces: self.probe_bounces,
                samples: self.probe_samples,
                dering,
            },
            interpolation: args::enumeration(
                self.probe_interpolation,
                "probe_interpolation",
                ProbeInterpolation::from_repr,
            )?,
            visibility: args::enumeration(
                self.probe_visibility,
                "probe_visibility",
                ProbeVisibility::from_repr,
            )?,
            statics: args::enumeration(self.probe_statics, "probe_statics", StaticLighting::from_repr)?,
        })
    }
}

/// A host's desc as the techniques' parameters. Made only inside [`kage_technique_desc::desc`],
/// whose caller promises that the probe positions are readable.
struct HostParams<'a>(&'a kage_technique_desc);

impl TechniqueParams for HostParams<'_> {
    type Error = Failure;
    fn prt(&self) -> Result<PrtParams, Failure> {
        Ok(PrtParams { bands: self.0.sh_bands, rays: self.0.prt_rays, ..PrtParams::DEFAULT })
    }
    fn regions(&self) -> usize {
        self.0.regions as usize
    }
    fn mask_size(&self) -> u32 {
        self.0.mask_size
    }
    fn occlusion(&self) -> Result<OcclusionSettings, Failure> {
        Ok(OcclusionSettings {
            regions: self.regions(),
            mask_size: self.mask_size(),
            penumbra: args::enumeration(self.0.penumbra, "penumbra", Penumbra::from_repr)?,
            dominant_lights: self.0.dominant_lights as usize,
            light_map_size: self.0.light_map_size,
            ..OcclusionSettings::default()
        })
    }
    fn shadow_map_size(&self) -> u32 {
        self.0.shadow_map_size
    }
    fn probes(&self) -> Result<ProbeSettings, Failure> {
        // SAFETY: `desc`'s caller promised the probe positions readable.
        unsafe { self.0.probe_settings() }
    }
    fn asm(&self) -> Result<AsmSettings, Failure> {
        Ok(AsmSettings {
            budget_mb: self.0.asm_budget_mb,
            time: AsmTimeBudget { time_ms: self.0.asm_time_ms, time_share: self.0.asm_time_share },
            test: args::enumeration(self.0.asm_test, "asm_test", AsmTest::from_repr)?,
            extra_levels: self.0.asm_extra_levels,
        })
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
        let (prt, occlusion) = (PrtParams::DEFAULT, OcclusionSettings::default());
        let (probes, asm) = (ProbeSettings::default(), AsmSettings::default());
        let filled = kage_technique_desc {
            size: size_of::<kage_technique_desc>() as u32,
            technique,
            sh_bands: prt.bands,
            prt_rays: prt.rays,
            regions: occlusion.regions as u32,
            mask_size: occlusion.mask_size,
            penumbra: occlusion.penumbra as u32,
            shadow_map_size: DEFAULT_SHADOW_MAP_SIZE,
            probe_grid: DEFAULT_GRID,
            probe_cube_size: probes.capture.cube_size,
            probe_light: probes.capture.light as u32,
            asm_budget_mb: asm.budget_mb,
            asm_time_ms: asm.time.time_ms,
            asm_test: asm.test as u32,
            probe_placement: kage_probe_placement::Grid as u32,
            probe_candidates: [0; 3],
            probe_tolerance: DEFAULT_TOLERANCE,
            probe_positions: std::ptr::null(),
            probe_position_count: 0,
            probe_interpolation: probes.interpolation as u32,
            probe_bounces: probes.capture.bounces,
            probe_samples: probes.capture.samples,
            probe_dering: kage_probe_dering::Off as u32,
            probe_dering_width: 0.0,
            probe_statics: probes.statics as u32,
            dominant_lights: occlusion.dominant_lights as u32,
            light_map_size: occlusion.light_map_size,
            probe_visibility: probes.visibility as u32,
            asm_extra_levels: asm.extra_levels,
            asm_time_share: asm.time.time_share,
        };
        // An unknown technique is reported here already, not at the first use.
        // SAFETY: the default places no probes at positions.
        unsafe { filled.desc() }?;
        *desc = filled;
        Ok(())
    })
}

/// Hears how far long work has come (`fraction`, 0 to 1, rising) and answers whether to go on:
/// false stops the work, and the call that started it returns `KAGE_RESULT_CANCELLED`, having
/// changed nothing. Called on the thread of that call, between steps of the work (about one
/// per submission to the device); `user` is the pointer the host gave beside it.
pub type kage_progress_fn = Option<unsafe extern "C" fn(user: *mut c_void, fraction: f64) -> bool>;

/// Calls the host's `progress` (when there is one) with the fraction `done` of `total`.
///
/// # Safety
/// `progress` NULL or a function that may be called with `user`.
pub(crate) unsafe fn report(
    progress: kage_progress_fn,
    user: *mut c_void,
    done: usize,
    total: usize,
) -> bool {
    let fraction = if total == 0 { 1.0 } else { done as f64 / total as f64 };
    // SAFETY: the caller's promise.
    progress.is_none_or(|progress| unsafe { progress(user, fraction) })
}

/// How `kage_precompute_with` caches and reports its work. All zero but `size`: no disk cache,
/// no progress.
#[repr(C)]
pub struct kage_precompute_options {
    /// `sizeof(kage_precompute_options)` as the host's kage.h declares it.
    pub size: u32,
    /// The PRT disk cache's folder (UTF-8), the one `kage precompute --cache` and `kage render`
    /// use: NULL for no disk cache; "" for the default folder (`KAGE_CACHE_DIR`, else
    /// `XDG_CACHE_HOME/kage`, else `HOME/.cache/kage`; an error when none is set). A file there
    /// made for the same geometry, bands, rays and visibility is read instead of computing;
    /// otherwise the result is computed and written there (the folder is created).
    pub cache_dir: *const c_char,
    /// NULL for none.
    pub progress: kage_progress_fn,
    pub user: *mut c_void,
}

/// Computes on the context's device what `technique` needs before its first frame, and keeps
/// it in the scene for `kage_renderer_create`: for Sloan and Tamura the per-vertex PRT transfer
/// (seconds to minutes: it casts `prt_rays` rays per vertex; for `KAGE_TECHNIQUE_SLOAN_SCENE`
/// against the whole scene as its group transforms stand); for the other techniques nothing.
/// A later call replaces what an earlier one computed. The same as `kage_precompute_with`
/// without options: no disk cache, no progress.
///
/// The scene keeps no reference to the context.
///
/// # Safety
/// `technique` NULL
/// or a valid desc.
#[no_mangle]
pub unsafe extern "C" fn kage_precompute(
    context: *const kage_context,
    scene: *mut kage_scene,
    technique: *const kage_technique_desc,
) -> kage_result {
    // SAFETY: the caller's promises, and no options.
    unsafe { kage_precompute_with(context, scene, technique, std::ptr::null()) }
}

/// `kage_precompute` with a disk cache and a progress callback that may cancel the work
/// (`options` NULL: neither). On `KAGE_RESULT_CANCELLED` the scene keeps what it had.
///
/// # Safety
/// `technique` and `options` NULL or valid; `options->cache_dir` NULL or a NUL-terminated
/// string; `options->progress` NULL or a function that may be called with `options->user`.
#[no_mangle]
pub unsafe extern "C" fn kage_precompute_with(
    context: *const kage_context,
    scene: *mut kage_scene,
    technique: *const kage_technique_desc,
    options: *const kage_precompute_options,
) -> kage_result {
    boundary(|| {
        let (context, mut scene) = (handles::get(context, "context")?, handles::get(scene, "scene")?);
        // SAFETY: the caller promises NULL or a valid desc (its probe positions included).
        let desc = unsafe { args::sized(technique, "technique")?.desc() }?;
        let (cache_dir, progress, user) = if options.is_null() {
            (None, None, std::ptr::null_mut())
        } else {
            // SAFETY: the caller promises a valid options struct.
            let options = unsafe { args::sized(options, "options") }?;
            let dir = if options.cache_dir.is_null() {
                None
            } else {
                // SAFETY: the caller promises a NUL-terminated string.
                match unsafe { args::text(options.cache_dir, "options.cache_dir") }? {
                    "" => Some(cache::default_dir().ok_or_else(|| {
                        Failure::invalid(
                            "options.cache_dir is \"\" (the default folder), but none of KAGE_CACHE_DIR, \
                             XDG_CACHE_HOME and HOME is set",
                        )
                    })?),
                    dir => Some(PathBuf::from(dir)),
                }
            };
            (dir, options.progress, options.user)
        };
        let Some(params) = desc.precomputation() else { return Ok(()) };
        let params = params.validated()?;
        let key = cache::CacheKey::new(&scene.scene, params);
        let path = cache_dir.map(|dir| dir.join(key.file_name()));
        if let Some(set) = path.as_ref().and_then(|p| cache::load(p, &key).ok()) {
            scene.transfer = Some(Arc::new(set));
            return Ok(());
        }
        // SAFETY: the caller promises a callable function for its own pointer.
        let mut report = |done, total| unsafe { report(progress, user, done, total) };
        let set = transfer::precompute(&context.ctx, &scene.scene, params, &mut report);
        kage_context::check_validation(&context.ctx)?;
        let set = set?;
        if let Some(path) = &path {
            cache::save(path, &set, &key).map_err(|e| Failure::new(kage_result::File, e.to_string()))?;
        }
        scene.transfer = Some(Arc::new(set));
        Ok(())
    })
}
