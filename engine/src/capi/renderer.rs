//! `kage_renderer`: a scene on the GPU with a technique; frames, pixels and pass timings.
use super::args;
use super::context::kage_context;
use super::handles;
use super::result::{boundary, kage_result, Failure};
use super::scene::{kage_camera_desc, kage_light_desc, kage_scene, kage_transform};
use super::technique::{kage_progress_fn, kage_technique_desc};
use crate::imageio::{self, auto_exposure, tonemap_srgb8};
use crate::pass::PassTiming;
use crate::renderer::{RenderOptions, Renderer};
use std::ffi::{c_char, c_void};

/// A scene on the GPU, lit by one technique, with its render targets.
pub struct kage_renderer {
    renderer: Renderer,
    ctx: std::sync::Arc<crate::backend::Context>,
    /// The pass timings of the last frame; `None` before the first.
    timings: Option<Vec<PassTiming>>,
}

impl kage_renderer {
    /// The last frame's picture; before the first frame, the caller's error.
    fn last_frame(&self) -> Result<crate::imageio::RgbaF32Image, Failure> {
        if self.timings.is_none() {
            return Err(Failure::invalid("no frame yet: call kage_renderer_render first"));
        }
        Ok(self.renderer.image()?)
    }
}

/// What `kage_renderer_create` builds.
#[repr(C)]
pub struct kage_renderer_desc {
    /// `sizeof(kage_renderer_desc)` as the host's kage.h declares it: checked, so that a host built
    /// against another version of the header gets an error instead of a misread struct.
    pub size: u32,
    /// Image size in pixels, 1 to 8192 each.
    pub width: u32,
    pub height: u32,
    pub technique: kage_technique_desc,
}

/// Pixel formats of `kage_renderer_read_pixels`.
#[repr(u32)]
#[derive(Clone, Copy, strum::FromRepr)]
pub enum kage_pixel_format {
    /// 4 bytes per pixel: radiance × exposure, tonemapped (ACES fit), sRGB-encoded; alpha 255.
    Rgba8Srgb = 0,
    /// 16 bytes per pixel: linear radiance as 32-bit floats; alpha 1.
    Rgba32fLinear = 1,
}

/// The GPU time of one pass in the last frame.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct kage_pass_timing {
    /// NUL-terminated, at most 31 bytes, e.g. "background", "scene", "readback". (A literal
    /// size: cbindgen would export every constant of the engine to name it.)
    pub name: [c_char; 32],
    /// Milliseconds; -1 when the device has no timestamps.
    pub milliseconds: f64,
}

/// Uploads the scene and builds the technique's pipelines and targets. `kage_precompute` with
/// the same technique (at least the same SH bands) must have run on the scene first for
/// techniques that need it, else `KAGE_RESULT_INVALID_VALUE`. The same as
/// `kage_renderer_create_with` without a progress callback.
///
/// The renderer copies what it needs: the scene may be destroyed afterwards. It holds a
/// reference to the context's device, which stays alive until the renderer is destroyed even if
/// the context handle is destroyed first. On success `*renderer` is a new handle that the host
/// owns and frees with `kage_renderer_destroy`; on failure it is set to NULL.
///
/// # Safety
/// `desc` NULL or
/// valid; `renderer` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_create(
    context: *const kage_context,
    scene: *const kage_scene,
    desc: *const kage_renderer_desc,
    renderer: *mut *mut kage_renderer,
) -> kage_result {
    // SAFETY: the caller's promises, and no callback.
    unsafe { kage_renderer_create_with(context, scene, desc, None, std::ptr::null_mut(), renderer) }
}

