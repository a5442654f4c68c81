#version 460
#extension GL_EXT_control_flow_attributes : require
// L = L_s - albedo * sum_i B_i T(p, w_i) V_o(p, w_i) (eq. (15)). V_o sums the filtered shadows of
// every occluder group for region i; it is clamped to 1 so that two occluders overlapping in
// one region never subtract the region twice, and L is clamped at 0. Beyond the paper, the
// dominant lights taken out of the map add albedo / pi * sum_j B_j max(n . w_j, 0) V_j(p).
#include "constants.glsl"
#include "layouts.glsl"
#include "occlusion.glsl"
#include "sh.glsl"
#include "envmap.glsl"
#define KAGE_ALBEDO_MAP_BINDING 10
#include "albedo_map.glsl"

layout(set = 0, binding = 3, std140) uniform Energy { vec4 region_energy[KAGE_MAX_REGIONS]; };
layout(set = 0, binding = 4) uniform sampler2DArray occlusion;
layout(set = 0, binding = 5, std140) uniform Layers { OcclusionLayer layers[KAGE_MAX_OCCLUSION_LAYERS]; };
layout(set = 0, binding = 6, std140) uniform Dominant { DominantLights dominant; };
layout(set = 0, binding = 7) uniform sampler2DArrayShadow dominant_shadow;
// The exact irradiance of the light L_s is made of (engine/src/frame/irradiance.rs).
layout(set = 0, binding = 9) uniform sampler2D irradiance;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
#include "dominant.glsl"
layout(push_constant) uniform Push { PrtDrawPush draw; };
// 0: the paper's fixed penumbra, 1: the adaptive one (a pipeline constant: see GraphicsDesc).
layout(constant_id = 0) const uint ADAPTIVE_PENUMBRA = 0u;
// ceil(q / 4), as prt_scene.vert declares it.
layout(constant_id = 1) const uint REGION_VEC4 = KAGE_MAX_REGIONS / 4;
// The dominant lights (see dominant.glsl), fixed for the renderer's life.
layout(constant_id = 3) const uint DOMINANT_LIGHTS = 0u;
// The cosine per pixel (see prt_scene.vert).
layout(constant_id = 4) const bool PIXEL_COSINE = false;

layout(location = 0) in vec3 self_term;
layout(location = 1) in vec3 world_position;
layout(location = 2) in vec3 world_normal;
layout(location = 3) in vec2 texcoord;
layout(location = 4) flat in uvec4 candidates[KAGE_LAYER_UVEC4];
layout(location = 4 + KAGE_LAYER_UVEC4) in vec4 region_transfer[REGION_VEC4];
layout(location = 0) out vec4 color;

// The adaptive penumbra (beyond the paper): a box as wide as sqrt(Omega_i) times this pixel's
// distance to the occluder along the region's direction, as the paper's R is for the group
// centres. The distance is the mean occluder height over the widest box (as percentage-closer
// soft shadows find it) less the pixel's own; an occluder below the pixel casts nothing on it.
// The filter passes left boxes of 1, the middle and the widest width side by side (R, G, B; A
// the occluder heights), and the coverage of the wanted width is interpolated between them.
float adaptive_occlusion(OcclusionLayer layer, vec4 boxes) {
    if (boxes.b <= 1e-4) return boxes.r;
    float distance = boxes.a / boxes.b - occlusion_height(layer, world_position);
    if (distance <= 0.0) return 0.0;
    float width = max(layer.widen * distance, 1.0);
    float middle = layer.axis_u.w, widest = layer.axis_v.w;
    return width <= middle
        ? mix(boxes.r, boxes.g, middle > 1.0 ? (width - 1.0) / (middle - 1.0) : 0.0)
        : mix(boxes.g, boxes.b, widest > middle ? min((width - middle) / (widest - middle), 1.0) : 0.0);
}

