// The adaptive shadow map's page-table descent (engine/src/techniques/asm/page_table.rs), shared
// by the lighting pass and the refinement analysis. The including shader declares the page table
// as `asm_nodes` and the page pool as `asm_pool` (sampler2DArray, one tile per layer).
#ifndef KAGE_ASM_LOOKUP_GLSL
#define KAGE_ASM_LOOKUP_GLSL

#include "layouts.glsl"

// The node of the finest resident tile holding light uv `uv`: from the root, into the child
// holding uv while it is resident. A missing tile so falls back to its nearest resident ancestor,
// at worst the root, never to "lit".
uint asm_descend(vec2 uv) {
    uint at = 0u;
    for (uint level = 1u; level <= uint(KAGE_ASM_MAX_LEVEL); ++level) {
        uint n = 1u << level;
        uvec2 cell = min(uvec2(uv * float(n)), uvec2(n - 1u));
        uint next = asm_nodes[at].children[2u * (cell.y & 1u) + (cell.x & 1u)];
        if (next == 0u) break;
        at = next;
    }
    return at;
}

// The texel of `tile` (AsmNode.tile) holding uv, moved by `offset` texels and kept in the tile.
ivec3 asm_texel(uvec4 tile, vec2 uv, ivec2 offset) {
    vec2 local = uv * float(1u << tile.y) - vec2(tile.zw);
    ivec2 texel = ivec2(local * float(KAGE_ASM_TILE_TEXELS)) + offset;
    return ivec3(clamp(texel, ivec2(0), ivec2(KAGE_ASM_TILE_TEXELS - 1)), int(tile.x));
}

// Light k's visibility at p (geometric normal ng; m = shadow_map_coords) in the finest resident
// tile: the depth comparison with the slope-scaled bias, texels scaled to the tile's level.
bool asm_visible(ShadowLight s, vec4 m, vec3 p, vec3 ng, uvec4 tile, ivec2 offset, vec4 bias) {
    float stored = texelFetch(asm_pool, asm_texel(tile, m.xy, offset), 0).r;
    return shadow_depth_visible(s, stored, m.z, p, ng, s.map.z / float(1u << tile.y), bias);
}

#endif