/// `kage_renderer_create` with `progress` (NULL: none) hearing its long work, the light
/// probes' capture (`KAGE_TECHNIQUE_PROBES`: one unit per probe, and one for the automatic
/// placement after them; seconds to a minute on a CPU driver), and able to cancel it
/// (`KAGE_RESULT_CANCELLED`, `*renderer` NULL).
///
/// # Safety
/// As `kage_renderer_create`; `progress` NULL or a function that may be called with `user`.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_create_with(
    context: *const kage_context,
    scene: *const kage_scene,
    desc: *const kage_renderer_desc,
    progress: kage_progress_fn,
    user: *mut c_void,
    renderer: *mut *mut kage_renderer,
) -> kage_result {
    boundary(|| {
        // SAFETY: the caller promises NULL or a writable pointer.
        let out = unsafe { args::handle_out(renderer, "renderer") }?;
        let (context, scene) = (handles::get(context, "context")?, handles::get(scene, "scene")?);
        // SAFETY: the caller promises NULL or a valid desc.
        let desc = unsafe { args::sized(desc, "desc") }?;
        // SAFETY: the caller promises a valid desc, its probe positions included.
        let technique = unsafe { desc.technique.desc() }?;
        let options = RenderOptions {
            width: desc.width,
            height: desc.height,
            technique,
            transfer: scene.transfer.clone(),
        };
        // SAFETY: the caller promises a callable function for its own pointer.
        let mut report = |done, total| unsafe { super::technique::report(progress, user, done, total) };
        let made = Renderer::with_progress(&context.ctx, &scene.scene, &options, &mut report);
        kage_context::check_validation(&context.ctx)?;
        let made = kage_renderer { renderer: made?, ctx: context.ctx.clone(), timings: None };
        *out = handles::register(made);
        Ok(())
    })
}

/// Destroys a renderer, waiting for its GPU work first. NULL is allowed and does nothing.
/// After `KAGE_RESULT_OK` the handle must not be used, nor after `KAGE_RESULT_VALIDATION`
/// (the renderer was destroyed, and this reports what the layer said meanwhile). On
/// `KAGE_RESULT_BUSY` (a call on another thread is using the renderer) nothing was destroyed
/// and the handle stays valid: call again once that call has returned.
#[no_mangle]
pub extern "C" fn kage_renderer_destroy(renderer: *mut kage_renderer) -> kage_result {
    boundary(|| {
        if renderer.is_null() {
            return Ok(());
        }
        let ctx = handles::get(renderer, "renderer")?.ctx.clone();
        handles::destroy(renderer, "renderer")?;
        kage_context::check_validation(&ctx)
    })
}

/// Places group `group` (0 to `kage_scene_group_count` - 1) for the next frames. `transform`
/// is only read during the call.
///
/// # Safety
/// `transform` NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_set_group_transform(
    renderer: *mut kage_renderer,
    group: u32,
    transform: *const kage_transform,
) -> kage_result {
    boundary(|| {
        let mut r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or a valid transform.
        let transform = unsafe { args::value(transform, "transform") }?;
        let transform = transform.validated().map_err(|e| Failure::invalid(format!("group {group}: {e}")))?;
        Ok(r.renderer.set_group_transform(group as usize, transform.matrix())?)
    })
}

/// Moves the camera for the next frames (checked as `kage_scene_desc`'s camera is). `camera` is
/// only read during the call.
///
/// # Safety
/// `camera` NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_set_camera(
    renderer: *mut kage_renderer,
    camera: *const kage_camera_desc,
) -> kage_result {
    boundary(|| {
        let mut r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or a valid camera.
        let camera = unsafe { args::value(camera, "camera") }?;
        Ok(r.renderer.set_camera(camera.camera()?)?)
    })
}

/// Replaces light `index` of the renderer's scene (0 to its light count − 1) for the next
/// frames, checked as a scene file's light is; a point light may become a spot light and back.
/// Techniques redo what they derived from it (shadow maps, adaptive shadow map tiles). `light`
/// is only read during the call.
///
/// # Safety
/// `light` NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_set_light(
    renderer: *mut kage_renderer,
    index: u32,
    light: *const kage_light_desc,
) -> kage_result {
    boundary(|| {
        let mut r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or a valid light.
        let light = unsafe { args::value(light, "light") }?.light("light->kind")?;
        Ok(r.renderer.set_light(index as usize, light)?)
    })
}

