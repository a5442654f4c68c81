//! The dominant lights' self-shadows (beyond the paper; see `dominant.rs`): for each dominant
//! light, a depth map of each group that can shadow itself (one not flat), fitted to the group's
//! bounding sphere, so a teapot gets the same texels whatever the size of the floor it stands
//! on. The scene pass tests each pixel of the group against its own map (one bilinear
//! percentage-closer tap). Shadows between groups take the occlusion layers' path, as the
//! regions' do, with the light's own angular size for their penumbra.
use super::dominant::DominantLight;
use crate::backend::{Binding, Buffer, BufferDesc, BufferUsage, Context, MemoryLocation, Sampler};
use crate::error::{Error, Result};
use crate::frame::bounds::{rotation_of, GroupBounds};
use crate::frame::shadow_depth::ShadowMaps;
use crate::frame::GpuScene;
use crate::layouts::{self, bytes_of, constants, DominantLights, DominantMap};
use crate::pass::Pass;

use glam::{Mat3, Mat4, Vec3};
use std::sync::Arc;

/// Default side of a group's map along a dominant light, texels.
pub const DEFAULT_MAP_SIZE: u32 = 512;
/// Sides accepted.
pub const MAP_SIZES: std::ops::RangeInclusive<u32> = 16..=4096;
/// Normals of a group within this angle of each other (radians) make it flat: it cannot shadow
/// itself.
const FLAT_SPREAD: f32 = 1e-3;

pub struct DominantMaps {
    lights: Vec<DominantLight>,
    bounds: Vec<GroupBounds>,
    size: u32,
    maps: ShadowMaps,
    /// Per group: its slot among the groups that shadow themselves (the map of light j is
    /// `j * slots + slot`); `None` for flat groups and those beyond the maps' capacity.
    slots: Vec<Option<u32>>,
    slot_count: u32,
    /// Per map: the group-to-light rotation it was rendered with, and whether it is rendered
    /// again this frame.
    rendered: Vec<Option<Mat3>>,
    stale: Vec<bool>,
    uniforms: Buffer,
    comparison: Sampler,
    /// Groups left without self-shadows from the dominant lights: more than the uniform
    /// buffer's `KAGE_MAX_DOMINANT_MAPS` maps would take.
    pub dropped: usize,
}

impl DominantMaps {
    /// Maps of `size`² texels for `lights` (at most `KAGE_MAX_DOMINANT_LIGHTS`) over the groups
    /// of `bounds` that are not flat.
    pub fn new(
        ctx: &Arc<Context>,
        lights: Vec<DominantLight>,
        bounds: Vec<GroupBounds>,
        size: u32,
    ) -> Result<DominantMaps> {
        if !MAP_SIZES.contains(&size) {
            return Err(Error::InvalidArgument(format!(
                "light map size {size} must be {} to {} texels",
                MAP_SIZES.start(),
                MAP_SIZES.end()
            )));
        }
        if lights.len() > constants::MAX_DOMINANT_LIGHTS as usize {
            return Err(Error::InvalidArgument(format!(
                "{} dominant lights: the scene pass lights at most {}",
                lights.len(),
                constants::MAX_DOMINANT_LIGHTS
            )));
        }
        let per_group = lights.len().max(1);
        let capacity = constants::MAX_DOMINANT_MAPS as usize / per_group;
        let mut slot_count = 0u32;
        let mut dropped = 0;
        let slots: Vec<Option<u32>> = bounds
            .iter()
            .map(|b| match b.normal_spread > FLAT_SPREAD && !lights.is_empty() {
                false => None,
                true if (slot_count as usize) < capacity => {
                    slot_count += 1;
                    Some(slot_count - 1)
                }
                true => {
                    dropped += 1;
                    None
                }
            })
            .collect();
        let count = lights.len() * slot_count as usize;
        // Nothing to shadow: one small map to bind.
        let (layers, side) = if count == 0 { (1, 16) } else { (count as u32, size) };
        Ok(DominantMaps {
            maps: ShadowMaps::new(ctx, "dominant", side, layers)?,
            uniforms: Buffer::new(
                ctx,
                &BufferDesc {
                    name: "dominant.lights",
                    size: size_of::<DominantLights>() as u64,
                    usage: BufferUsage::UNIFORM,
                    location: MemoryLocation::CpuToGpu,
                },
            )?,
            comparison: Sampler::comparison(ctx, "dominant.comparison")?,
            rendered: vec![None; count],
            stale: vec![false; count],
            slots,
            slot_count,
            dropped,
            lights,
            bounds,
            size,
        })
    }

