#version 460
// Moving groups lit by the light probes: L = albedo / pi * max(E(n), 0) with
// E(n) = (n, 1)^T M (n, 1) per channel (Ramamoorthi & Hanrahan 2001, eq. 12), M from the SH
// interpolated at the group's position (ProbeLight). Negative irradiance, from ringing of the
// 9 coefficients, is clamped. The probes were captured in world space with the environment
// unrotated, so unlike scene.frag the normal is not turned with the environment.
#include "layouts.glsl"
#include "sh.glsl"
#define KAGE_ALBEDO_MAP_BINDING 2
#include "albedo_map.glsl"

layout(set = 0, binding = 1, std140) uniform Light { ProbeLight light; };
layout(push_constant) uniform Push { DrawPush draw; };
layout(location = 0) in vec3 world_normal;
layout(location = 1) in vec2 texcoord;
layout(location = 0) out vec4 color;

void main() {
    // Two-sided, as in scene.frag.
    vec4 n = vec4(normalize(gl_FrontFacing ? world_normal : -world_normal), 1.0);
    vec3 irradiance = vec3(dot(n, light.red * n), dot(n, light.green * n), dot(n, light.blue * n));
    color = vec4(draw.albedo.rgb * albedo_texel(texcoord) / KAGE_PI * max(irradiance, vec3(0.0)), 1.0);
}
