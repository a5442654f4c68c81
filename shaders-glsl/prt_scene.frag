#version 460
// L = L_s - albedo * sum_i B_i T(p, w_i) V_o(p, w_i) (eq. (15)). V_o sums the filtered shadows of
// every occluder group for region i; it is clamped to 1 so that two occluders overlapping in
// one region never subtract the region twice, and L is clamped at 0.
#include "constants.glsl"
#include "layouts.glsl"

layout(set = 0, binding = 3, std430) readonly buffer Energy { vec4 region_energy[]; };
layout(set = 0, binding = 4) uniform sampler2DArray occlusion;
layout(set = 0, binding = 5, std140) uniform Layers { OcclusionLayer layers[KAGE_MAX_OCCLUSION_LAYERS]; };
layout(push_constant) uniform Push { PrtDrawPush draw; };

layout(location = 0) in vec3 self_shadowed;
layout(location = 1) in vec3 world_position;
layout(location = 2) in vec4 region_transfer[KAGE_MAX_REGIONS / 4];
layout(location = 0) out vec4 color;

void main() {
    // Layers come sorted by region, so each region's V_o is complete when the region changes.
    vec3 blocked = vec3(0.0);
    uint region = KAGE_NO_HIT;
    float occluded = 0.0;
    for (uint l = draw.layers.x; l < draw.layers.x + draw.layers.y; ++l) {
        OcclusionLayer layer = layers[l];
        if (layer.ids.x != region) {
            if (region != KAGE_NO_HIT) {
                blocked += region_energy[region].rgb * region_transfer[region / 4][region % 4] * min(occluded, 1.0);
            }
            region = layer.ids.x;
            occluded = 0.0;
        }
        vec3 offset = world_position - layer.centre.xyz;
        vec2 uv = vec2(dot(offset, layer.axis_u.xyz), dot(offset, layer.axis_v.xyz)) * layer.centre.w + 0.5;
        occluded += textureLod(occlusion, vec3(uv, float(l)), 0.0).r;
    }
    if (region != KAGE_NO_HIT) {
        blocked += region_energy[region].rgb * region_transfer[region / 4][region % 4] * min(occluded, 1.0);
    }
    color = vec4(max(self_shadowed - draw.albedo.rgb * blocked, vec3(0.0)), 1.0);
}
