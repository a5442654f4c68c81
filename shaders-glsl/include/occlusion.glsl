// Where a world point falls in an occlusion layer, and whether the layer can hold any shadow
// there: shared by the occluder masks and the scene pass.
#ifndef KAGE_OCCLUSION_GLSL
#define KAGE_OCCLUSION_GLSL
#include "layouts.glsl"

// The layer's mask coordinates of `world`: the orthographic projection along the region's
// direction onto the plane through the occluder's centre, [0, 1]² over the mask.
vec2 occlusion_uv(OcclusionLayer layer, vec3 world) {
    vec3 offset = world - layer.centre.xyz;
    return vec2(dot(offset, layer.axis_u.xyz), dot(offset, layer.axis_v.xyz)) * layer.centre.w + 0.5;
}

// Height of `world` above the mask's plane, towards the light (world units).
float occlusion_height(OcclusionLayer layer, vec3 world) {
    return dot(world - layer.centre.xyz, cross(layer.axis_u.xyz, layer.axis_v.xyz));
}

// Whether a read of the layer within `margin` (mask uv units) of `world` can return anything
// but 0 (see OcclusionLayer).
bool within_footprint(OcclusionLayer layer, vec3 world, float margin) {
    vec2 uv = occlusion_uv(layer, world);
    return all(greaterThanEqual(uv, layer.footprint.xy - margin)) && all(lessThanEqual(uv, layer.footprint.zw + margin));
}
#endif
