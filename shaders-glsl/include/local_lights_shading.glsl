// The lighting of the shadowmap and ASM techniques (local_lights.frag, asm_lights.frag): direct
// light from the scene's point and spot lights with hard shadows,
// L = albedo / pi * sum_k I_k cos / d^2 * V_k, lit exactly as the reference's --light local
// (local_light.glsl). The including shader declares its shadow maps and defines
// `bool visible(uint k, vec3 p, vec3 ng)`, V_k, and KAGE_ALBEDO_MAP_BINDING (albedo_map.glsl);
// this file declares bindings 0 and 1, the albedo map and main.
#ifndef KAGE_LOCAL_LIGHTS_SHADING_GLSL
#define KAGE_LOCAL_LIGHTS_SHADING_GLSL

#include "layouts.glsl"
#include "local_light.glsl"
#include "sh.glsl"
#include "shadow_test.glsl"
#include "albedo_map.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform Lights { ShadowLight lights[KAGE_MAX_LOCAL_LIGHTS]; };
layout(push_constant) uniform Push { LocalDrawPush draw; };
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 texcoord;
layout(location = 0) out vec4 color;

bool visible(uint k, vec3 p, vec3 ng);

// The point of the surface through q (normal ng) on the eye ray through this pixel's centre,
// where the reference's primary ray finds it. The interpolated position strays from that ray
// by the float error of interpolating across a large triangle (about 1/100 px measured),
// which moves a spot's cone edge and the shadows' edges by as much. Kept within half a
// pixel's footprint of q: at grazing view the plane's normal is too uncertain to follow.
vec3 on_pixel_ray(vec3 q, vec3 ng) {
    vec2 ndc = gl_FragCoord.xy / frame.viewport.xy * 2.0 - 1.0;
    vec4 far = frame.inv_view_proj * vec4(ndc, 0.5, 1.0);
    vec3 o = frame.camera_pos.xyz;
    vec3 d = normalize(far.xyz / far.w - o);
    float dn = dot(d, ng);
    vec3 p = o + d * (dot(q - o, ng) / dn);
    bool near = dn != 0.0 && length(p - q) <= 0.5 * length(fwidth(q));
    return near ? p : q;
}

void main() {
    // Oriented as the reference's bvh_surface does: the geometric normal towards the camera,
    // the shading normal flipped with it on back faces (two-sided surfaces).
    vec3 ng = normalize(cross(dFdx(world_position), dFdy(world_position)));
    if (dot(ng, frame.camera_pos.xyz - world_position) < 0.0) ng = -ng;
    vec3 p = on_pixel_ray(world_position, ng);
    vec3 ns = normalize(gl_FrontFacing ? world_normal : -world_normal);
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < draw.params.x; ++k) {
        vec3 e = local_light_unshadowed(lights[k].light, p, ns, ng);
        if (any(greaterThan(e, vec3(0.0))) && visible(k, p, ng)) {
            sum += e;
        }
    }
    color = vec4(draw.albedo.rgb * albedo_texel(texcoord) / KAGE_PI * sum, 1.0);
}

#endif