/// Turns the environment about +Y (counter-clockwise seen from above) by `radians` (finite) for
/// the next frames, as `kage render --env-rotation` does. Techniques that capture the
/// environment once (the light probes) keep their captured light.
#[no_mangle]
pub extern "C" fn kage_renderer_set_env_rotation(renderer: *mut kage_renderer, radians: f32) -> kage_result {
    boundary(|| {
        let mut r = handles::get(renderer, "renderer")?;
        Ok(r.renderer.set_env_rotation(radians)?)
    })
}

/// Poses every group that has keyframes (a scene file's `keyframes`; the built-in scenes' hop,
/// a one-second loop) at `seconds` (finite) of its motion for the next frames, as
/// `kage render --time` does; the other groups stay as they are.
#[no_mangle]
pub extern "C" fn kage_renderer_set_time(renderer: *mut kage_renderer, seconds: f32) -> kage_result {
    boundary(|| {
        let mut r = handles::get(renderer, "renderer")?;
        Ok(r.renderer.set_time(seconds)?)
    })
}

/// What a renderer holds and what its last frame had to leave out.
#[repr(C)]
#[derive(Clone, Copy, Default)]
pub struct kage_renderer_stats {
    /// Bytes of GPU memory the renderer's device has allocated (all of Kage's objects on it).
    pub gpu_bytes: u64,
    /// Occluder/receiver/region layers the Tamura technique wanted in the last frame but had
    /// no room for (its layer limit): their shadows are missing. 0 for other techniques.
    pub dropped_layers: u32,
    /// Light probes the probes technique interpolates; 0 for other techniques.
    pub probes: u32,
    /// Probes captured before automatic placement kept `probes` of them (the same as `probes`
    /// for the other placements); 0 for other techniques.
    pub probe_candidates: u32,
    /// Probe positions left out because they lie inside geometry; 0 for other techniques.
    pub probes_inside_geometry: u32,
}

/// Writes the renderer's statistics to `*stats`.
///
/// # Safety
/// `stats` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_get_stats(
    renderer: *const kage_renderer,
    stats: *mut kage_renderer_stats,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or writable.
        let stats = unsafe { args::out(stats, "stats") }?;
        let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        let technique = r.renderer.stats();
        let probes = technique.probes;
        *stats = kage_renderer_stats {
            gpu_bytes: r.ctx.allocated_bytes(),
            dropped_layers: count(technique.dropped_layers),
            probes: probes.map_or(0, |p| count(p.kept)),
            probe_candidates: probes.map_or(0, |p| count(p.candidates)),
            probes_inside_geometry: probes.map_or(0, |p| count(p.inside_geometry)),
        };
        Ok(())
    })
}

/// The probes technique's lookups since the renderer was made (one per moving group and frame),
/// counted by what the visibility test (`kage_technique_desc.probe_visibility`) did; all 0 for
/// the other techniques. The host sets `size`; Kage fills the rest.
#[repr(C)]
pub struct kage_probe_lookups {
    /// `sizeof(kage_probe_lookups)` as the host's kage.h declares it: checked.
    pub size: u32,
    /// Lookups made.
    pub lookups: u64,
    /// Lookups where the point did not see some probe of its cell, whose weight went to the
    /// others.
    pub renormalised: u64,
    /// Lookups where the point saw none of its cell's probes and the nearest probe it sees took
    /// all the weight.
    pub nearest: u64,
    /// Lookups where the point saw no probe among its 32 nearest (inside a solid, or sealed
    /// off) and kept its cell's weights.
    pub unweighted: u64,
}

