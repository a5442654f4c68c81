#version 460
// The ground truth: direct lighting of the diffuse scene with full visibility, one invocation
// per pixel, one primary ray through the pixel centre (the rasterizer has no antialiasing
// either). Environment mode adds `frame.w` Monte Carlo samples of the reflected radiance
// albedo / pi * E (see reference.glsl) to each pixel's statistics; a ray that misses shows the
// environment bilinearly filtered, as the raster background does. Local mode is deterministic:
// point and spot lights with hard shadows, one shadow ray each, black background.
#include "constants.glsl"
#include "layouts.glsl"
#include "bvh.glsl"
#include "reference.glsl"
#include "local_light.glsl"

layout(local_size_x = KAGE_REFERENCE_GROUP, local_size_y = KAGE_REFERENCE_GROUP) in;
layout(set = 0, binding = KAGE_BVH_BINDINGS + 4, std430) readonly buffer Lights {
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

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    uint width = p.frame.x, height = p.frame.y;
    if (pixel.x >= width || pixel.y >= height) return;
    uint index = pixel.y * width + pixel.x;
    // Row 0 at the top is NDC y = -1, as in the rasterizer's framebuffer.
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(width, height) * 2.0 - 1.0;
    vec4 far = p.inv_view_proj * vec4(ndc, 0.5, 1.0);
    vec3 origin = p.camera_pos.xyz;
    vec3 dir = normalize(far.xyz / far.w - origin);
    bool local = p.params.x == 1u;
    uint before = p.frame.z, count = p.frame.w;

    RayHit hit = bvh_closest_hit(origin, dir, REFERENCE_FAR);
    if (hit.instance == KAGE_NO_HIT || local) {
        // Deterministic: every sample would be the same value.
        vec3 value = vec3(0.0);
        if (hit.instance != KAGE_NO_HIT) {
            value = local_lighting(bvh_surface(hit, dir));
        } else if (!local) {
            value = textureLod(env, env_dir_to_uv(dir), 0.0).rgb;
        }
        accum[index] = ReferenceAccum(vec4(value, 0.0), vec4(0.0));
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
