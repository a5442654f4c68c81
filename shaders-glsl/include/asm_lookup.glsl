// The adaptive shadow map's page table and its descent (engine/src/techniques/asm/page_table.rs),
// shared by the lighting pass and the refinement analysis, with the page pool (pages of
// KAGE_ASM_PAGE_DEPTH_TEXELS texels, each one slot of a tile: a 4x4 grid of
// KAGE_ASM_PAGE_TEXELS squares; asm_pack.comp writes them). The including shader declares
// nothing else at set 0, bindings 2 and 3.
#ifndef KAGE_ASM_LOOKUP_GLSL
#define KAGE_ASM_LOOKUP_GLSL

#include "layouts.glsl"

#define ASM_DIRECTORY_SIDE (1u << KAGE_ASM_DIRECTORY_LEVEL)

layout(set = 0, binding = 2) uniform usamplerBuffer asm_pool;
// The page table as uvec4 texels: the directory (rows of ASM_DIRECTORY_SIDE entries, four to a
// texel: node index | level << 24, the finest resident tile at or above the directory's level
// over each of its tiles), then the nodes (an AsmNode is ASM_NODE_TEXELS texels: below[0..3],
// pages[0..3]). A texel buffer because llvmpipe gathers texel fetches and reads storage buffers lane by
// lane (vendor-notes.md).
layout(set = 0, binding = 3) uniform usamplerBuffer asm_table;
#define ASM_DIRECTORY_TEXELS int(ASM_DIRECTORY_SIDE * ASM_DIRECTORY_SIDE / 4u)
#define ASM_NODE_TEXELS 8
#define ASM_NODE_PAGES 4

uint asm_directory(uint entry) { return texelFetch(asm_table, int(entry >> 2))[entry & 3u]; }
// Texel `field` (0 to 3: below's rows, ASM_NODE_PAGES + 0 to 3: pages' rows) of node `node`.
uvec4 asm_node(uint node, int field) {
    return texelFetch(asm_table, ASM_DIRECTORY_TEXELS + ASM_NODE_TEXELS * int(node) + field);
}

// A resident tile: its page-table node and its level.
struct AsmTile {
    uint node;
    uint level;
};

// The finest resident tile holding light uv `uv`: the directory's tile, then down two levels a
// step through each node's `below` while the tile two levels down is resident (one texel fetch
// per step: the descent's cost in the lighting pass is its fetches). A missing tile so falls back
// to its nearest resident ancestor, at worst the root, never to "lit".
AsmTile asm_descend(vec2 uv) {
    uvec2 entry_cell = min(uvec2(uv * float(ASM_DIRECTORY_SIDE)), uvec2(ASM_DIRECTORY_SIDE - 1u));
    uint entry = asm_directory(entry_cell.y * ASM_DIRECTORY_SIDE + entry_cell.x);
    AsmTile at = AsmTile(entry & 0xffffffu, entry >> 24);
    // A tile above the directory's level has no resident child over uv: the directory would
    // name that child.
    if (at.level < uint(KAGE_ASM_DIRECTORY_LEVEL)) return at;
    for (uint step = 0u; step < (uint(KAGE_ASM_MAX_LEVEL - KAGE_ASM_DIRECTORY_LEVEL) + 1u) / 2u; ++step) {
        uint n = 4u << at.level;
        uvec2 cell = min(uvec2(uv * float(n)), uvec2(n - 1u)) & 3u;
        uint below = asm_node(at.node, int(cell.y))[cell.x];
        uint down = below >> 24;
        if (down == 0u) break;
        at = AsmTile(below & 0xffffffu, at.level + down);
        if (down == 1u) break;
    }
    return at;
}

// The stored slot that holds a point: its tile, and where its texels lie.
struct AsmPage {
    uvec3 tile; // x: level, y, z: tile x, y at that level
    ivec2 slot; // the slot's first texel within the tile
    uint page; // its index in the pool
    float nearest; // its depths' span: the nearest depth and the step of its 16-bit values
    float step;
};

// Light uv in the texel space of tile `tile` (level, x, y).
vec2 asm_texel_coords(uvec3 tile, vec2 uv) {
    return (uv * float(1u << tile.x) - vec2(tile.yz)) * float(KAGE_ASM_TILE_TEXELS);
}

// The light uv of the centre of texel `texel` of tile `tile` (the inverse of asm_texel_coords).
vec2 asm_texel_centre(uvec3 tile, ivec2 texel) {
    return (vec2(tile.yz) + (vec2(texel) + 0.5) / float(KAGE_ASM_TILE_TEXELS)) / float(1u << tile.x);
}

// The slot of tile `tile` holding uv.
ivec2 asm_slot(uvec3 tile, vec2 uv) {
    const float slots = float(KAGE_ASM_TILE_TEXELS / KAGE_ASM_PAGE_TEXELS);
    return ivec2(clamp(asm_texel_coords(tile, uv) / float(KAGE_ASM_PAGE_TEXELS), vec2(0.0), vec2(slots - 1.0)));
}

// The stored slot holding uv, from resident tile `at`'s entry for its slot there: the tile is
// the finest resident one (asm_descend, whose cells give the tile's coordinates again), so no
// resident child covers the slot, and the entry names its page or, where the tile does not
// store it, the nearest ancestor's that holds the point (levels up in the entry's top byte).
AsmPage asm_page(AsmTile at, vec2 uv) {
    uint n = 1u << at.level;
    uvec2 xy = min(uvec2(uv * float(n)), uvec2(n - 1u));
    ivec2 s = asm_slot(uvec3(at.level, xy), uv);
    uint entry = asm_node(at.node, ASM_NODE_PAGES + s.y)[s.x];
    uint up = entry >> 24;
    uvec3 tile = uvec3(at.level - up, xy >> up);
    uint index = entry & 0xffffffu;
    uvec4 span = texelFetch(asm_pool, int((index + 1u) * KAGE_ASM_PAGE_DEPTH_TEXELS) - 1);
    ivec2 slot = asm_slot(tile, uv) * KAGE_ASM_PAGE_TEXELS;
    return AsmPage(tile, slot, index, uintBitsToFloat(span.x), uintBitsToFloat(span.y));
}

// Tile texel `texel` kept in the page's slot (the texels beyond it are in other pages, or in
// none where the tile does not store them).
ivec2 asm_slot_texel(AsmPage page, ivec2 texel) {
    return clamp(texel, page.slot, page.slot + KAGE_ASM_PAGE_TEXELS - 1);
}

// Where tile texel `texel`, kept in the page's slot, lies in the page: row by row.
uint asm_page_texel(AsmPage page, ivec2 texel) {
    ivec2 t = asm_slot_texel(page, texel) - page.slot;
    return uint(t.y * KAGE_ASM_PAGE_TEXELS + t.x);
}

// The stored Vulkan depth of tile texel `texel` (kept in the page's slot), to within half the
// page's step.
float asm_depth(AsmPage page, ivec2 texel) {
    uint i = asm_page_texel(page, texel);
    uint word = texelFetch(asm_pool, int(page.page * KAGE_ASM_PAGE_DEPTH_TEXELS + i / 8u))[(i / 2u) & 3u];
    uint q = (word >> (16u * (i & 1u))) & 0xffffu;
    return q == 0xffffu ? 1.0 : page.nearest + float(q) * page.step;
}

// The world size at unit depth of the texels of a tile at `level`.
float asm_texel_size(ShadowLight s, uint level) {
    return s.map.z / float(1u << level);
}

#endif
