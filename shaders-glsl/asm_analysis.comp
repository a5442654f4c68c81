#version 460
// ASM refinement analysis, per visible eye pixel (Fernando et al. 2001, section 4): where its
// light uv lands in the finest resident tile, whether it is on a shadow edge, and how many
// levels finer a tile would have to be for a shadow texel to be no larger than the eye pixel's
// footprint. Edge pixels short of resolution are recorded (AsmAnalysisPush) for the host's
// planner, which counts them per requested tile (the tiles under theirs towards them, up to
// KAGE_ASM_CHAIN_LEVELS deep) and renders the chosen ones before the same frame's lighting.
//
// Projected areas from screen-space derivatives of the light uv, taken by finite differences of
// the world positions reconstructed from the depth target, not from the paper's mip-map trick:
// a compute pass has no hardware derivatives, the eye depth pass already holds every visible
// surface, and picking the smaller of the forward and backward difference keeps a pixel next
// to a silhouette from taking its neighbour's surface.
#include "layouts.glsl"
#include "shadow_test.glsl"
#include "eye_ray.glsl"

layout(local_size_x = KAGE_ASM_ANALYSIS_GROUP, local_size_y = KAGE_ASM_ANALYSIS_GROUP) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform Lights { ShadowLight lights[KAGE_MAX_LOCAL_LIGHTS]; };
layout(set = 0, binding = 4) uniform sampler2D eye_depth;
layout(std430, set = 0, binding = 5) buffer Requests { uint requests[]; };
layout(push_constant) uniform Push { AsmAnalysisPush push; };
// Levels asked for beyond the eye pixel's (`AsmSettings::extra_levels`).
layout(constant_id = 0) const uint EXTRA_LEVELS = KAGE_ASM_EXTRA_LEVELS;

#include "asm_lookup.glsl"


// The world position seen at pixel q, or w = 0 where the pixel shows no surface.
vec4 surface(ivec2 q) {
    ivec2 size = ivec2(push.size.xy);
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) return vec4(0.0);
    float d = texelFetch(eye_depth, q, 0).r;
    if (d >= 1.0) return vec4(0.0);
    // The view depth along the pixel's eye ray.
    float depth = view_depth(d, frame.viewport.z, frame.viewport.w);
    return vec4(frame.camera_pos.xyz + depth * eye_ray(frame.eye_rays, eye_ndc(vec2(q) + 0.5, vec2(size))), 1.0);
}

// The smaller of the differences to the neighbours at q - step and q + step (0 where neither
// shows a surface).
vec3 difference(vec3 p, ivec2 q, ivec2 step) {
    vec4 back = surface(q - step), ahead = surface(q + step);
    vec3 db = p - back.xyz, da = ahead.xyz - p;
    if (back.w == 0.0) return ahead.w == 0.0 ? vec3(0.0) : da;
    if (ahead.w == 0.0) return db;
    return dot(db, db) < dot(da, da) ? db : da;
}

// Whether the occluder stored in the texel of `tile` holding p lies in front of the receiver's
// tangent plane at that texel's centre. On a plane 1/w (w the light's view depth) is affine in
// light uv, so the plane's depth there follows from p and its screen neighbours (their map
// coordinates mx, my) with no slope bias, only a margin for the receiver's own curvature and
// creases. `stored` is that texel's depth.
#define ASM_PLANE_MARGIN_TEXELS 4.0
bool occluded_at_plane(ShadowLight s, vec4 m, vec3 p, vec3 ng, vec4 mx, vec4 my, AsmPage page, float stored) {
    vec2 ux = mx.xy - m.xy, uy = my.xy - m.xy;
    float det = ux.x * uy.y - ux.y * uy.x;
    if (det == 0.0) return false;
    float iw = 1.0 / m.z;
    float a = 1.0 / mx.z - iw;
    float b = 1.0 / my.z - iw;
    vec2 slope = vec2(a * uy.y - b * ux.y, ux.x * b - uy.x * a) / det;
    ivec2 texel = asm_slot_texel(page, ivec2(asm_texel_coords(page.tile, m.xy)));
    vec2 centre = asm_texel_centre(page.tile, texel);
    float inv = iw + dot(slope, centre - m.xy);
    if (inv <= 0.0) return false;
    return !shadow_depth_visible(s, stored, 1.0 / inv, p, ng, asm_texel_size(s, page.tile.x), vec4(ASM_PLANE_MARGIN_TEXELS, 0.0, 0.0, 0.0), page.step);
}