/// Writes the probes technique's lookup counts to `*lookups`, whose `size` the host set.
///
/// # Safety
/// `lookups` NULL or readable and writable.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_get_probe_lookups(
    renderer: *const kage_renderer,
    lookups: *mut kage_probe_lookups,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or a readable and writable struct.
        let out = unsafe { args::sized_out(lookups, "lookups") }?;
        let counts = r.renderer.stats().probe_lookups.unwrap_or_default();
        *out = kage_probe_lookups {
            size: out.size,
            lookups: counts.lookups,
            renormalised: counts.renormalised,
            nearest: counts.nearest,
            unweighted: counts.unweighted,
        };
        Ok(())
    })
}

/// Renders one frame and waits for it; then `kage_renderer_read_pixels` and
/// `kage_renderer_timings` give its picture and pass timings.
#[no_mangle]
pub extern "C" fn kage_renderer_render(renderer: *mut kage_renderer) -> kage_result {
    boundary(|| {
        let mut r = handles::get(renderer, "renderer")?;
        let timings = r.renderer.render();
        kage_context::check_validation(&r.ctx)?;
        r.timings = Some(timings?);
        Ok(())
    })
}

/// Copies the last frame into `pixels`, row 0 at the top, rows tightly packed, in `format` (a
/// `kage_pixel_format` value). `size` is the buffer's size in bytes and must be at least
/// width × height × bytes per pixel, else `KAGE_RESULT_BUFFER_TOO_SMALL`. `exposure` (> 0)
/// scales radiance before tonemapping `KAGE_PIXEL_FORMAT_RGBA8_SRGB` (`kage_renderer_auto_exposure`
/// gives one for any units of light); the linear format ignores it. Before the first `kage_renderer_render`: `KAGE_RESULT_INVALID_VALUE`.
///
/// # Safety
/// `pixels` NULL or `size`
/// writable bytes.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_read_pixels(
    renderer: *const kage_renderer,
    format: u32,
    exposure: f32,
    pixels: *mut u8,
    size: usize,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        let format = args::enumeration(format, "format", kage_pixel_format::from_repr)?;
        if pixels.is_null() {
            return Err(Failure::new(kage_result::NullArgument, "pixels is NULL"));
        }
        let srgb = matches!(format, kage_pixel_format::Rgba8Srgb);
        if srgb && !(exposure.is_finite() && exposure > 0.0) {
            return Err(Failure::invalid(format!("exposure {exposure} is not a positive number")));
        }
        let image = r.last_frame()?;
        let bytes_per_pixel = if srgb { 4 } else { 16 };
        let needed = image.pixels.len() * bytes_per_pixel;
        args::room_for(size, needed, || {
            format!("a {}x{} frame needs {needed} bytes, pixels holds {size}", image.width, image.height)
        })?;
        // Written in place: no copy of the frame the size of the host's buffer.
        // SAFETY: the caller promises `size` >= needed writable bytes at `pixels`.
        let out = unsafe { std::slice::from_raw_parts_mut(pixels, needed) };
        for (to, p) in out.chunks_exact_mut(bytes_per_pixel).zip(&image.pixels) {
            if srgb {
                let [r, g, b] = tonemap_srgb8([p[0], p[1], p[2]], exposure);
                to.copy_from_slice(&[r, g, b, 255]);
            } else {
                for (to, v) in to.chunks_exact_mut(4).zip(p) {
                    to.copy_from_slice(&v.to_ne_bytes());
                }
            }
        }
        Ok(())
    })
}

