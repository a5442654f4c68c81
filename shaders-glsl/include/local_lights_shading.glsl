// The lighting of the shadowmap and ASM techniques (local_lights.frag, asm_lights.frag): direct
// light from the scene's point and spot lights with hard shadows,
// L = albedo / pi * sum_k I_k cos / d^2 * V_k, lit exactly as the reference's --light local
// (local_light.glsl). The including shader declares its shadow maps and defines
// `bool visible(uint k, vec3 p, vec3 ng)`, V_k, and KAGE_ALBEDO_MAP_BINDING (albedo_map.glsl);
// this file declares bindings 0 and 1, the albedo map and main.
#ifndef KAGE_LOCAL_LIGHTS_SHADING_GLSL
#define KAGE_LOCAL_LIGHTS_SHADING_GLSL

#include "layouts.glsl"
#include "local_light.glsl"
#include "sh.glsl"
#include "shadow_test.glsl"
#include "albedo_map.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform Lights { ShadowLight lights[KAGE_MAX_LOCAL_LIGHTS]; };
layout(push_constant) uniform Push { LocalDrawPush draw; };
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;
layout(location = 0) out vec4 color;

bool visible(uint k, vec3 p, vec3 ng);

void main() {
    // Oriented as the reference's bvh_surface does: the geometric normal towards the camera,
    // the shading normal flipped with it on back faces (two-sided surfaces).
    vec3 ng = normalize(cross(dFdx(world_position), dFdy(world_position)));
    if (dot(ng, frame.camera_pos.xyz - world_position) < 0.0) ng = -ng;
    vec3 ns = normalize(gl_FrontFacing ? world_normal : -world_normal);
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < draw.params.x; ++k) {
        vec3 e = local_light_unshadowed(lights[k].light, world_position, ns, ng);
        if (any(greaterThan(e, vec3(0.0))) && visible(k, world_position, ng)) {
            sum += e;
        }
    }
    color = vec4(draw.albedo.rgb * albedo_texel(texcoord) / KAGE_PI * sum, 1.0);
}

#endif
