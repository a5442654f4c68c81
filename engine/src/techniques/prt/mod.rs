//! Precomputed radiance transfer (Sloan, Kautz, Snyder 2002): per-vertex transfer vectors with
//! self-visibility, the base of the Tamura–Johan–Nishita soft shadows.
