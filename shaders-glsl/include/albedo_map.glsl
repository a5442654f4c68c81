// The mesh's albedo map, which a lit pipeline binds per draw as its last binding
// (engine/src/frame/albedo_maps.rs): the including fragment shader defines
// KAGE_ALBEDO_MAP_BINDING, the binding after its own, and multiplies its radiance, which is
// linear in the albedo, by albedo_texel(uv). A mesh without a map reads a white texel.
#ifndef KAGE_ALBEDO_MAP_GLSL
#define KAGE_ALBEDO_MAP_GLSL

layout(set = 0, binding = KAGE_ALBEDO_MAP_BINDING) uniform sampler2D albedo_map;

// The map's linear colour at texture coordinate uv (sRGB decoded by the image's format).
vec3 albedo_texel(vec2 uv) {
    return texture(albedo_map, uv).rgb;
}

#endif
