#version 460
// Casts a list of rays through the scene BVH, one per invocation, and writes what each hit:
// the ray caster behind the BVH tests and `kage bench rays`.
#include "constants.glsl"
#include "layouts.glsl"
#include "bvh.glsl"

layout(local_size_x = KAGE_RAYCAST_GROUP) in;
// The rays as texels, two per CastRay (origin, direction): a texel fetch is a gather on a CPU
// driver, where a storage buffer is read one lane and word at a time (bvh.glsl).
layout(set = 0, binding = KAGE_BVH_BINDINGS) uniform usamplerBuffer ray_texels;
layout(set = 0, binding = KAGE_BVH_BINDINGS + 1, std430) writeonly buffer Results {
    CastResult results[];
};
layout(push_constant) uniform Push { CastPush p; };

CastRay ray_at(uint i) {
    return CastRay(uintBitsToFloat(texelFetch(ray_texels, 2 * int(i))),
                   uintBitsToFloat(texelFetch(ray_texels, 2 * int(i) + 1)));
}

// The query (KAGE_CAST_*): a specialization, one pipeline per query, because a CPU driver runs
// both sides of every branch under a lane mask, so the code of the queries not asked would run,
// masked off, beside the one asked (on llvmpipe that cost more than the traversal itself).
layout(constant_id = 0) const uint QUERY = KAGE_CAST_CLOSEST;

// Rays first .. first + KAGE_BVH_PACKET - 1 (those in the list) as one packet from the first
// one's origin through group p.params.z, in its object space: bvh_closest_hits_packet.
void cast_packet(uint first) {
    vec3 dirs[KAGE_BVH_PACKET];
    RayHit hits[KAGE_BVH_PACKET];
    uint in_list = 0u;
    for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
        CastRay ray = ray_at(min(first + uint(r), p.params.x - 1u));
        dirs[r] = ray.direction.xyz;
        bool listed = first + uint(r) < p.params.x;
        // A negative tmax: the packet does not cast it.
        hits[r] = RayHit(listed ? ray.origin.w : -1.0, KAGE_NO_HIT, 0u, vec2(0.0));
        if (listed) in_list |= 1u << r;
    }
    bvh_closest_hits_packet(p.params.z, ray_at(first).origin.xyz, dirs, hits);
    for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
        if ((in_list & (1u << r)) == 0u) continue;
        results[first + uint(r)].hit = vec4(hits[r].t, hits[r].barycentric, 0.0);
        results[first + uint(r)].ids = uvec4(hits[r].instance, hits[r].triangle, 0u, 0u);
    }
}

void main() {
    uint i = p.params.w + gl_GlobalInvocationID.x;
    if (i >= p.params.x) return;
    if (QUERY == KAGE_CAST_PACKET_OBJECT_SPACE) {
        if (i % KAGE_BVH_PACKET == 0u) cast_packet(i);
        return;
    }
    CastRay ray = ray_at(i);
    vec3 origin = ray.origin.xyz;
    vec3 dir = ray.direction.xyz;
    float tmax = ray.origin.w;
    if (QUERY == KAGE_CAST_OCCLUDED || QUERY == KAGE_CAST_OCCLUDED_OBJECT_SPACE) {
        bool occluded = QUERY == KAGE_CAST_OCCLUDED
                      ? bvh_occluded(origin, dir, tmax)
                      : bvh_occluded_object_space(p.params.z, origin, dir, tmax);
        // An any-hit query says only whether, not where: instance 0 stands for "occluded".
        results[i].ids = uvec4(occluded ? 0u : KAGE_NO_HIT, 0u, 0u, 0u);
        return;
    }
    RayHit hit = bvh_closest_hit(origin, dir, tmax);
    results[i].hit = vec4(hit.t, hit.barycentric, 0.0);
    results[i].ids = uvec4(hit.instance, hit.triangle, 0u, 0u);
    // Only surface queries pay for the surface and its 64 bytes of output.
    if (QUERY == KAGE_CAST_SURFACE && hit.instance != KAGE_NO_HIT) {
        SurfacePoint s = bvh_surface(hit, dir);
        results[i].position = vec4(s.position, 0.0);
        results[i].geometric_normal = vec4(s.geometric_normal, 0.0);
        results[i].shading_normal = vec4(s.shading_normal, 0.0);
        results[i].albedo = vec4(s.albedo, 0.0);
    }
}