/// Writes the last frame to the file `path` (UTF-8) as `kage render --out` does, in the format
/// its extension names (any case): `.png`, radiance × `exposure` (finite, at least 0)
/// tonemapped and sRGB-encoded as `KAGE_PIXEL_FORMAT_RGBA8_SRGB` is, 8-bit RGB, written to a
/// temporary file renamed over `path` (a failed write leaves no partial file); `.exr`, linear
/// radiance as 32-bit float RGB (`exposure` is ignored). Another extension, or a bad exposure,
/// is `KAGE_RESULT_INVALID_VALUE` naming it; a file that cannot be written (no such folder, no
/// permission, a full disk) is `KAGE_RESULT_FILE` naming the path. Before the first
/// `kage_renderer_render`: `KAGE_RESULT_INVALID_VALUE`.
///
/// # Safety
/// `path` NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_write_image(
    renderer: *const kage_renderer,
    path: *const c_char,
    exposure: f32,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or a NUL-terminated string.
        let path = unsafe { args::text(path, "path") }?;
        let image = r.last_frame()?;
        imageio::write(path, &image, exposure).map_err(crate::Error::from)?;
        Ok(())
    })
}

/// Writes to `*exposure` the exposure that makes the last frame readable whatever its units
/// (what `kage render --exposure auto` uses): 0.18 over the log-average Rec. 709 luminance of
/// its linear pixels, exp(mean ln(10⁻⁴ + L)); 1 for a black frame. Pass it to
/// `kage_renderer_read_pixels`. Before the first `kage_renderer_render`:
/// `KAGE_RESULT_INVALID_VALUE`.
///
/// # Safety
/// `exposure` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_auto_exposure(
    renderer: *const kage_renderer,
    exposure: *mut f32,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or writable.
        let exposure = unsafe { args::out(exposure, "exposure") }?;
        *exposure = auto_exposure(&r.last_frame()?);
        Ok(())
    })
}

/// Writes the last frame's device time in milliseconds to `*milliseconds`: from its first
/// pass's start to its last pass's end, the time between passes included (what `kage render`
/// reports as the frame); -1 before the first frame or on a device without timestamps. A host
/// that calls it after every frame has the series `kage render --trace` records.
///
/// # Safety
/// `milliseconds` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_frame_time(
    renderer: *const kage_renderer,
    milliseconds: *mut f64,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or writable.
        let milliseconds = unsafe { args::out(milliseconds, "milliseconds") }?;
        *milliseconds = r.timings.as_deref().and_then(crate::pass::frame_ms).unwrap_or(-1.0);
        Ok(())
    })
}

/// Copies the last frame's per-pass GPU timings, in the order the passes ran, into `timings`
/// (room for `capacity`), and writes how many passes the frame had to `*count`, as every call
/// that fills an array does (see the top of this header: NULL with capacity 0 asks for the
/// count alone; a shorter array gets the first `capacity` and `KAGE_RESULT_BUFFER_TOO_SMALL`).
/// Before the first frame the count is 0.
///
/// # Safety
/// `timings` NULL or
/// `capacity` writable elements; `count` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn kage_renderer_timings(
    renderer: *const kage_renderer,
    timings: *mut kage_pass_timing,
    capacity: usize,
    count: *mut usize,
) -> kage_result {
    boundary(|| {
        let r = handles::get(renderer, "renderer")?;
        // SAFETY: the caller promises NULL or writable.
        let count = unsafe { args::out(count, "count") }?;
        let frame = r.timings.as_deref().unwrap_or_default();
        *count = frame.len();
        if args::count_query(timings, capacity, "timings")? {
            return Ok(());
        }
        for (at, pass) in frame.iter().take(capacity).enumerate() {
            let mut name = [0 as c_char; 32];
            let room = name.len() - 1;
            for (to, byte) in name.iter_mut().zip(pass.name.bytes().take(room)) {
                *to = byte as c_char;
            }
            let timing = kage_pass_timing { name, milliseconds: pass.gpu_ms.unwrap_or(-1.0) };
            // SAFETY: at < capacity, and the caller promises `capacity` writable elements.
            unsafe { timings.add(at).write(timing) };
        }
        args::room_for(capacity, frame.len(), || {
            format!("the frame had {} passes, timings holds {capacity}", frame.len())
        })
    })
}
