// Eye rays through pixels (layouts.glsl, EyeRays), shared by the reference's primary rays, the
// background pass and ASM's analysis, so that a pixel's ray is the same everywhere and passes
// through the centre the rasterizer samples.
#ifndef KAGE_EYE_RAY_GLSL
#define KAGE_EYE_RAY_GLSL

#include "layouts.glsl"

// The direction (unit view depth, not unit length) of the eye ray through NDC point ndc.
vec3 eye_ray(EyeRays rays, vec2 ndc) {
    return rays.forward.xyz + ndc.x * rays.x.xyz + ndc.y * rays.y.xyz;
}

// The NDC point of pixel position `at` (pixels from the target's top-left corner) in a target
// of `size` pixels: row 0 at the top is NDC y = -1, as in the rasterizer's framebuffer.
vec2 eye_ndc(vec2 at, vec2 size) {
    return at / size * 2.0 - 1.0;
}

#endif