    /// The map slot of group `g` plus one, 0 when it has no maps (the scene pass's push
    /// constant).
    pub fn slot(&self, g: usize) -> u32 {
        self.slots[g].map_or(0, |s| s + 1)
    }

    /// Places this frame's maps and uploads the lights; a map whose group turned relative to
    /// its light is rendered again.
    pub fn update(&mut self, transforms: &[Mat4], env: Mat3) -> Result<()> {
        let mut data = DominantLights::default();
        self.maps.view_projs.clear();
        for (j, light) in self.lights.iter().enumerate() {
            let w = (env * light.direction.as_vec3()).normalize();
            let first = j as u32 * self.slot_count;
            for (g, slot) in self.slots.iter().enumerate() {
                let Some(slot) = slot else { continue };
                let t = &transforms[g];
                let centre = t.transform_point3(self.bounds[g].centre);
                let radius = (self.bounds[g].radius * t.x_axis.truncate().length()).max(1e-6);
                let up = if w.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
                let view_proj = Mat4::orthographic_rh(-radius, radius, -radius, radius, 0.0, 2.0 * radius)
                    * Mat4::look_at_rh(centre + radius * w, centre, up);
                let m = (first + slot) as usize;
                data.maps[m] = DominantMap {
                    view_proj: view_proj.to_cols_array_2d(),
                    params: [2.0 * radius / self.size as f32, self.size as f32, 0.0, 0.0],
                };
                // What the map holds depends on the group's rotation relative to the light only.
                let relative = rotation_of(t).transpose() * Mat3::from_cols(w, up, w.cross(up));
                self.stale[m] = !self.rendered[m].is_some_and(|r| r.abs_diff_eq(relative, 1e-6));
                if self.stale[m] {
                    self.rendered[m] = Some(relative);
                }
                self.maps.view_projs.push(view_proj);
            }
            let energy = light.energy.map(|e| e as f32);
            data.lights[j] = layouts::DominantLight {
                direction: w.extend(light.radius.tan() as f32).to_array(),
                energy: [energy[0], energy[1], energy[2], 0.0],
                maps: [first, self.slot_count, 0, 0],
            };
        }
        self.uniforms.write(0, bytes_of(&data))
    }

    /// The `dominant_maps` pass, when any map is stale.
    pub fn pass<'a>(&'a self, ctx: &'a Context, scene: &'a GpuScene) -> Option<Pass<'a>> {
        if !self.stale.iter().any(|&s| s) {
            return None;
        }
        Some(Pass::new("dominant_maps", move |cmd| {
            let groups: Vec<usize> = (0..self.slots.len()).filter(|&g| self.slots[g].is_some()).collect();
            for (m, view_proj) in self.maps.view_projs.iter().enumerate().filter(|&(m, _)| self.stale[m]) {
                let g = groups[m % groups.len()];
                let draws = scene
                    .meshes
                    .iter()
                    .filter(|mesh| mesh.group == g)
                    .map(|mesh| (mesh, 0, mesh.index_count));
                self.maps.record(ctx, cmd, scene, m as u32, view_proj, draws);
            }
        }))
    }

    /// What the scene pass binds: the records and the maps for filtered comparisons.
    pub fn bindings(&self) -> [Binding<'_>; 2] {
        [Binding::Uniform(&self.uniforms), Binding::Sampled(self.maps.image(), &self.comparison)]
    }
}
