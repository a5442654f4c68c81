//! Dynamic soft shadows under environment light (Tamura, Johan, Nishita): PRT self-shadowing per
//! vertex plus per-pixel occlusion between rigid groups, with the environment split into
//! regions that act as area lights: Sloan's PRT (`techniques::sloan`) plus shadows between groups.
pub mod dominant;
pub mod dominant_maps;
pub mod occlusion;
pub mod sheet;
pub mod technique;
