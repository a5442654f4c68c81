// The depth comparison of a local light's shadow map (shadowmap and ASM techniques, and the ASM
// refinement analysis): the stored depth linearized, compared with the receiver's view depth
// less a slope-scaled bias.
#ifndef KAGE_SHADOW_TEST_GLSL
#define KAGE_SHADOW_TEST_GLSL

#include "layouts.glsl"
#include "view_depth.glsl"

// The light's map coordinates of p: xy in [0, 1) inside the map (rows downward, as texels),
// z the view depth along the light's axis (clip w); w < 0 where p is outside the map.
vec4 shadow_map_coords(ShadowLight s, vec3 p) {
    vec4 clip = s.view_proj * vec4(p, 1.0);
    vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
    bool inside = clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) && all(lessThan(uv, vec2(1.0)));
    return vec4(uv, clip.w, inside ? 1.0 : -1.0);
}

// The view depth a receiver at view depth w (point p, geometric normal ng) must not pass to be
// lit, for texels of world size `texel` at unit depth. bias: x constant and y slope-scaled bias
// in texels, z the largest slope (tan) the bias follows. `step`: the stored depths' rounding
// step (Vulkan depth) where they are stored coarser than D32 (ASM's pages), else 0.
float shadow_receiver_depth(ShadowLight s, float w, vec3 p, vec3 ng, float texel, vec4 bias, float step) {
    float near = s.map.x, far = s.map.y;
    // The depth a surface spans inside one texel grows with the texel (w * texel in world
    // units) and with tan of the light's angle to the surface: the slope-scaled bias.
    vec3 l = normalize(s.light.position.xyz - p);
    float c = max(dot(ng, l), 1e-4);
    float slope = min(sqrt(max(1.0 - c * c, 0.0)) / c, bias.z);
    // Fine texels (deep ASM tiles) fall below the D32 depth's own resolution near the far plane:
    // d(z)/d(d) = z^2 (far - near) / (near far), times 4 ulps of a depth near 1 (2^-24 each),
    // and half a step of depths stored coarser.
    float resolution = w * w * (far - near) / (near * far) * (2.4e-7 + 0.5 * step);
    return w - w * texel * (bias.x + bias.y * slope) - resolution;
}

// Whether a receiver whose biased depth is `receiver` (shadow_receiver_depth) is lit past a
// texel that stores Vulkan depth `stored`.
bool shadow_lit_past(ShadowLight s, float stored, float receiver) {
    return receiver <= view_depth(stored, s.map.x, s.map.y);
}

// Whether a receiver at view depth w is lit past a texel that stores Vulkan depth `stored`
// (shadow_receiver_depth's arguments).
bool shadow_depth_visible(ShadowLight s, float stored, float w, vec3 p, vec3 ng, float texel, vec4 bias, float step) {
    return shadow_lit_past(s, stored, shadow_receiver_depth(s, w, p, ng, texel, bias, step));
}

// Hard shadows reconstructed between texel centres: the four texels around texel-space point f
// (texel centres at i + 1/2) are each tested, and f is lit where their bilinear blend is at least
// 1/2. The edge then runs through the cells between differing texel centres, close to the true
// edge along its length, where the nearest texel's staircase strays up to half a texel diagonal
// (kage bench asm: 7 % fewer misclassified pixels in both techniques). The slope-scaled bias
// covers 1 texel along the slope; the corners farther than that from f weigh under 0.14 together,
// so they never decide.
// Corner j = 0..3 (x, then y) of f's footprint: its texel.
ivec2 shadow_footprint_texel(vec2 f, int j) {
    return ivec2(floor(f - 0.5)) + ivec2(j & 1, j >> 1);
}

// Whether f is lit, the four texels of its footprint (shadow_footprint_texel, in corner order)
// storing Vulkan depths `stored`, for a receiver of biased depth `receiver`.
bool shadow_footprint_visible(ShadowLight s, vec2 f, vec4 stored, float receiver) {
    vec2 a = fract(f - 0.5);
    vec4 weight = vec4((1.0 - a.x) * (1.0 - a.y), a.x * (1.0 - a.y), (1.0 - a.x) * a.y, a.x * a.y);
    float lit = 0.0;
    for (int j = 0; j < 4; ++j) {
        if (shadow_lit_past(s, stored[j], receiver)) lit += weight[j];
    }
    return lit >= 0.5;
}

#endif
