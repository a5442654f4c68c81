// Constants shared by GLSL and Rust. engine/build.rs turns each `#define KAGE_NAME value` into
// `kage::layouts::constants::NAME` (integer literal: u32, literal with '.': f32); comment lines
// right above a define become its Rust doc comment.
#ifndef KAGE_CONSTANTS_GLSL
#define KAGE_CONSTANTS_GLSL

// SH coefficients per colour channel (bands 0 to 2).
#define KAGE_SH_COEFFS 9
// Invocations per workgroup of the SH projection and reduction shaders. Small groups with
// many texels per invocation keep workgroup barriers few: they dominate on CPU drivers.
#define KAGE_SH_GROUP 64
// Environment texels each SH projection invocation adds up.
#define KAGE_SH_TEXELS_PER_INVOCATION 16

#endif
