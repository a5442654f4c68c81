// The dominant lights' per-pixel lighting (beyond the paper; see
// engine/src/techniques/tamura/dominant_maps.rs): an exact cosine, the group's own shadow from
// its depth map along the light (one bilinear percentage-closer tap), and the other groups'
// shadows from the occlusion layers (prt_scene.frag). The including shader declares `dominant`
// (DominantLights) and `dominant_shadow` (sampler2DArrayShadow).
#ifndef KAGE_DOMINANT_GLSL
#define KAGE_DOMINANT_GLSL
#include "layouts.glsl"

// The fraction of light j that the group of map slot `slot` (0: none, a flat group) leaves
// visible at `p` (normal `n`, cosine `c` to the light).
float dominant_self_visibility(uint j, uint slot, vec3 p, vec3 n, float c) {
    if (slot == 0u) return 1.0;
    uint m = dominant.lights[j].maps.x + slot - 1u;
    DominantMap map = dominant.maps[m];
    // Normal offset against acne: more where the light grazes the surface (as parallel lights),
    // half as much as parallel lights' in texels: these maps are fitted to one group, their
    // texels finer, and a larger offset leaks light into the group's own creases (measured:
    // twice this offset raised the error under every sun map, half of it brought acne back).
    float texel = map.params.x, size = map.params.y;
    float s = sqrt(max(1.0 - c * c, 0.0));
    vec3 clip = (map.view_proj * vec4(p + n * texel * (0.75 * s + 0.25), 1.0)).xyz;
    return texture(dominant_shadow, vec4(clip.xy * 0.5 + 0.5, float(m), clip.z - 0.5 / size));
}
#endif
