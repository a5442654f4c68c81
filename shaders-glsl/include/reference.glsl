// The Monte Carlo reference's shared half: the environment map and its sampling distribution
// (engine/src/reference/env_sampling.rs builds it), the per-item statistics, and the estimator
// of direct environment lighting with full visibility. The including shader includes bvh.glsl
// first and declares its own bindings from KAGE_BVH_BINDINGS + 4 on.
#ifndef KAGE_REFERENCE_GLSL
#define KAGE_REFERENCE_GLSL

#include "constants.glsl"
#include "layouts.glsl"
#include "envmap.glsl"
#include "sampling.glsl"

layout(set = 0, binding = KAGE_BVH_BINDINGS + 0) uniform sampler2D env;
// The sampling distribution's CDFs as texel buffers of four words a texel: llvmpipe gathers a
// texel fetch where it reads a storage buffer lane by lane (vendor-notes.md). Each holds the
// CDF entries' bits, up to a whole texel, then their guide (EnvDistribution::marginal_words):
// per run of n + 1 entries, for each of n equal cells of u, a word with the range of indices
// where the search for u can end. The marginal: height + 1 entries, P(row < j).
layout(set = 0, binding = KAGE_BVH_BINDINGS + 1) uniform usamplerBuffer env_marginal_texels;
// The conditionals: height runs of width + 1 entries, P(column < i | row j).
layout(set = 0, binding = KAGE_BVH_BINDINGS + 2) uniform usamplerBuffer env_conditional_texels;

// Entry k of a CDF texel buffer.
float env_cdf(usamplerBuffer cdf, uint k) { return uintBitsToFloat(texelFetch(cdf, int(k >> 2))[k & 3u]); }
layout(set = 0, binding = KAGE_BVH_BINDINGS + 3, std430) buffer Accum { ReferenceAccum accum[]; };

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

// In run `run` of n + 1 entries of `cdf` (`runs` of them), the first entry greater than u,
// minus one: never an empty interval. The guide's word for u's cell (after the texels of all
// the runs' entries, start | end << 16) bounds where that entry lies, so a search of its range
// alone ends where a search of the whole run would.
uint env_pick(usamplerBuffer cdf, uint run, uint runs, uint n, float u) {
    uint base = run * (n + 1u);
    uint cell = run * n + min(uint(u * float(n)), n - 1u);
    uint guide = texelFetch(cdf, int((runs * (n + 1u) + 3u) / 4u + cell / 4u))[cell & 3u];
    uint lo = guide & 0xffffu, hi = guide >> 16;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (env_cdf(cdf, base + mid) <= u) lo = mid + 1u; else hi = mid;
    }
    return clamp(lo, 1u, n) - 1u;
}

float env_within(float u, float c0, float c1) {
    return c1 > c0 ? clamp((u - c0) / (c1 - c0), 0.0, 1.0) : 0.5;
}

// A direction drawn in proportion to luminance x solid angle: texel by the CDFs, then uniform in
// solid angle inside it, so the pdf is luminance / total everywhere in the texel. Returns the
// texel, or (-1, -1) where an interval of the CDFs it lies in is empty (a direction of no
// density, which only u past the last entry reaches). Needs a map of positive total.
ivec2 env_sample(vec2 u, out vec3 dir) {
    ivec2 size = textureSize(env, 0);
    uint w = uint(size.x), h = uint(size.y);
    uint j = env_pick(env_marginal_texels, 0u, 1u, h, u.x);
    float row0 = env_cdf(env_marginal_texels, j), row1 = env_cdf(env_marginal_texels, j + 1u);
    uint i = env_pick(env_conditional_texels, j, h, w, u.y);
    uint base = j * (w + 1u);
    float column0 = env_cdf(env_conditional_texels, base + i);
    float column1 = env_cdf(env_conditional_texels, base + i + 1u);
    float v_in = env_within(u.x, row0, row1);
    float u_in = env_within(u.y, column0, column1);
    float cos0 = cos(REFERENCE_PI * float(j) / float(h));
    float cos1 = cos(REFERENCE_PI * float(j + 1u) / float(h));
    float cos_theta = mix(cos0, cos1, v_in);
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    float phi = 2.0 * REFERENCE_PI * (float(i) + u_in) / float(w);
    dir = vec3(sin_theta * sin(phi), cos_theta, -sin_theta * cos(phi));
    return row1 > row0 && column1 > column0 ? ivec2(i, j) : ivec2(-1);
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
            ivec2 texel = env_sample(vec2(rng_next(rng), rng_next(rng)), dir);
            float w = texel.x >= 0 && dot(ng, dir) > 0.0 ? max(dot(n, dir), 0.0) : 0.0;
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
