#version 460
// Unshadowed environment lighting: L = albedo / pi * E(n), E from the map's 9 SH coefficients.
#include "layouts.glsl"
#include "sh.glsl"
#include "envmap.glsl"
#define KAGE_ALBEDO_MAP_BINDING 2
#include "albedo_map.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std140) uniform Sh { ShCoeffs sh; };
layout(push_constant) uniform Push { DrawPush draw; };
layout(location = 0) in vec3 world_normal;
layout(location = 1) in vec2 texcoord;
layout(location = 0) out vec4 color;

void main() {
    // Surfaces are two-sided: the back of an open mesh (the inside of the teapot) is lit as
    // seen, with its normal turned towards the viewer.
    vec3 n = normalize(gl_FrontFacing ? world_normal : -world_normal);
    // The coefficients are in the map's frame: look up the normal as the turned map sees it.
    vec3 irradiance = max(sh9_irradiance(sh.c, env_world_to_map(n, frame.env_params.y)), vec3(0.0));
    color = vec4(draw.albedo.rgb * albedo_texel(texcoord) / KAGE_PI * irradiance, 1.0);
}