// What the occluders hide of `source`, V_o summed over them: two occluders overlapping in one
// source never take it away twice. A region this point's transfer does not reach (T <= 0, SH
// ringing), or a dominant light it faces away from, loses nothing.
void take_away(uint source, float occluded, float lit[KAGE_MAX_DOMINANT_LIGHTS], inout vec3 blocked,
               inout vec3 dominant_blocked) {
    uint regions = draw.mesh.w;
    if (source < regions) {
        blocked += region_energy[source].rgb * max(region_transfer[source / 4u][source % 4u], 0.0) * min(occluded, 1.0);
    } else if (DOMINANT_LIGHTS > 0u && source != KAGE_NO_HIT) {
        dominant_blocked += dominant.lights[source - regions].energy.rgb * lit[source - regions] * min(occluded, 1.0);
    }
}

void main() {
    // The dominant lights' exact cosine and self-shadow: B_j max(n . w_j, 0) v_j (constant
    // indices), before the other groups' shadows take their share. Two-sided surfaces, as in
    // scene.frag: the back of an open mesh faces the viewer.
    vec3 n = normalize(gl_FrontFacing ? world_normal : -world_normal);
    float lit[KAGE_MAX_DOMINANT_LIGHTS];
    vec3 dominant_light = vec3(0.0);
    [[unroll]] for (uint j = 0u; j < DOMINANT_LIGHTS; ++j) {
        float c = max(dot(n, dominant.lights[j].direction.xyz), 0.0);
        lit[j] = c > 0.0 ? c * dominant_self_visibility(j, draw.layers.z, world_position, n, c) : 0.0;
        dominant_light += dominant.lights[j].energy.rgb * lit[j];
    }
    // Layers come sorted by source (regions, then dominant lights), so each one's V_o is
    // complete when the source changes.
    vec3 blocked = vec3(0.0), dominant_blocked = vec3(0.0);
    uint source = KAGE_NO_HIT;
    float occluded = 0.0;
    uint first = draw.layers.x;
    // llvmpipe runs both sides of every branch and tests a loop's condition after its body
    // (a loop whose lanes are all done at the start still runs its body once), so the layers
    // are walked in one bottom-tested loop per 32 of them, as many times as the SIMD group's
    // busiest lane has candidates: the layers its triangle can reach (see prt_scene.vert).
    uint words = (draw.layers.y + 31u) / 32u, w = 0u;
    do {
        uint hits = candidates[w / 4u][w % 4u];
        do {
            bool live = hits != 0u;
            uint l = first + 32u * w + (live ? uint(findLSB(hits)) : 0u);
            hits &= hits - 1u;
            OcclusionLayer layer = layers[l];
            if (live) {
                if (layer.region != source) {
                    take_away(source, occluded, lit, blocked, dominant_blocked);
                    source = layer.region;
                    occluded = 0.0;
                }
                vec4 boxes = textureLod(occlusion, vec3(occlusion_uv(layer, world_position), float(l)), 0.0);
                occluded += ADAPTIVE_PENUMBRA == 0u ? boxes.r : adaptive_occlusion(layer, boxes);
            }
        } while (hits != 0u);
    } while (++w < words);
    take_away(source, occluded, lit, blocked, dominant_blocked);
    // The dominant lights a sheet hides wholly, which have no layers (the regions it hides are
    // in self_term: see prt_scene.vert).
    [[unroll]] for (uint j = 0u; j < DOMINANT_LIGHTS; ++j) {
        uint s = draw.mesh.w + j;
        bool gone = (draw.covered[s / 32u] & (1u << (s % 32u))) != 0u;
        dominant_blocked += gone ? dominant.lights[j].energy.rgb * lit[j] : vec3(0.0);
    }

    vec3 self_shadowed = self_term;
    if (PIXEL_COSINE) {
        vec3 d = env_world_to_map(normalize(world_normal), frame.env_params.y);
        vec3 unshadowed = textureLod(irradiance, irradiance_uv(d, textureSize(irradiance, 0)), 0.0).rgb;
        self_shadowed = draw.albedo.rgb / KAGE_PI * unshadowed - self_term;
    }
    vec3 radiance = max(self_shadowed - draw.albedo.rgb * blocked, vec3(0.0))
        + draw.albedo.rgb / KAGE_PI * max(dominant_light - dominant_blocked, vec3(0.0));
    color = vec4(radiance * albedo_texel(texcoord), 1.0);
}
