// Struct layouts shared by GLSL and Rust, defined only here. engine/build.rs generates the
// matching `#[repr(C)]` Rust structs in `kage::layouts` with std430 offsets (valid in std140
// too), so this file may hold only plain struct definitions with members of type float, int,
// uint, vec2, vec4, ivec4, uvec4, mat4 or an earlier struct, and fixed-size arrays of the
// 16-byte-aligned ones. Comments right above a struct or member, or after a member on its line,
// become Rust doc comments.
#ifndef KAGE_LAYOUTS_GLSL
#define KAGE_LAYOUTS_GLSL

#include "constants.glsl"

// Per-frame camera data (uniform buffer, std140).
struct FrameUniforms {
    mat4 view_proj;
    mat4 inv_view_proj;
    vec4 camera_pos; // xyz: world-space camera position, w: unused
    vec4 env_params; // x: intensity, y: rotation in radians, z, w: unused
};

// Per-draw data (push constants).
struct DrawPush {
    mat4 model;
    vec4 albedo; // rgb: diffuse albedo, a: unused
};

// SH irradiance coefficients, KAGE_SH_COEFFS per channel.
struct ShCoeffs {
    vec4 c[KAGE_SH_COEFFS]; // rgb: one coefficient per channel, w: unused
};

// Push constants of the SH projection compute pass.
struct ShProjectPush {
    uvec4 size; // x: width, y: height, z: groups in x, w: unused
};

#endif
