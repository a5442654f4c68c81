//! Dynamic soft shadows under environment light (Tamura, Johan, Nishita): PRT self-shadowing per
//! vertex plus per-pixel occlusion between rigid groups, with the environment split into
//! regions that act as area lights. Sloan's PRT is the same technique with no regions.
pub mod dominant;
pub mod dominant_maps;
pub mod occlusion;
pub mod self_shadow;
pub mod technique;

pub use technique::PrtTechnique;
