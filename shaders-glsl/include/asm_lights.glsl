// ASM technique: V of the shared local-light shading looked up in the finest resident tile of
// the adaptive shadow map (one light: the page table covers one light's view). With
// ASM_ID_TEST, the paper's test: lit where the texel's polygon is the receiver's own (no bias
// needed, so no acne), else the depth comparison with the slope-scaled bias decides.
#ifndef KAGE_ASM_LIGHTS_GLSL
#define KAGE_ASM_LIGHTS_GLSL

#include "local_lights_shading.glsl"

// The frame's use marks for the pool's LRU: per page-table node, the last frame (params.z) whose
// lighting looked a point up in its tile. Hidden fragments mark nothing.
layout(early_fragment_tests) in;
layout(std430, set = 0, binding = 4) writeonly buffer AsmUsed { uint asm_used[]; };
#ifdef ASM_ID_TEST
// The polygon IDs: KAGE_ASM_PAGE_ID_TEXELS texels a page, in the depth pool's page order.
layout(set = 0, binding = 5) uniform usamplerBuffer asm_ids;
#endif

#include "asm_lookup.glsl"

bool visible(uint k, vec3 p, vec3 ng) {
    ShadowLight s = lights[k];
    vec4 m = shadow_map_coords(s, p);
    if (m.w < 0.0) return true;
    AsmTile at = asm_descend(m.xy);
    asm_used[at.node] = draw.params.z;
    AsmPage page = asm_page(at, m.xy);
    vec2 f = asm_texel_coords(page.tile, m.xy);
#ifdef ASM_ID_TEST
    uint i = asm_page_texel(page, ivec2(f));
    if (texelFetch(asm_ids, int(page.page * KAGE_ASM_PAGE_ID_TEXELS + i / 4u))[i & 3u] == draw.params.y + uint(gl_PrimitiveID)) {
        return true;
    }
#endif
    // The four texels around the point in its page (shadow_footprint_texel; at the page's
    // border the border texel again).
    vec4 stored;
    for (int j = 0; j < 4; ++j) {
        stored[j] = asm_depth(page, shadow_footprint_texel(f, j));
    }
    float receiver = shadow_receiver_depth(s, m.z, p, ng, asm_texel_size(s, page.tile.x), draw.bias, page.step);
    return shadow_footprint_visible(s, f, stored, receiver);
}

#endif