// The stored depth at the centre of tile texel `texel`, a neighbour of texel t across its page's
// border, where a tile at least as fine as the page's holds it (a resident child, another
// slot's page, a neighbouring tile): the 3x3 test clamped to the page would read the border
// texel again, and a thin occluder that crosses the border but that the page's own texels miss
// would never ask for refinement on this side (a wedge of its shadow lit, tests/tests/asm.rs).
// Where only a coarser tile holds it, its texel's centre lies farther than the test's bias
// allows for, so the page's border texel (`kept`) answers as before.
float across_border_depth(AsmPage page, ivec2 texel, float kept) {
    vec2 uv = clamp(asm_texel_centre(page.tile, texel), vec2(0.0), vec2(1.0));
    AsmPage there = asm_page(asm_descend(uv), uv);
    if (there.tile.x < page.tile.x) return kept;
    return asm_depth(there, ivec2(asm_texel_coords(there.tile, uv)));
}

void main() {
    // One pixel of each 2x2 block per frame, the block's corner turning frame by frame (the
    // paper analyses 1/8 of the pixels per frame): the refinement is progressive anyway.
    ivec2 q = 2 * ivec2(gl_GlobalInvocationID.xy) + ivec2(push.phase.x & 1u, push.phase.x >> 1u);
    vec4 here = surface(q);
    if (here.w == 0.0) return;
    vec3 p = here.xyz;
    ShadowLight s = lights[0];
    vec4 m = shadow_map_coords(s, p);
    if (m.w < 0.0) return;
    vec3 dx = difference(p, q, ivec2(1, 0)), dy = difference(p, q, ivec2(0, 1));
    vec3 ng = cross(dx, dy);
    if (dot(ng, ng) == 0.0) return;
    ng = normalize(ng);
    if (dot(ng, frame.camera_pos.xyz - p) < 0.0) ng = -ng;
    // Shadow edges matter only where the light reaches: facing it and inside a spot's cone.
    vec3 l = normalize(s.light.position.xyz - p);
    if (dot(ng, l) <= 0.0) return;
    if (s.light.position.w > 0.5 && dot(-l, s.light.direction.xyz) < s.light.direction.w) return;

    AsmTile at = asm_descend(m.xy);
    AsmPage page = asm_page(at, m.xy);
    uint level = page.tile.x;
    uint n = 1u << at.level;
    uvec3 at_tile = uvec3(at.level, min(uvec2(m.xy * float(n)), uvec2(n - 1u)));
    // The eye pixel's footprint in light uv: |det J| of the uv's screen derivatives. A tile at
    // level L has texels of 1 / (TILE 2^L) a side, so it matches the pixel where
    // 2^L = 1 / (TILE sqrt(area)); EXTRA_LEVELS finer.
    vec4 mx = shadow_map_coords(s, p + dx), my = shadow_map_coords(s, p + dy);
    float texel = asm_texel_size(s, level);
    ivec2 t = ivec2(asm_texel_coords(page.tile, m.xy));
    float stored = asm_depth(page, t);
    // Lit, but the slope-scaled bias hides an occluder in front of the receiver's plane (a
    // coarse tile under grazing light): a finer tile's bias is narrower and shows the shadow.
    bool lit = shadow_lit_past(s, stored, shadow_receiver_depth(s, m.z, p, ng, texel, push.bias, page.step));
    bool hidden = lit && occluded_at_plane(s, m, p, ng, mx, my, page, stored);
    ivec2 at_slot = asm_slot(at_tile, m.xy);
    uint slot_bit = 1u << (at_slot.y * (KAGE_ASM_TILE_TEXELS / KAGE_ASM_PAGE_TEXELS) + at_slot.x);
    // Read from its tile's own texels: the slot is in use; from an ancestor's: that one's is.
    atomicOr(requests[2u + 2u * at.node], level == at.level ? slot_bit : slot_bit << 16);
    vec2 ux = mx.xy - m.xy, uy = my.xy - m.xy;
    float area = abs(ux.x * uy.y - ux.y * uy.x);
    float needed = area > 0.0 ? -log2(float(KAGE_ASM_TILE_TEXELS) * sqrt(area)) : float(KAGE_ASM_MAX_LEVEL);
    needed += float(EXTRA_LEVELS);
    float missing = min(ceil(needed), float(KAGE_ASM_MAX_LEVEL)) - float(level);
    // On a shadow edge: the receiver's visibility against its texel and the 8 around it
    // disagrees (an occluder's silhouette, a depth discontinuity in the light's view, passes
    // within a texel). Neighbours lie up to 1 + sqrt(2) texels from p: the slope term grows so.
    // The receiver's biased depths are computed once for all the texels.
    vec4 wide_bias = vec4(push.bias.x, push.bias.y * 2.5, push.bias.z, 0.0);
    float wide = shadow_receiver_depth(s, m.z, p, ng, texel, wide_bias, page.step);
    bool centre = shadow_lit_past(s, stored, wide);
    bool edge = false;
    for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) {
            if (i != 0 || j != 0) edge = edge || shadow_lit_past(s, asm_depth(page, t + ivec2(i, j)), wide) != centre;
        }
    }
    // On the page's border, the texel across it along the axis whose border t lies on; at a
    // corner, across y in the even columns' phases and across x in the odd ones' (the diagonal
    // texel is left out). One descent, not one per axis: lavapipe runs a branch's code whether
    // or not a lane takes it (vendor-notes.md), so each descent written costs every invocation
    // (0.4 ms of the pass at 512²).
    ivec2 across = ivec2(greaterThanEqual(t, page.slot + KAGE_ASM_PAGE_TEXELS - 1)) -
                ivec2(lessThanEqual(t, page.slot));
    if (across.x != 0 && across.y != 0) across[push.phase.x & 1u] = 0;
    if (!edge && across != ivec2(0)) {
        edge = shadow_lit_past(s, across_border_depth(page, t + across, stored), wide) != centre;
    }
    edge = edge || hidden;
    // Texels from two levels up or more: the slot of the tile's parent over the pixel is asked
    // for (coarse texels can miss a thin occluder altogether, where no test sees it). On an
    // edge with its tile's own texels: the tile keeps that slot (see pool.rs, trials). Never
    // both, so one atomic (llvmpipe runs each as a loop over the lanes).
    uint asked = (level + 2u <= at.level ? slot_bit : 0u) | (edge && level == at.level ? slot_bit << 16 : 0u);
    if (asked != 0u) atomicOr(requests[1u + 2u * at.node], asked);
    if (!edge || missing < 1.0 || level >= uint(KAGE_ASM_MAX_LEVEL)) return;
    uint record = atomicAdd(requests[0], 1u);
    if (record >= push.size.w) return;
    uint word = 1u + 2u * push.size.z + KAGE_ASM_EDGE_WORDS * record;
    const float cells = float(1u << KAGE_ASM_EDGE_CELL_BITS);
    // The cell is in the finest resident tile's square, the levels missing from the page's.
    uvec2 cell = uvec2(clamp(asm_texel_coords(at_tile, m.xy) * (cells / float(KAGE_ASM_TILE_TEXELS)), 0.0, cells - 1.0));
    requests[word] = at.node | uint(missing) << KAGE_ASM_EDGE_NODE_BITS | (at.level - level) << (KAGE_ASM_EDGE_NODE_BITS + 5);
    requests[word + 1u] = cell.x | cell.y << 16;
}
