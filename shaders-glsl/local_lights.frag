#version 460
// Shadowmap technique: V_k of the shared local-light shading is the depth comparison in light
// k's map, reconstructed between texel centres and kept hard (shadow_footprint_texel: the
// reference's shadows are hard). Points outside the map (a point
// light's map covers only its field of view) are lit.
#define KAGE_ALBEDO_MAP_BINDING 3
#include "local_lights_shading.glsl"

layout(set = 0, binding = 2) uniform sampler2DArray shadow_maps;

bool visible(uint k, vec3 p, vec3 ng) {
    ShadowLight s = lights[k];
    vec4 m = shadow_map_coords(s, p);
    if (m.w < 0.0) return true;
    int size = textureSize(shadow_maps, 0).x;
    vec2 f = m.xy * float(size);
    vec4 stored;
    for (int j = 0; j < 4; ++j) {
        ivec2 texel = clamp(shadow_footprint_texel(f, j), ivec2(0), ivec2(size - 1));
        stored[j] = texelFetch(shadow_maps, ivec3(texel, int(k)), 0).r;
    }
    return shadow_footprint_visible(s, f, stored, shadow_receiver_depth(s, m.z, p, ng, s.map.z, draw.bias, 0.0));
}
