#version 460
// The ground truth: direct lighting of the diffuse scene with full visibility, one invocation
// per pixel, one primary ray through the pixel centre (the rasterizer has no antialiasing
// either). Environment mode adds `frame.w` Monte Carlo samples of the reflected radiance
// albedo / pi * E (see reference.glsl) to each pixel's statistics; a ray that misses shows the
// environment bilinearly filtered, as the raster background does. Local mode is deterministic:
// point and spot lights with hard shadows, one shadow ray each, black background (and
// coverage 0 there, see ReferenceAccum); it also
// records the lowest and highest luminance the pixel takes when its primary ray moves by the
// rasterizer's sub-pixel precision along x or y (edge ties, see metrics.rs).
#include "constants.glsl"
#include "layouts.glsl"
#include "bvh.glsl"
#include "reference.glsl"
#include "local_light.glsl"
#include "eye_ray.glsl"

layout(local_size_x = KAGE_REFERENCE_GROUP, local_size_y = KAGE_REFERENCE_GROUP) in;
layout(set = 0, binding = KAGE_BVH_BINDINGS + 3, std430) readonly buffer Lights {
    ReferenceLight lights[];
};
layout(push_constant) uniform Push { ReferencePush p; };

// Point and spot lights (local_light.glsl), one shadow ray each.
vec3 local_lighting(SurfacePoint s) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < p.params.y; ++k) {
        sum += local_light_shadowed(lights[k], s.position, s.shading_normal, s.geometric_normal);
    }
    return s.albedo / REFERENCE_PI * sum;
}

// The primary ray through `at` (in pixels from the image's top-left corner).
vec3 primary_dir(vec2 at) {
    return normalize(eye_ray(p.eye_rays, eye_ndc(at, vec2(p.frame.xy))));
}

// Local lighting seen along a primary ray, and 1 where it meets a surface: black and 0 where it
// misses.
vec4 local_radiance(vec3 dir) {
    RayHit hit = bvh_closest_hit(p.camera_pos.xyz, dir, REFERENCE_FAR);
    return hit.instance == KAGE_NO_HIT ? vec4(0.0) : vec4(local_lighting(bvh_surface(hit, dir)), 1.0);
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    uint width = p.frame.x, height = p.frame.y;
    if (pixel.x >= width || pixel.y >= height) return;
    uint index = pixel.y * width + pixel.x;
    vec2 centre = vec2(pixel) + 0.5;
    vec3 origin = p.camera_pos.xyz;
    vec3 dir = primary_dir(centre);
    uint before = p.frame.z, count = p.frame.w;

    if (p.params.x == 1u) {
        // Deterministic: one sample is the value. The rasterizer places vertices to
        // 1 / 2^params.w px, so the pixel is also seen from that far to each side.
        vec4 value = local_radiance(dir);
        float step = 1.0 / float(1u << p.params.w);
        float lowest = luminance(value.rgb), highest = lowest;
        for (uint k = 0u; k < 4u; ++k) {
            vec2 offset = vec2[4](vec2(1, 0), vec2(-1, 0), vec2(0, 1), vec2(0, -1))[k] * step;
            float l = luminance(local_radiance(primary_dir(centre + offset)).rgb);
            lowest = min(lowest, l);
            highest = max(highest, l);
        }
        accum[index] = ReferenceAccum(vec4(value.rgb, lowest), vec4(value.a, 0.0, 0.0, highest));
        return;
    }
    RayHit hit = bvh_closest_hit(origin, dir, REFERENCE_FAR);
    if (hit.instance == KAGE_NO_HIT) {
        // Deterministic: every sample would be the same value.
        accum[index] = ReferenceAccum(vec4(textureLod(env, env_dir_to_uv(dir), 0.0).rgb, 0.0), vec4(0.0));
        return;
    }

    SurfacePoint s = bvh_surface(hit, dir);
    vec3 mean = vec3(0.0), m2 = vec3(0.0);
    for (uint k = 0u; k < count; ++k) {
        Rng rng = rng_init(p.params.z, index, before + k);
        vec3 x = s.albedo / REFERENCE_PI
            * env_irradiance_sample(s.position, s.shading_normal, s.geometric_normal,
                                    p.camera_pos.w, rng);
        vec3 delta = x - mean;
        mean += delta / float(k + 1u);
        m2 += delta * (x - mean);
    }
    accum_merge(index, before, count, mean, m2);
}
