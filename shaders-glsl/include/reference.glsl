// The Monte Carlo reference's shared half: the environment map and its sampling distribution
// (engine/src/reference/env_sampling.rs builds it), the per-item statistics, and the estimator
// of direct environment lighting with full visibility. The including shader includes bvh.glsl
// first and declares its own bindings from KAGE_BVH_BINDINGS + 3 on.
#ifndef KAGE_REFERENCE_GLSL
#define KAGE_REFERENCE_GLSL

#include "constants.glsl"
#include "layouts.glsl"
#include "envmap.glsl"
#include "sampling.glsl"

layout(set = 0, binding = KAGE_BVH_BINDINGS + 0) uniform sampler2D env;
// The sampling distribution's alias table (Walker 1977; EnvDistribution::alias_words), a texel
// buffer of two entries a texel: per texel of the map, row by row, the chance in 2^32 that a
// draw of its slot yields its alias instead, and the alias. A texel buffer because llvmpipe
// gathers a texel fetch where it reads a storage buffer lane by lane (vendor-notes.md).
layout(set = 0, binding = KAGE_BVH_BINDINGS + 1) uniform usamplerBuffer env_alias_texels;
layout(set = 0, binding = KAGE_BVH_BINDINGS + 2, std430) buffer Accum { ReferenceAccum accum[]; };

const float REFERENCE_PI = 3.14159265358979323846;
// "Infinite" ray length: the environment is at infinity.
const float REFERENCE_FAR = 1e30;

// The lighting treats the map as constant over each texel (nearest texel, no filtering), the
// same function the sampling distribution and the SH projection use.
ivec2 env_texel_of(vec3 dir) {
    ivec2 size = textureSize(env, 0);
    vec2 uv = env_dir_to_uv(dir);
    return min(ivec2(uv * vec2(size)), size - 1);
}

// A direction drawn in proportion to luminance x solid angle: the texel from the alias table (a
// slot uniform over the texels, then the slot's texel or its alias by the slot's chance: one
// fetch), then uniform in solid angle inside it, so the pdf is luminance / total everywhere in
// the texel. Returns the texel. Needs a map of positive total.
ivec2 env_sample(inout Rng rng, out vec3 dir) {
    ivec2 size = textureSize(env, 0);
    uint w = uint(size.x), h = uint(size.y);
    uint slot = rng_below(rng, w * h);
    uvec4 pair = texelFetch(env_alias_texels, int(slot >> 1u));
    uvec2 entry = (slot & 1u) == 0u ? pair.xy : pair.zw;
    uint t = rng_next_word(rng) < entry.x ? entry.y : slot;
    uint i = t % w, j = t / w;
    float v_in = rng_next(rng), u_in = rng_next(rng);
    float cos0 = cos(REFERENCE_PI * float(j) / float(h));
    float cos1 = cos(REFERENCE_PI * float(j + 1u) / float(h));
    float cos_theta = mix(cos0, cos1, v_in);
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    float phi = 2.0 * REFERENCE_PI * (float(i) + u_in) / float(w);
    dir = vec3(sin_theta * sin(phi), cos_theta, -sin_theta * cos(phi));
    return ivec2(i, j);
}

// Candidates of the environment strategy's resampling (see env_irradiance_sample).
const uint REFERENCE_CANDIDATES = 16u;

// One two-sample estimate of E = integral of L_env(w) V(w) max(dot(n, w), 0) dw at p: one
// direction from the environment strategy and one cosine-weighted, combined by the power
// heuristic. `ng` is the geometric normal on the side the light arrives from: directions below
// it are blocked by the surface itself (with smooth shading normals they exist), and shadow
// rays leave from p offset along it. total == 0 (a black map) means cosine sampling alone.
//
// The environment strategy resamples (Talbot et al. 2005, resampled importance sampling): of
// REFERENCE_CANDIDATES directions drawn in proportion to luminance, one is kept in proportion
// to its cosine, so the shadow ray goes where L cos is large. A few bright lamps low over the
// horizon (studio maps) are drawn as often as their energy says, but light a floor in
// proportion to their cosine: without resampling most shadow rays went to lamps that light
// little. The kept direction y contributes f(y) W, W = mean(w) / (luminance(y) cos(y) / total)
// with w = cos (the candidates' target over their pdf, up to the constant total): unbiased for
// any target that is positive wherever f is. Its MIS weight takes the luminance pdf: any
// weights that add up to one per direction keep the sum unbiased.
vec3 env_irradiance_sample(vec3 p, vec3 n, vec3 ng, float total, inout Rng rng) {
    vec3 origin = offset_ray_origin(p, ng);
    vec3 sum = vec3(0.0);
    if (total > 0.0) {
        vec3 kept_dir = vec3(0.0);
        ivec2 kept_texel = ivec2(0);
        float weights = 0.0;
        // The candidates' weights need their directions only: the kept one's texel is read once.
        for (uint k = 0u; k < REFERENCE_CANDIDATES; ++k) {
            vec3 dir;
            ivec2 texel = env_sample(rng, dir);
            float w = dot(ng, dir) > 0.0 ? max(dot(n, dir), 0.0) : 0.0;
            weights += w;
            if (w > 0.0 && rng_next(rng) * weights < w) {
                kept_dir = dir;
                kept_texel = texel;
            }
        }
        vec3 kept_radiance = texelFetch(env, kept_texel, 0).rgb;
        float kept_pdf = luminance(kept_radiance) / total;
        if (weights > 0.0 && kept_pdf > 0.0 && !bvh_occluded(origin, kept_dir, REFERENCE_FAR)) {
            float cos_n = dot(n, kept_dir);
            sum += power_heuristic(kept_pdf, cos_n / REFERENCE_PI) * kept_radiance
                * (weights / float(REFERENCE_CANDIDATES) / kept_pdf);
        }
    }
    vec2 u_cos = vec2(rng_next(rng), rng_next(rng));
    vec3 dir = sample_cosine(n, u_cos);
    float cos_n = dot(n, dir);
    if (cos_n > 0.0 && dot(ng, dir) > 0.0 && !bvh_occluded(origin, dir, REFERENCE_FAR)) {
        vec3 radiance = texelFetch(env, env_texel_of(dir), 0).rgb;
        float pdf_env = total > 0.0 ? luminance(radiance) / total : 0.0;
        // radiance * cos / (cos / pi), weighted.
        sum += power_heuristic(cos_n / REFERENCE_PI, pdf_env) * radiance * REFERENCE_PI;
    }
    return sum;
}

// Adds a batch (count, mean, m2 over its samples) to item `index`'s statistics (Chan et al.
// 1979, the pairwise form of Welford's update).
void accum_merge(uint index, uint before, uint count, vec3 mean, vec3 m2) {
    if (before == 0u) {
        accum[index] = ReferenceAccum(vec4(mean, 0.0), vec4(m2, 0.0));
        return;
    }
    ReferenceAccum a = accum[index];
    float total = float(before + count);
    vec3 delta = mean - a.mean.rgb;
    a.mean.rgb += delta * (float(count) / total);
    a.m2.rgb += m2 + delta * delta * (float(before) * float(count) / total);
    accum[index] = a;
}

#endif
