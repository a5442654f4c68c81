#version 460
// Parallel-lights baseline (the paper's Fig. 3): the environment's q regions as directional
// lights with binary shadow maps, L = albedo / pi * sum_i B_i max(n . omega_i, 0) V_i(p).
// V_i is one depth comparison (no PCF): the banding of binary maps is what this baseline shows.
#include "layouts.glsl"
#include "sh.glsl"
#define KAGE_ALBEDO_MAP_BINDING 3
#include "albedo_map.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform Lights { ParallelLight lights[KAGE_MAX_PARALLEL_LIGHTS]; };
layout(set = 0, binding = 2) uniform sampler2DArray shadow_maps;
layout(push_constant) uniform Push { ParallelDrawPush draw; };
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;
layout(location = 0) out vec4 color;

void main() {
    // Two-sided surfaces, as in scene.frag: the back of an open mesh faces the viewer.
    vec3 n = normalize(gl_FrontFacing ? world_normal : -world_normal);
    int size = int(draw.params.y);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < draw.params.x; ++i) {
        vec3 w = lights[i].direction.xyz;
        float c = dot(n, w);
        if (c <= 0.0) {
            continue;
        }
        // Normal offset: look the map up from a point moved off the surface along n, by more
        // where the light grazes the surface (see parallel_lights.rs).
        float s = sqrt(max(1.0 - c * c, 0.0));
        vec3 p = world_position + n * (draw.shadow.x * s + draw.shadow.y);
        vec3 clip = (lights[i].view_proj * vec4(p, 1.0)).xyz;
        ivec2 texel = clamp(ivec2(floor((clip.xy * 0.5 + 0.5) * float(size))), ivec2(0), ivec2(size - 1));
        float nearest = texelFetch(shadow_maps, ivec3(texel, int(i)), 0).r;
        if (clip.z - draw.shadow.z <= nearest) {
            sum += lights[i].energy.rgb * c;
        }
    }
    color = vec4(draw.albedo.rgb * albedo_texel(texcoord) / KAGE_PI * sum, 1.0);
}
