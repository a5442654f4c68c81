// The adaptive shadow map's page table and its descent (engine/src/techniques/asm/page_table.rs),
// shared by the lighting pass and the refinement analysis, with the page pool (one tile per
// layer). The including shader declares nothing else at set 0, bindings 2 and 3.
#ifndef KAGE_ASM_LOOKUP_GLSL
#define KAGE_ASM_LOOKUP_GLSL

#include "layouts.glsl"

#define ASM_DIRECTORY_SIDE (1u << KAGE_ASM_DIRECTORY_LEVEL)

layout(set = 0, binding = 2) uniform sampler2DArray asm_pool;
// The directory (rows of ASM_DIRECTORY_SIDE entries: node index | level << 24, the finest
// resident tile at or above the directory's level over each of its tiles), then the nodes.
layout(std430, set = 0, binding = 3) readonly buffer PageTable {
    uint asm_directory[ASM_DIRECTORY_SIDE * ASM_DIRECTORY_SIDE];
    AsmNode asm_nodes[];
};

// The node of the finest resident tile holding light uv `uv`: the directory's tile, then into
// the child holding uv while it is resident. A missing tile so falls back to its nearest
// resident ancestor, at worst the root, never to "lit".
uint asm_descend(vec2 uv) {
    uvec2 entry_cell = min(uvec2(uv * float(ASM_DIRECTORY_SIDE)), uvec2(ASM_DIRECTORY_SIDE - 1u));
    uint entry = asm_directory[entry_cell.y * ASM_DIRECTORY_SIDE + entry_cell.x];
    uint at = entry & 0xffffffu;
    // A tile above the directory's level has no resident child over uv: the directory would
    // name that child.
    if ((entry >> 24) < uint(KAGE_ASM_DIRECTORY_LEVEL)) return at;
    for (uint level = uint(KAGE_ASM_DIRECTORY_LEVEL) + 1u; level <= uint(KAGE_ASM_MAX_LEVEL); ++level) {
        uint n = 1u << level;
        uvec2 cell = min(uvec2(uv * float(n)), uvec2(n - 1u));
        uint next = asm_nodes[at].children[2u * (cell.y & 1u) + (cell.x & 1u)];
        if (next == 0u) break;
        at = next;
    }
    return at;
}

// Light uv in `tile`'s (AsmNode.tile) texel space.
vec2 asm_texel_coords(uvec4 tile, vec2 uv) {
    return (uv * float(1u << tile.y) - vec2(tile.zw)) * float(KAGE_ASM_TILE_TEXELS);
}

// Texel `texel` of `tile`, kept in the tile (its neighbours' texels are in other pages).
ivec3 asm_page_texel(uvec4 tile, ivec2 texel) {
    return ivec3(clamp(texel, ivec2(0), ivec2(KAGE_ASM_TILE_TEXELS - 1)), int(tile.x));
}

// The texel of `tile` holding uv, moved by `offset` texels and kept in the tile.
ivec3 asm_texel(uvec4 tile, vec2 uv, ivec2 offset) {
    return asm_page_texel(tile, ivec2(asm_texel_coords(tile, uv)) + offset);
}

// The world size at unit depth of `tile`'s texels.
float asm_texel_size(ShadowLight s, uvec4 tile) {
    return s.map.z / float(1u << tile.y);
}

// Light k's visibility at p (geometric normal ng; m = shadow_map_coords) in the texel of `tile`
// holding it, moved by `offset`: the depth comparison with the slope-scaled bias, texels scaled
// to the tile's level. The refinement analysis's test, texel by texel (the lighting blends four).
bool asm_visible(ShadowLight s, vec4 m, vec3 p, vec3 ng, uvec4 tile, ivec2 offset, vec4 bias) {
    float stored = texelFetch(asm_pool, asm_texel(tile, m.xy, offset), 0).r;
    return shadow_depth_visible(s, stored, m.z, p, ng, asm_texel_size(s, tile), bias);
}

#endif
