#version 460
// Shadowmap technique: direct light from the scene's point and spot lights with hard shadows,
// L = albedo / pi * sum_k I_k cos / d^2 * V_k, lit exactly as the reference's --light local
// (local_light.glsl). V_k is one depth comparison in light k's map (no filtering: the
// reference's shadows are hard), made in linear depth with a slope-scaled bias.
#include "layouts.glsl"
#include "local_light.glsl"
#include "sh.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform Lights { ShadowLight lights[KAGE_MAX_LOCAL_LIGHTS]; };
layout(set = 0, binding = 2) uniform sampler2DArray shadow_maps;
layout(push_constant) uniform Push { LocalDrawPush draw; };
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 0) out vec4 color;

// Whether p is seen by light k: its map's nearest texel holds a depth at least p's, less the
// bias. Points outside the map (a point light's map covers only its field of view) are lit.
bool visible(uint k, vec3 p, vec3 ng) {
    ShadowLight s = lights[k];
    vec4 clip = s.view_proj * vec4(p, 1.0);
    vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
    if (clip.w <= 0.0 || any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) {
        return true;
    }
    int size = textureSize(shadow_maps, 0).x;
    ivec2 texel = min(ivec2(uv * float(size)), ivec2(size - 1));
    float stored = texelFetch(shadow_maps, ivec3(texel, int(k)), 0).r;
    // Vulkan depth of a right-handed perspective projection back to view depth:
    // z = near * far / (far - d * (far - near)); the receiver's view depth is clip.w.
    float near = s.map.x, far = s.map.y;
    float occluder = near * far / (far - stored * (far - near));
    // The depth a surface spans inside one texel grows with the texel (clip.w * map.z in world
    // units) and with tan of the light's angle to the surface: the slope-scaled bias.
    vec3 l = normalize(s.light.position.xyz - p);
    float c = max(dot(ng, l), 1e-4);
    float slope = min(sqrt(max(1.0 - c * c, 0.0)) / c, draw.bias.z);
    float bias = clip.w * s.map.z * (draw.bias.x + draw.bias.y * slope);
    return clip.w - bias <= occluder;
}

void main() {
    vec3 p = world_position;
    // Oriented as the reference's bvh_surface does: the geometric normal towards the camera,
    // the shading normal flipped with it on back faces (two-sided surfaces).
    vec3 ng = normalize(cross(dFdx(p), dFdy(p)));
    if (dot(ng, frame.camera_pos.xyz - p) < 0.0) ng = -ng;
    vec3 ns = normalize(gl_FrontFacing ? world_normal : -world_normal);
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < draw.params.x; ++k) {
        vec3 e = local_light_unshadowed(lights[k].light, p, ns, ng);
        if (any(greaterThan(e, vec3(0.0))) && visible(k, p, ng)) {
            sum += e;
        }
    }
    color = vec4(draw.albedo.rgb / KAGE_PI * sum, 1.0);
}
