// Direct light from one point or spot light (ReferenceLight), shared by the reference
// (reference_render.comp) and the shadowmap technique (local_lights.frag) so that the two
// compare pixel by pixel: radiant intensity I over squared distance, no attenuation beyond the
// inverse square; a spot light is a hard-edged cone (full intensity inside, none outside).
#ifndef KAGE_LOCAL_LIGHT_GLSL
#define KAGE_LOCAL_LIGHT_GLSL

#include "layouts.glsl"

// I cos(theta) / d^2 at p with shading normal ns and geometric normal ng (both on the side the
// viewer sees), visibility left out; 0 where the light is behind either normal or outside the
// spot's cone.
vec3 local_light_unshadowed(ReferenceLight light, vec3 p, vec3 ns, vec3 ng) {
    vec3 to_light = light.position.xyz - p;
    float d2 = dot(to_light, to_light);
    if (d2 <= 0.0) return vec3(0.0);
    vec3 l = to_light * inversesqrt(d2);
    float cos_n = dot(ns, l);
    if (cos_n <= 0.0 || dot(ng, l) <= 0.0) return vec3(0.0);
    if (light.position.w > 0.5 && dot(-l, light.direction.xyz) < light.direction.w) return vec3(0.0);
    return light.intensity.rgb * (cos_n / d2);
}

#ifdef KAGE_BVH_GLSL
// The same with one shadow ray from p (offset along ng) to the light: the reference's hard
// shadows, shared by its image and irradiance modes.
vec3 local_light_shadowed(ReferenceLight light, vec3 p, vec3 ns, vec3 ng) {
    vec3 e = local_light_unshadowed(light, p, ns, ng);
    if (all(equal(e, vec3(0.0)))) return e;
    vec3 origin = offset_ray_origin(p, ng);
    vec3 to_light = light.position.xyz - origin;
    float tmax = length(to_light);
    return bvh_occluded(origin, to_light / tmax, tmax) ? vec3(0.0) : e;
}
#endif

#endif
