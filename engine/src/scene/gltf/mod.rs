//! glTF 2.0 scenes: read ([`parts`]) and written ([`write_glb`]) through the `gltf` crate.
//!
//! Kage's scene and glTF's map onto each other as follows (both ways):
//! - a group is a root node: its TRS the group's transform, its meshes on it (one) or on
//!   children without a transform (several); each Kage mesh one glTF mesh of one triangle
//!   primitive with positions, normals, u32 indices and a material whose baseColorFactor is the
//!   albedo (metallic 0, roughness 1: a diffuse surface in other viewers too) and whose
//!   baseColorTexture, read through TEXCOORD_0, is its albedo map (a PNG in the buffer);
//! - a group's motion is one animation named after the group, with linear translation, rotation
//!   and scale channels;
//! - the camera is a perspective camera on its own root node, point and spot lights are
//!   KHR_lights_punctual lights on their own root nodes (colour × intensity in candela, over
//!   [`LUMENS_PER_WATT`], = Kage's radiant intensity in W/sr; a spot's full cone twice its outer
//!   cone angle, its edge hard).
//!
//! Where glTF's form loses what Kage holds (a camera's look-at target and up vector, rounding in
//! a light's colour and cone, a motion's loop), Kage writes its own values in the node's or
//! animation's `extras` (`{"kage": {...}}`); the reader takes them only where they agree with the
//! glTF values, so a file edited in another tool is read from what that tool wrote.
mod import;
mod read;
mod texture;
mod write;

pub use read::{overview, parts, Parts};
pub use write::write_glb;

use super::file::{CameraDesc, LightDesc};
use serde::{Deserialize, Serialize};

/// The luminous efficacy that turns KHR_lights_punctual's candela (lm/sr) into Kage's radiant
/// intensity (W/sr): 683 lm/W, the definition of the candela at 555 nm, as Blender's exporter
/// uses it (a Blender point light of P watts is written as P × 683 / 4π cd, read back as the
/// P / 4π W/sr it radiates).
pub const LUMENS_PER_WATT: f32 = 683.0;

/// `extras` of a node or animation that Kage wrote: `{"kage": {...}}`.
#[derive(Debug, Default, Serialize, Deserialize)]
struct Extras {
    kage: KageExtras,
}

/// Kage's exact values beside their glTF form.
#[derive(Debug, Default, Serialize, Deserialize)]
struct KageExtras {
    /// On a camera's node: its position, target, up and field of view.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    camera: Option<CameraDesc>,
    /// On a light's node: the light as a scene file gives it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    light: Option<LightDesc>,
    /// On an animation: the loop length of the motion (glTF animations play once).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    loop_seconds: Option<f32>,
}

impl Extras {
    /// Kage's extras in `raw`, if it holds them (other tools' extras are left alone).
    fn of(raw: &gltf::json::Extras) -> KageExtras {
        raw.as_ref()
            .and_then(|raw| serde_json::from_str::<Extras>(raw.get()).ok())
            .map_or_else(KageExtras::default, |extras| extras.kage)
    }
}
