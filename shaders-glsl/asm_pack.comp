#version 460
// ASM page packing: a slot of the tile scratch (engine/src/techniques/asm/pages.rs) becomes a
// depth page of the pool (KAGE_ASM_PAGE_DEPTH_TEXELS), written in place. Its depths are stored
// as 16-bit steps over the slot's own span, from the nearest depth drawn to the farthest;
// texels nothing covers keep the clear depth as 0xffff. A page so takes half the bytes of D32,
// and a step is the slot's span over 65534: within a slot on one surface far finer than D32
// near the far plane, across a silhouette the span's. The lookups allow half a step in their
// bias (asm_lookup.glsl).
//
// One invocation packs a whole slot, with no shared memory or barrier (llvmpipe runs a
// workgroup's barriers as coroutine switches; vendor-notes.md).
#include "layouts.glsl"

layout(local_size_x = KAGE_ASM_PACK_GROUP) in;
layout(set = 0, binding = 0) uniform sampler2DArray scratch;
// The slots to pack, one per invocation, each with its page: slot x + y * n of layer l of the
// scratch's n x n, as x + y * n + l * n * n.
layout(std430, set = 0, binding = 1) readonly buffer Slots { uvec2 slots[]; };
// The pool's depth pages (the lookups read them as a usamplerBuffer). A storage texel buffer,
// not a storage buffer: its bound is maxTexelBufferElements texels.
layout(set = 0, binding = 2, rgba32ui) uniform writeonly uimageBuffer pages;
layout(push_constant) uniform Push { AsmPackPush push; };

#define EMPTY 0xffffu
// Steps over a span: the largest below EMPTY.
#define STEPS 65534.0

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= push.count.x) return;
    uint side = uint(textureSize(scratch, 0).x / KAGE_ASM_PAGE_TEXELS);
    uint layer = slots[k].x / (side * side), slot = slots[k].x % (side * side);
    ivec2 origin = ivec2(slot % side, slot / side) * KAGE_ASM_PAGE_TEXELS;
    // Depths are non-negative: the span from the nearest covered texel to the farthest. Each
    // texel is fetched once.
    float depths[KAGE_ASM_PAGE_TEXELS * KAGE_ASM_PAGE_TEXELS];
    float nearest = 1.0, farthest = 0.0;
    for (int i = 0; i < KAGE_ASM_PAGE_TEXELS * KAGE_ASM_PAGE_TEXELS; ++i) {
        float d = texelFetch(scratch, ivec3(origin + ivec2(i % KAGE_ASM_PAGE_TEXELS, i / KAGE_ASM_PAGE_TEXELS), layer), 0).r;
        depths[i] = d;
        if (d < 1.0) {
            nearest = min(nearest, d);
            farthest = max(farthest, d);
        }
    }
    float step = max(farthest - nearest, 0.0) / STEPS;
    // A texel of eight depths at a time: fewer, wider stores.
    int base = int(slots[k].y * KAGE_ASM_PAGE_DEPTH_TEXELS);
    for (int t = 0; t < KAGE_ASM_PAGE_DEPTH_TEXELS - 1; ++t) {
        uvec4 texel;
        for (int w = 0; w < 4; ++w) {
            uint pair = 0u;
            for (int j = 0; j < 2; ++j) {
                float d = depths[8 * t + 2 * w + j];
                uint q = step > 0.0 ? min(uint(round((d - nearest) / step)), uint(STEPS)) : 0u;
                pair |= (d < 1.0 ? q : EMPTY) << (16 * j);
            }
            texel[w] = pair;
        }
        imageStore(pages, base + t, texel);
    }
    imageStore(pages, base + KAGE_ASM_PAGE_DEPTH_TEXELS - 1, uvec4(floatBitsToUint(nearest), floatBitsToUint(step), 0u, 0u));
}
