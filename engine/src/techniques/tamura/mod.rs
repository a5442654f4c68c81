//! Dynamic soft shadows under environment light (Tamura, Johan, Nishita): PRT self-shadowing per
//! vertex plus per-pixel occlusion between rigid groups, with the environment split into
//! regions that act as area lights.
pub mod regions;
