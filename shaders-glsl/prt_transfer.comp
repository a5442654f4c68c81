#version 460
// PRT transfer vectors (engine/src/techniques/prt): estimates, per vertex,
// T_i = ∫ (1/π) v_s(ω) max(ω·n, 0) y_i(ω) dω from cosine-weighted directions, for which the
// estimator is the mean of v_s(ω_k) y_i(ω_k). The directions are a Hammersley point set
// (k/N, radical inverse of k) shifted per vertex by a hashed Cranley–Patterson rotation: the
// unshadowed error falls about as 1/N, and neighbouring vertices do not share one pattern of
// error. Visibility is tested against the vertex's own group, in its object space, or against
// the whole scene as it stands (the ray taken to world space; the basis stays in object space).
//
// KAGE_PRT_LANES invocations share a vertex, and cast its rays in an order that keeps them
// coherent (`hammersley_index`): each invocation traces the KAGE_BVH_PACKET rays of one cell
// of the point set (neighbouring directions from one point) together, reading each BVH node
// once for all of them (`bvh_closest_hits_packet`), and the lanes side by side take
// neighbouring cells, so the SIMD lanes of a CPU driver, or a GPU's, walk nearly the same
// nodes. Each lane sums its own rays; the vertex's first lane adds the lanes' sums, in lane
// order, to the vertex's running sums.
//
// One dispatch casts rays [first, first + count) of every vertex in its range and adds their
// sums to the vertex's running sums (the first dispatch stores), so one invocation never loops
// long: llvmpipe (Mesa 22.3) ends every loop of an invocation, silently, once all its loops
// together have run 65,535 iterations (its loop limiter), which per-ray BVH traversals reached
// after 1,728 rays from the vertices of a 62-vertex sphere.
// `rays_cast` counts the rays each vertex really got, so that the host can prove no loop was cut.
//
// `back_hits` counts the rays whose closest hit is the back of a surface (its interpolated
// normal facing along the ray): a vertex whose rays nearly all end so lies inside a closed
// part of the mesh (a teapot's spout inside its body), and the host fills its transfer from its
// neighbours (engine/src/prt/buried.rs). Hence closest hits, not any hit, for the visibility.
#include "constants.glsl"
#include "layouts.glsl"
#include "sh.glsl"
#include "bvh.glsl"

layout(local_size_x = KAGE_PRT_GROUP) in;
layout(set = 0, binding = KAGE_BVH_BINDINGS, std430) readonly buffer Vertices { PrtVertex vertices[]; };
layout(set = 0, binding = KAGE_BVH_BINDINGS + 1, std430) buffer Transfer { float transfer[]; };
layout(set = 0, binding = KAGE_BVH_BINDINGS + 2, std430) buffer RaysCast { uint rays_cast[]; };
layout(set = 0, binding = KAGE_BVH_BINDINGS + 3, std430) buffer BackHits { uint back_hits[]; };
layout(push_constant) uniform Push { PrtTransferPush p; };
// Coefficients per vertex (bands²): the sums and basis functions past it are compiled out.
layout(constant_id = 0) const uint COEFFS = 25u;
// False: every ray is taken as a miss without tracing it, which times everything but the
// traversal (engine/src/prt/transfer.rs reports the split).
layout(constant_id = 1) const bool TRACE = true;
// True: visibility against the whole scene as it stands (each ray taken to world space and
// traced alone through both levels); false: against the vertex's own group, in its object
// space, KAGE_BVH_PACKET rays of one Hammersley cell traced together.
layout(constant_id = 2) const bool WHOLE_SCENE = false;

// Each lane's sums (7 vec4s hold 25 coefficients), rays cast and back hits, for its vertex's
// first lane to add up.
shared vec4 lane_sums[KAGE_PRT_GROUP][7];
shared uvec2 lane_counts[KAGE_PRT_GROUP];

