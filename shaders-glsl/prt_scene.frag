#version 460
// L = L_s - albedo * sum_i B_i T(p, w_i) V_o(p, w_i) (eq. (15)). V_o sums the filtered shadows of
// every occluder group for region i; it is clamped to 1 so that two occluders overlapping in
// one region never subtract the region twice, and L is clamped at 0.
#include "constants.glsl"
#include "layouts.glsl"
#include "occlusion.glsl"

layout(set = 0, binding = 3, std140) uniform Energy { vec4 region_energy[KAGE_MAX_REGIONS]; };
layout(set = 0, binding = 4) uniform sampler2DArray occlusion;
layout(set = 0, binding = 5, std140) uniform Layers { OcclusionLayer layers[KAGE_MAX_OCCLUSION_LAYERS]; };
layout(push_constant) uniform Push { PrtDrawPush draw; };
// 0: the paper's fixed penumbra, 1: the adaptive one (a pipeline constant: see GraphicsDesc).
layout(constant_id = 0) const uint ADAPTIVE_PENUMBRA = 0u;
// ceil(q / 4), as prt_scene.vert declares it.
layout(constant_id = 1) const uint REGION_VEC4 = KAGE_MAX_REGIONS / 4;

layout(location = 0) in vec3 self_shadowed;
layout(location = 1) in vec3 world_position;
layout(location = 2) in vec4 region_transfer[REGION_VEC4];
layout(location = 0) out vec4 color;

// Sums of both channels of a summed-area table layer over the square of half-width `half_width`
// (uv units) around `uv`. An integral up to edge X (in texels) is the table's value at texel
// X - 1, so the table is sampled half a texel before each edge; bilinear filtering gives exact
// integrals between texel edges, and the sampler's black border the zero before the first one.
vec2 table_box(uint l, vec2 uv, float half_width, float size) {
    vec2 lo = clamp(uv - half_width, 0.0, 1.0) - 0.5 / size;
    vec2 hi = clamp(uv + half_width, 0.0, 1.0) - 0.5 / size;
    float layer = float(l);
    return textureLod(occlusion, vec3(hi, layer), 0.0).rg - textureLod(occlusion, vec3(lo.x, hi.y, layer), 0.0).rg
        - textureLod(occlusion, vec3(hi.x, lo.y, layer), 0.0).rg + textureLod(occlusion, vec3(lo, layer), 0.0).rg;
}

// The adaptive penumbra (beyond the paper): the box width follows this pixel's distance to the
// occluder along the region's direction, s = sqrt(Omega_i) * distance, as the paper's R does for
// the group centres. The distance comes from the mean occluder height found in a search box
// (as in percentage-closer soft shadows); an occluder below the pixel casts nothing on it.
float adaptive_occlusion(OcclusionLayer layer, uint l, vec2 uv, vec3 offset, float size) {
    vec2 found = table_box(l, uv, 0.5 * layer.axis_u.w / size, size);
    if (found.x < 0.5) return 0.0;  // less than half a texel of occluder within reach
    float height = dot(offset, cross(layer.axis_u.xyz, layer.axis_v.xyz));
    float distance = found.y / found.x - height;
    if (distance <= 0.0) return 0.0;
    float half_width = max(0.5 * layer.axis_v.w * distance * layer.centre.w, 0.5 / size);
    float texels = 2.0 * half_width * size;
    return clamp(table_box(l, uv, half_width, size).x / (texels * texels), 0.0, 1.0);
}

void main() {
    // Layers come sorted by region, so each region's V_o is complete when the region changes.
    vec3 blocked = vec3(0.0);
    uint region = KAGE_NO_HIT;
    float occluded = 0.0;
    uint first = draw.layers.x, count = draw.layers.y;
    for (uint base = 0u; base < count; base += 32u) {
        // Most of a receiver lies outside any one occluder's shadow. The cheap footprint tests
        // come first and the texture reads loop over the hits only: a branch around a read would
        // not save it where the lanes of a SIMD group disagree (llvmpipe runs both sides of
        // every branch), but a loop ends when all its lanes are done.
        uint hits = 0u;
        for (uint k = 0u; k < min(count - base, 32u); ++k) {
            hits |= uint(within_footprint(layers[first + base + k], world_position)) << k;
        }
        while (hits != 0u) {
            uint l = first + base + uint(findLSB(hits));
            hits &= hits - 1u;
            OcclusionLayer layer = layers[l];
            if (layer.ids.x != region) {
                if (region != KAGE_NO_HIT) {
                    blocked += region_energy[region].rgb * region_transfer[region / 4][region % 4] * min(occluded, 1.0);
                }
                region = layer.ids.x;
                occluded = 0.0;
            }
            vec2 uv = occlusion_uv(layer, world_position);
            occluded += ADAPTIVE_PENUMBRA == 0u
                ? textureLod(occlusion, vec3(uv, float(l)), 0.0).r
                : adaptive_occlusion(layer, l, uv, world_position - layer.centre.xyz, float(draw.layers.w));
        }
    }
    if (region != KAGE_NO_HIT) {
        blocked += region_energy[region].rgb * region_transfer[region / 4][region % 4] * min(occluded, 1.0);
    }
    color = vec4(max(self_shadowed - draw.albedo.rgb * blocked, vec3(0.0)), 1.0);
}
