#version 460
// ASM technique: V of the shared local-light shading looked up in the finest resident tile of
// the adaptive shadow map (one light: the page table covers one light's view).
#include "local_lights_shading.glsl"

layout(set = 0, binding = 2) uniform sampler2DArray asm_pool;
layout(std430, set = 0, binding = 3) readonly buffer PageTable { AsmNode asm_nodes[]; };

#include "asm_lookup.glsl"

bool visible(uint k, vec3 p, vec3 ng) {
    ShadowLight s = lights[k];
    vec4 m = shadow_map_coords(s, p);
    if (m.w < 0.0) return true;
    uvec4 tile = asm_nodes[asm_descend(m.xy)].tile;
    return asm_visible(s, m, p, ng, tile, ivec2(0), draw.bias);
}