// PCG output permutation (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering").
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// An orthonormal basis around unit n without a branch on its direction (Duff et al. 2017).
void tangent_frame(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// The Hammersley index k of a vertex's j-th ray, a permutation of 0 .. rays - 1 (the estimator
// sums the same points in another order). With P = KAGE_BVH_PACKET = 2^b and rays = 2^m
// (m ≥ b), k's bits are [A | c | D]: c = j mod P (the ray within its packet), A (h bits) and D
// (l = m - b - h bits) from j's cell j / P. The P rays of one (A, D) have k/N within 2^-h of
// each other (band A of the disc's radius) and radical inverses within 2^-l (a sector of its
// angle): the Hammersley set is a (0, m, 2)-net in base 2, so every such elementary interval
// holds exactly P points, and one packet casts them together. The radical inverse reverses D,
// so sector s is D = reverse(s); the cell's lowest bits, which tell the lanes of a vertex apart,
// pick 4 neighbouring sectors (2 bits) by neighbouring bands (the other lane bits), so that the
// SIMD lanes walk nearly the same nodes: on the Stanford bunny, 1.2x faster than cells whose
// lowest bits were D's own (lanes 1/8 of a turn apart). Other counts keep k = j.
uint hammersley_index(uint j, uint rays) {
    // b bits of k pick the point within a cell of KAGE_BVH_PACKET points.
    uint b = uint(findMSB(uint(KAGE_BVH_PACKET)));
    if (rays < uint(KAGE_BVH_PACKET) || (rays & (rays - 1u)) != 0u) return j;
    uint m = uint(findMSB(rays));
    uint h = (m - b) / 2u;
    uint l = m - b - h;
    uint cell = j >> b;
    uint lane_bits = uint(findMSB(uint(KAGE_PRT_LANES)));
    uint sector_bits = min(min(2u, lane_bits), l);
    uint band_bits = min(lane_bits - min(2u, lane_bits), h);
    uint rest = cell >> (sector_bits + band_bits);
    uint sector = (cell & ((1u << sector_bits) - 1u)) | ((rest & ((1u << (l - sector_bits)) - 1u)) << sector_bits);
    uint band = ((cell >> sector_bits) & ((1u << band_bits) - 1u)) | ((rest >> (l - sector_bits)) << band_bits);
    uint d = l == 0u ? 0u : bitfieldReverse(sector) >> (32u - l);
    return (band << (l + b)) | ((j & (uint(KAGE_BVH_PACKET) - 1u)) << l) | d;
}

// The cosine-weighted direction of Hammersley point k of `rays` about n, shifted: a uniform
// point on the unit disc lifted onto the hemisphere.
vec3 ray_direction(uint k, uint rays, vec2 shift, vec3 n, vec3 tangent, vec3 bitangent) {
    const float to_unit = 1.0 / 4294967296.0;
    vec2 u = fract(vec2(float(k) / float(rays), float(bitfieldReverse(k)) * to_unit) + shift);
    float r = sqrt(u.x);
    float phi = 2.0 * KAGE_PI * u.y;
    return normalize(r * cos(phi) * tangent + r * sin(phi) * bitangent + sqrt(max(1.0 - u.x, 0.0)) * n);
}

// Adds sums 4j .. 4j + 3 of a vertex to its running sums (stores them on the first
// dispatch), those below COEFFS; on the last dispatch divides by the ray count.
void add(uint base, uint j, vec4 sums, bool first, float scale) {
    for (uint c = 0u; c < 4u; ++c) {
        uint i = 4u * j + c;
        if (i < COEFFS) {
            float before = first ? 0.0 : transfer[base + i];
            transfer[base + i] = (before + sums[c]) * scale;
        }
    }
}

void main() {
    uint lane = gl_LocalInvocationID.x % KAGE_PRT_LANES;
    uint local = gl_GlobalInvocationID.x / KAGE_PRT_LANES;
    // Every invocation reaches the barrier below; those past the range cast nothing.
    bool casting = local < p.range.y;
    uint vertex = p.range.x + min(local, p.range.y - 1u);
    uint group = p.range.z;
    uint rays = p.range.w;

    vec3 n = normalize(vertices[vertex].normal.xyz);
    vec3 origin = offset_ray_origin(vertices[vertex].position.xyz, n);
    vec3 tangent, bitangent;
    tangent_frame(n, tangent, bitangent);
    vec2 shift = vec2(pcg_hash(2u * vertex), pcg_hash(2u * vertex + 1u)) * (1.0 / 4294967296.0);

    vec4 s0 = vec4(0.0), s1 = vec4(0.0), s2 = vec4(0.0), s3 = vec4(0.0), s4 = vec4(0.0),
         s5 = vec4(0.0), s6 = vec4(0.0);
    mat4 to_world = bvh_object_to_world(group);
    vec3 world_origin = (to_world * vec4(origin, 1.0)).xyz;
    uint first = p.params.x;
    uint end = casting ? first + p.params.y : first;
    uint done = 0u, back = 0u;
    // Each lane casts whole cells (first is a multiple of the packet), the lanes side by side.
    for (uint cell = first / KAGE_BVH_PACKET + lane; cell * KAGE_BVH_PACKET < end; cell += KAGE_PRT_LANES) {
        vec3 dirs[KAGE_BVH_PACKET];
        RayHit hits[KAGE_BVH_PACKET];
        uint cast_rays = 0u;
        for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
            uint j = cell * KAGE_BVH_PACKET + uint(r);
            dirs[r] = ray_direction(hammersley_index(min(j, rays - 1u), rays), rays, shift, n, tangent, bitangent);
            // A negative tmax: the packet does not cast it.
            hits[r] = RayHit(j < end ? 1e30 : -1.0, KAGE_NO_HIT, 0u, vec2(0.0));
            if (j < end) cast_rays |= 1u << r;
        }
        if (TRACE && WHOLE_SCENE) {
            for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
                if ((cast_rays & (1u << r)) != 0u) bvh_traverse(world_origin, normalize(mat3(to_world) * dirs[r]), false, hits[r]);
            }
        } else if (TRACE) {
            bvh_closest_hits_packet(group, origin, dirs, hits);
        }
        for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
            if ((cast_rays & (1u << r)) == 0u) continue;
            RayHit hit = hits[r];
            if (hit.instance != KAGE_NO_HIT) {
                // The hit normal is taken to the space the ray was cast in (the scale is
                // uniform, so the rotation part carries normals).
                BvhTriangleAttributes a = bvh_attributes(hit.triangle);
                vec3 w = vec3(1.0 - hit.barycentric.x - hit.barycentric.y, hit.barycentric);
                vec3 normal = w.x * a.n0.xyz + w.y * a.n1.xyz + w.z * a.n2.xyz;
                vec3 ray_dir = dirs[r];
                if (WHOLE_SCENE) {
                    normal = mat3(bvh_object_to_world(hit.instance)) * normal;
                    ray_dir = mat3(to_world) * ray_dir;
                }
                if (dot(normal, ray_dir) > 0.0) ++back;
            } else {
                vec4 c0, c1, c2, c3, c4, c5, c6;
                sh25_basis(dirs[r], c0, c1, c2, c3, c4, c5, c6);
                s0 += c0;
                if (COEFFS > 4u) { s1 += c1; s2 += c2; }
                if (COEFFS > 12u) { s3 += c3; }
                if (COEFFS > 16u) { s4 += c4; s5 += c5; s6 += c6; }
            }
            ++done;
        }
    }
    uint slot = gl_LocalInvocationID.x;
    lane_sums[slot][0] = s0; lane_sums[slot][1] = s1; lane_sums[slot][2] = s2;
    lane_sums[slot][3] = s3; lane_sums[slot][4] = s4; lane_sums[slot][5] = s5;
    lane_sums[slot][6] = s6;
    lane_counts[slot] = uvec2(done, back);
    barrier();
    if (!casting || lane != 0u) return;
    for (uint other = 1u; other < KAGE_PRT_LANES; ++other) {
        s0 += lane_sums[slot + other][0]; s1 += lane_sums[slot + other][1];
        s2 += lane_sums[slot + other][2]; s3 += lane_sums[slot + other][3];
        s4 += lane_sums[slot + other][4]; s5 += lane_sums[slot + other][5];
        s6 += lane_sums[slot + other][6];
        done += lane_counts[slot + other].x;
        back += lane_counts[slot + other].y;
    }
    bool first_dispatch = first == 0u;
    // The last dispatch turns the sums into means.
    float scale = first + p.params.y == rays ? 1.0 / float(rays) : 1.0;
    uint base = vertex * COEFFS;
    add(base, 0u, s0, first_dispatch, scale);
    add(base, 1u, s1, first_dispatch, scale);
    add(base, 2u, s2, first_dispatch, scale);
    add(base, 3u, s3, first_dispatch, scale);
    add(base, 4u, s4, first_dispatch, scale);
    add(base, 5u, s5, first_dispatch, scale);
    add(base, 6u, s6, first_dispatch, scale);
    rays_cast[vertex] = (first_dispatch ? 0u : rays_cast[vertex]) + done;
    back_hits[vertex] = (first_dispatch ? 0u : back_hits[vertex]) + back;
}
