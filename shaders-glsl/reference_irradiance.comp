#version 460
// The reference's irradiance mode: E(p, n) = integral of L V max(dot(n, w), 0) dw at listed
// points, one invocation per point, `params.z` samples per batch added to its statistics.
// L is the environment (MIS, reference.glsl) and the scene's point and spot lights (one shadow
// ray each), and, with `transport.y`, the light the surfaces reflect: one cosine-weighted ray
// per sample whose closest hit radiates the per-vertex radiance `radiance[]` interpolated with
// the hit's barycentrics, on the side its winding faces (black behind). Light probes compute
// that radiance at every vertex with this same shader (techniques/probes/transport.rs), so a
// probe's capture and this reference integrate the same surfaces.
// Shadow rays leave from p offset along n; the point's own surface is whatever the scene holds
// there.
#include "constants.glsl"
#include "layouts.glsl"
layout(push_constant) uniform Push { IrradiancePush p; };
// transport.z 0: every ray a miss, to time all but the traversal (IrradianceReference::untraced_seconds).
#define KAGE_BVH_TRACE (p.transport.z != 0u)
#include "bvh.glsl"
#include "reference.glsl"
#include "local_light.glsl"

layout(local_size_x = KAGE_IRRADIANCE_GROUP) in;
layout(set = 0, binding = KAGE_BVH_BINDINGS + 3, std430) readonly buffer Points {
    IrradiancePoint points[];
};
layout(set = 0, binding = KAGE_BVH_BINDINGS + 4, std430) readonly buffer Lights {
    ReferenceLight lights[];
};
// Per scene vertex (scene order: groups, meshes, vertices): outgoing radiance, rgb.
layout(set = 0, binding = KAGE_BVH_BINDINGS + 5, std430) readonly buffer Radiance { vec4 radiance[]; };
// Per BVH triangle: the scene vertex indices of its v0, v1, v2.
layout(set = 0, binding = KAGE_BVH_BINDINGS + 6, std430) readonly buffer TriangleVertices {
    uvec4 triangle_vertices[];
};
// The rays the invocations traced, added up (a u32 that wraps: the host reads it after every
// batch, which traces far fewer than 2^32).
layout(set = 0, binding = KAGE_BVH_BINDINGS + 7, std430) buffer RaysTraced { uint rays_traced; };

// One cosine-weighted sample of the irradiance from the surfaces' radiance: L cos / pdf = L pi.
vec3 surface_irradiance_sample(vec3 position, vec3 n, inout Rng rng) {
    vec3 dir = sample_cosine(n, vec2(rng_next(rng), rng_next(rng)));
    RayHit hit = bvh_closest_hit(offset_ray_origin(position, n), dir, REFERENCE_FAR);
    if (hit.instance == KAGE_NO_HIT) return vec3(0.0);
    BvhTriangle v = bvh_triangle(hit.triangle);
    vec3 face = mat3(bvh_object_to_world(hit.instance))
        * cross(v.v1.xyz - v.v0.xyz, v.v2.xyz - v.v0.xyz);
    if (dot(face, dir) >= 0.0) return vec3(0.0);
    uvec4 ids = triangle_vertices[hit.triangle];
    vec3 w = vec3(1.0 - hit.barycentric.x - hit.barycentric.y, hit.barycentric);
    vec3 l = w.x * radiance[ids.x].rgb + w.y * radiance[ids.y].rgb + w.z * radiance[ids.z].rgb;
    // The vertices' radiance holds the mesh's albedo; its albedo map multiplies it at the hit.
    return l * bvh_hit_texel(hit) * REFERENCE_PI;
}

void main() {
    uint index = gl_GlobalInvocationID.x;
    if (index >= p.params.x) return;
    vec3 position = points[index].position.xyz;
    vec3 n = points[index].normal.xyz;
    uint before = p.params.y, count = p.params.z;
    vec3 local = vec3(0.0);
    for (uint k = 0u; k < p.transport.x; ++k) {
        local += local_light_shadowed(lights[k], position, n, n);
    }
    vec3 mean = vec3(0.0), m2 = vec3(0.0);
    for (uint k = 0u; k < count; ++k) {
        Rng rng = rng_init(p.params.w, index, before + k);
        vec3 x = local + env_irradiance_sample(position, n, n, p.env.x, rng);
        if (p.transport.y == 1u) x += surface_irradiance_sample(position, n, rng);
        vec3 delta = x - mean;
        mean += delta / float(k + 1u);
        m2 += delta * (x - mean);
    }
    accum_merge(index, before, count, mean, m2);
    atomicAdd(rays_traced, bvh_rays_traced);
}
