#version 460
// Casts a list of rays through the scene BVH, one per invocation, and writes what each hit:
// the ray caster behind the BVH tests and `kage bench rays`.
#include "constants.glsl"
#include "layouts.glsl"
#include "bvh.glsl"

layout(local_size_x = KAGE_RAYCAST_GROUP) in;
layout(set = 0, binding = KAGE_BVH_BINDINGS, std430) readonly buffer Rays { CastRay rays[]; };
layout(set = 0, binding = KAGE_BVH_BINDINGS + 1, std430) writeonly buffer Results {
    CastResult results[];
};
layout(push_constant) uniform Push { CastPush p; };

const uint QUERY_CLOSEST = 0u;
const uint QUERY_OCCLUDED = 1u;
const uint QUERY_OCCLUDED_OBJECT_SPACE = 2u;
const uint QUERY_SURFACE = 3u;
const uint QUERY_PACKET_OBJECT_SPACE = 4u;
// The packet query's pipeline: a specialization, because a CPU driver would otherwise run its
// code, masked off, beside every single ray's (both sides of a branch run there).
layout(constant_id = 0) const bool PACKETS = false;

// Rays first .. first + KAGE_BVH_PACKET - 1 (those in the list) as one packet from the first
// one's origin through group p.params.z, in its object space: bvh_closest_hits_packet.
void cast_packet(uint first) {
    vec3 dirs[KAGE_BVH_PACKET];
    RayHit hits[KAGE_BVH_PACKET];
    uint in_list = 0u;
    for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
        uint i = min(first + uint(r), p.params.x - 1u);
        dirs[r] = rays[i].direction.xyz;
        bool listed = first + uint(r) < p.params.x;
        // A negative tmax: the packet does not cast it.
        hits[r] = RayHit(listed ? rays[i].origin.w : -1.0, KAGE_NO_HIT, 0u, vec2(0.0));
        if (listed) in_list |= 1u << r;
    }
    bvh_closest_hits_packet(p.params.z, rays[first].origin.xyz, dirs, hits);
    for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
        if ((in_list & (1u << r)) == 0u) continue;
        results[first + uint(r)].hit = vec4(hits[r].t, hits[r].barycentric, 0.0);
        results[first + uint(r)].ids = uvec4(hits[r].instance, hits[r].triangle, 0u, 0u);
    }
}

void main() {
    uint i = p.params.w + gl_GlobalInvocationID.x;
    if (i >= p.params.x) return;
    if (PACKETS) {
        if (i % KAGE_BVH_PACKET == 0u) cast_packet(i);
        return;
    }
    CastRay ray = rays[i];
    vec3 origin = ray.origin.xyz;
    vec3 dir = ray.direction.xyz;
    float tmax = ray.origin.w;
    uint query = p.params.y;
    if (query == QUERY_OCCLUDED || query == QUERY_OCCLUDED_OBJECT_SPACE) {
        bool occluded = query == QUERY_OCCLUDED
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
    if (query == QUERY_SURFACE && hit.instance != KAGE_NO_HIT) {
        SurfacePoint s = bvh_surface(hit, dir);
        results[i].position = vec4(s.position, 0.0);
        results[i].geometric_normal = vec4(s.geometric_normal, 0.0);
        results[i].shading_normal = vec4(s.shading_normal, 0.0);
        results[i].albedo = vec4(s.albedo, 0.0);
    }
}
