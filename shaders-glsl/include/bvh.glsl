// Ray casting against the scene BVH built by engine/src/raycast (see its module doc for the
// node layout). Two levels: a top-level tree over the instances (world space) and one
// bottom-level tree per scene group (object space). Rays enter an instance through its
// world_to_object matrix without renormalising the direction, so the ray parameter t is the
// same in both spaces and every t returned is a world-space distance along a unit ray.
//
// Declares storage buffers at set 0, bindings 0 .. KAGE_BVH_BINDINGS - 1.
#ifndef KAGE_BVH_GLSL
#define KAGE_BVH_GLSL

#include "constants.glsl"
#include "layouts.glsl"

// What the traversal reads (pairs, top-level nodes, instances, triangles) and what every hit
// reads (the triangles' attributes) are texel buffers of uvec4s, read through the accessors
// below: llvmpipe gathers a texel fetch over the SIMD lanes without branching, where it reads
// a storage buffer one lane and word at a time (vendor-notes.md). The albedo maps, which only
// a textured hit reads, stay in storage buffers.
layout(set = 0, binding = 0) uniform usamplerBuffer bvh_blas_pairs;
layout(set = 0, binding = 1) uniform usamplerBuffer bvh_tlas_nodes;
layout(set = 0, binding = 2) uniform usamplerBuffer bvh_instances;
layout(set = 0, binding = 3) uniform usamplerBuffer bvh_triangles;
layout(set = 0, binding = 4) uniform usamplerBuffer bvh_attribute_texels;
// The scene's albedo maps (entry 0 unused: a triangle without a map) and their texels, RGBA8
// sRGB packed little-endian, row after row from the top.
layout(set = 0, binding = 5, std430) readonly buffer BvhAlbedoMaps { BvhAlbedoMap bvh_albedo_maps[]; };
layout(set = 0, binding = 6, std430) readonly buffer BvhAlbedoTexels { BvhTexel bvh_albedo_texels[]; };

// Pair `index` of the bottom-level trees.
BvhPair bvh_pair(uint index) {
    int texel = KAGE_BVH_PAIR_TEXELS * int(index);
    return BvhPair(texelFetch(bvh_blas_pairs, texel), texelFetch(bvh_blas_pairs, texel + 1));
}

// Where a pair's left and right child lead.
uint bvh_pair_left(BvhPair pair) { return pair.origin.w; }
uint bvh_pair_right(BvhPair pair) { return pair.boxes.w; }

// Node `index` of the top-level tree.
BvhNode bvh_tlas_node(uint index) {
    int texel = KAGE_BVH_NODE_TEXELS * int(index);
    return BvhNode(uintBitsToFloat(texelFetch(bvh_tlas_nodes, texel)),
                   uintBitsToFloat(texelFetch(bvh_tlas_nodes, texel + 1)));
}

// The matrix of instance `index` that starts at texel `first` of its record (0: object to
// world, 4: world to object), and its info.
mat4 bvh_instance_matrix(uint index, int first) {
    int texel = KAGE_BVH_INSTANCE_TEXELS * int(index) + first;
    return mat4(uintBitsToFloat(texelFetch(bvh_instances, texel)), uintBitsToFloat(texelFetch(bvh_instances, texel + 1)),
                uintBitsToFloat(texelFetch(bvh_instances, texel + 2)), uintBitsToFloat(texelFetch(bvh_instances, texel + 3)));
}
mat4 bvh_object_to_world(uint index) { return bvh_instance_matrix(index, 0); }
mat4 bvh_world_to_object(uint index) { return bvh_instance_matrix(index, 4); }
uvec4 bvh_instance_info(uint index) { return texelFetch(bvh_instances, KAGE_BVH_INSTANCE_TEXELS * int(index) + 8); }

// Triangle `index` of the triangle buffer.
BvhTriangle bvh_triangle(uint index) {
    int texel = KAGE_BVH_TRIANGLE_TEXELS * int(index);
    return BvhTriangle(uintBitsToFloat(texelFetch(bvh_triangles, texel)),
                       uintBitsToFloat(texelFetch(bvh_triangles, texel + 1)),
                       uintBitsToFloat(texelFetch(bvh_triangles, texel + 2)));
}

// The attributes of triangle `index` of the triangle buffer.
BvhTriangleAttributes bvh_attributes(uint index) {
    int texel = KAGE_BVH_ATTRIBUTE_TEXELS * int(index);
    return BvhTriangleAttributes(
        uintBitsToFloat(texelFetch(bvh_attribute_texels, texel)), uintBitsToFloat(texelFetch(bvh_attribute_texels, texel + 1)),
        uintBitsToFloat(texelFetch(bvh_attribute_texels, texel + 2)), uintBitsToFloat(texelFetch(bvh_attribute_texels, texel + 3)),
        uintBitsToFloat(texelFetch(bvh_attribute_texels, texel + 4)), uintBitsToFloat(texelFetch(bvh_attribute_texels, texel + 5)));
}

// instance == KAGE_NO_HIT on a miss; triangle indexes the BVH triangle buffer; barycentric holds
// the weights of the triangle's v1 and v2 (v0's is 1 - x - y).
struct RayHit {
    float t;
    uint instance;
    uint triangle;
    vec2 barycentric;
};

struct SurfacePoint {
    vec3 position;
    vec3 geometric_normal;
    vec3 shading_normal;
    vec3 albedo;
};

// The per-ray set-up of the watertight test (Woop, Benthin, Wald 2013): the axis kz where the
// direction is largest, and the shear that maps the ray onto +kz.
struct WatertightRay {
    vec3 origin;
    ivec3 k; // kx, ky, kz
    vec3 shear; // Sx, Sy, Sz
};

WatertightRay bvh_watertight_ray(vec3 origin, vec3 dir) {
    vec3 a = abs(dir);
    int kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    // Keeps the triangle's winding as seen along the ray, so the sign tests below stay valid.
    if (dir[kz] < 0.0) {
        int swap = kx;
        kx = ky;
        ky = swap;
    }
    return WatertightRay(origin, ivec3(kx, ky, kz),
                         vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]));
}

// Whether edge functions u, w1 and w2 put a ray inside a triangle: none of them of another sign
// than the others, a value of exactly zero counting as inside.
bool bvh_edges_inside(float u, float w1, float w2) {
    return !((u < 0.0 || w1 < 0.0 || w2 < 0.0) && (u > 0.0 || w1 > 0.0 || w2 > 0.0));
}

// Whether t = tt / denominator lies in (0, tmax), tested without the division and for either
// sign of the denominator (none for zero).
bool bvh_t_in_range(float tt, float denominator, float tmax) {
    return denominator > 0.0 ? (tt > 0.0 && tt < tmax * denominator) : (tt < 0.0 && tt > tmax * denominator);
}

// Hit with t in (0, tmax): returns t and the weights of v1 and v2. `precise` forbids fused
// multiply-adds, so that an edge shared by two triangles gets bit-identical (negated) edge
// functions in both and no ray slips between them. Edge functions of exactly zero count as
// inside, so a ray exactly through a shared edge hits both triangles rather than neither.
bool bvh_intersect(WatertightRay r, BvhTriangle v, float tmax, out float t, out vec2 bary) {
    precise vec3 a = v.v0.xyz - r.origin;
    precise vec3 b = v.v1.xyz - r.origin;
    precise vec3 c = v.v2.xyz - r.origin;
    precise float ax = a[r.k.x] - r.shear.x * a[r.k.z];
    precise float ay = a[r.k.y] - r.shear.y * a[r.k.z];
    precise float bx = b[r.k.x] - r.shear.x * b[r.k.z];
    precise float by = b[r.k.y] - r.shear.y * b[r.k.z];
    precise float cx = c[r.k.x] - r.shear.x * c[r.k.z];
    precise float cy = c[r.k.y] - r.shear.y * c[r.k.z];
    precise float u = cx * by - cy * bx;
    precise float w1 = ax * cy - ay * cx;
    precise float w2 = bx * ay - by * ax;
    if (!bvh_edges_inside(u, w1, w2)) return false;
    precise float det = u + w1 + w2;
    if (det == 0.0) return false;
    precise float tt = u * (r.shear.z * a[r.k.z]) + w1 * (r.shear.z * b[r.k.z])
                     + w2 * (r.shear.z * c[r.k.z]);
    if (!bvh_t_in_range(tt, det, tmax)) return false;
    float inv = 1.0 / det;
    t = tt * inv;
    bary = vec2(w1, w2) * inv;
    return t > 0.0 && t < tmax;
}

// The half of a ray–triangle test that rays from one origin share: the triangle's corners
// relative to the origin span three planes through it, one per edge, and a ray from there
// crosses the triangle where its direction lies on the inner side of all three (the Plücker
// form of the edge test). Each plane's normal is the cross product of its edge's corners,
// which a neighbour sharing the edge computes from the same two differences with the factors
// swapped: exactly the negation under `precise`, so the test stays watertight as Woop's is.
// The distance comes from the triangle's plane, its normal from the triangle's own edges and
// the origin's height over it, so its rounding does not grow with the corners' distance from
// the origin as the triple product of the three would.
struct BvhFan {
    vec3 edge0; // opposite v0: its weight
    vec3 edge1;
    vec3 edge2;
    vec3 normal;
    float height;
};

// x × y with each component the difference of two rounded products: `precise` reaches no
// further than the function it is declared in, and a fused multiply-add would round x × y and
// y × x differently.
vec3 bvh_cross_unfused(vec3 x, vec3 y) {
    precise vec3 product = vec3(x.y * y.z - x.z * y.y, x.z * y.x - x.x * y.z, x.x * y.y - x.y * y.x);
    return product;
}

BvhFan bvh_fan(BvhTriangle v, vec3 origin) {
    precise vec3 a = v.v0.xyz - origin;
    precise vec3 b = v.v1.xyz - origin;
    precise vec3 c = v.v2.xyz - origin;
    vec3 normal = cross(v.v1.xyz - v.v0.xyz, v.v2.xyz - v.v0.xyz);
    return BvhFan(bvh_cross_unfused(b, c), bvh_cross_unfused(c, a), bvh_cross_unfused(a, b), normal, dot(a, normal));
}

// The per-ray half: as bvh_intersect, for a ray from the fan's origin (dir of any length, t
// in its units), three dot products a ray where Woop's shears the three corners.
bool bvh_intersect_fan(BvhFan f, vec3 dir, float tmax, out float t, out vec2 bary) {
    precise float u = dot(dir, f.edge0);
    precise float w1 = dot(dir, f.edge1);
    precise float w2 = dot(dir, f.edge2);
    if (!bvh_edges_inside(u, w1, w2)) return false;
    precise float det = u + w1 + w2;
    if (det == 0.0) return false;
    // t = height / dot(dir, normal); the weights divide by det, so that they sum to one.
    float slope = dot(dir, f.normal);
    if (!bvh_t_in_range(f.height, slope, tmax)) return false;
    t = f.height / slope;
    bary = vec2(w1, w2) / det;
    return t > 0.0 && t < tmax;
}

// The same against triangle `tri` of the triangle buffer.
bool bvh_intersect_triangle(WatertightRay r, uint tri, float tmax, out float t, out vec2 bary) {
    return bvh_intersect(r, bvh_triangle(tri), tmax, t, bary);
}

// Entry distance of a ray into the box lo .. hi given relative to the ray's origin, or +inf
// when it misses the box or enters at or past tmax. inv_dir may hold infinities (axis-parallel
// rays); max/min discard the NaN of 0 * inf, which happens only for origins exactly on a slab
// plane.
float bvh_enter_from(vec3 lo, vec3 hi, vec3 inv_dir, float tmax) {
    vec3 t0 = lo * inv_dir;
    vec3 t1 = hi * inv_dir;
    vec3 near = min(t0, t1);
    vec3 far = max(t0, t1);
    float enter = max(max(near.x, near.y), max(near.z, 0.0));
    float leave = min(min(far.x, far.y), min(far.z, tmax));
    return enter <= leave ? enter : 1.0 / 0.0;
}

// The same for a box in the ray's space.
float bvh_enter(vec3 lo, vec3 hi, vec3 origin, vec3 inv_dir, float tmax) {
    return bvh_enter_from(lo - origin, hi - origin, inv_dir, tmax);
}

float bvh_enter_box(BvhNode node, vec3 origin, vec3 inv_dir, float tmax) {
    return bvh_enter(node.lo.xyz, node.hi.xyz, origin, inv_dir, tmax);
}

uint bvh_node_index(BvhNode node) { return floatBitsToUint(node.lo.w); }
uint bvh_node_count(BvhNode node) { return floatBitsToUint(node.hi.w); }

// Of two children entered at these distances (+inf: not entered), how many are entered (0, 1
// or 2) and whether to visit the left one first: the nearer, so that a hit in it shrinks tmax
// and prunes the other.
int bvh_order(float enter_left, float enter_right, out bool left_first) {
    bool left = enter_left != 1.0 / 0.0;
    bool right = enter_right != 1.0 / 0.0;
    left_first = left && (!right || enter_left <= enter_right);
    return int(left) + int(right);
}

// A pair's children as bvh_order takes them: entered at these distances and present.
int bvh_pair_order(BvhPair pair, float enter_left, float enter_right, out bool left_first) {
    return bvh_order(bvh_pair_left(pair) != KAGE_NO_HIT ? enter_left : 1.0 / 0.0,
                     bvh_pair_right(pair) != KAGE_NO_HIT ? enter_right : 1.0 / 0.0, left_first);
}

// The triangles of a child reference: none for a pair, count and first for a leaf.
uint bvh_leaf_count(uint ref) { return (ref & KAGE_BVH_LEAF) != 0u ? (ref >> 28) & 7u : 0u; }
uint bvh_leaf_first(uint ref) { return ref & 0x0fffffffu; }

// The children of inner node `index` (at index and index + 1) that the ray enters before
// `tmax`: how many (0, 1 or 2); `next`, the one to visit now (the nearer of two, so that tmax
// shrinks early and prunes the farther one); `pushed` and `pushed_enter`, the other one's index
// and entry distance when both.
int bvh_children(BvhNode left_node, BvhNode right_node, uint index, vec3 origin, vec3 inv_dir, float tmax,
                 inout BvhNode next, out uint pushed, out float pushed_enter) {
    bool left_first;
    float enter_left = bvh_enter_box(left_node, origin, inv_dir, tmax);
    float enter_right = bvh_enter_box(right_node, origin, inv_dir, tmax);
    int entered = bvh_order(enter_left, enter_right, left_first);
    pushed = left_first ? index + 1u : index;
    pushed_enter = left_first ? enter_right : enter_left;
    if (entered > 0) next = left_first ? left_node : right_node;
    return entered;
}

// Corner c of a pair's children (0, 1: the left child's minimum and maximum, 2, 3: the
// right child's), byte c of each axis's word of grid steps from the pair's origin. q * step is
// exact, so the one rounding of the sum is the one the builder checked
// (engine/src/raycast/pairs.rs).
vec3 bvh_pair_corner(vec3 origin, vec3 step, uvec3 steps, int c) {
    return origin + vec3((steps >> (8 * c)) & 0xffu) * step;
}

void bvh_pair_boxes(BvhPair pair, out vec3 left_lo, out vec3 left_hi, out vec3 right_lo, out vec3 right_hi) {
    vec3 origin = uintBitsToFloat(pair.origin.xyz & 0xffffff00u);
    vec3 step = uintBitsToFloat((pair.origin.xyz & 0xffu) << 23);
    left_lo = bvh_pair_corner(origin, step, pair.boxes.xyz, 0);
    left_hi = bvh_pair_corner(origin, step, pair.boxes.xyz, 1);
    right_lo = bvh_pair_corner(origin, step, pair.boxes.xyz, 2);
    right_hi = bvh_pair_corner(origin, step, pair.boxes.xyz, 3);
}

// Traverses one bottom-level tree, ray in object space. With any_hit it returns at the first
// hit found; otherwise it narrows hit.t to the closest one. hit.t is the running tmax.
//
// "While-while" (Aila and Laine 2009): the invocations of a SIMD group run in lockstep, and a
// CPU driver (lavapipe) runs both sides of every branch under a lane mask, so each step kind
// has its own loop that all lanes run together: down through inner nodes until each lane holds
// a leaf or finds no child entered, then the leaves' triangles, then one pop. Measured on the
// Stanford bunny (`kage bench rays`, lavapipe): 1.3-1.4x the rays per second of one loop
// whose every iteration held all three. The stack keeps each entry's entry distance beside its
// index, so a pop skips an entry that a hit found since has moved out of reach without
// fetching its node again.
bool bvh_traverse_blas(uint instance, vec3 origin, vec3 dir, bool any_hit, inout RayHit hit) {
    WatertightRay wray = bvh_watertight_ray(origin, dir);
    vec3 inv_dir = 1.0 / dir;
    bool found = false;
    uint stack[KAGE_BVH_STACK];
    float stack_enter[KAGE_BVH_STACK];
    int top = 0;
    // What the ray visits next: a pair, or a leaf (KAGE_BVH_LEAF set). The root pair's own
    // box is not tested: its children's are.
    uint next = bvh_instance_info(instance).w;
    bool live = true;
    while (live) {
        // Down through pairs while a child is entered.
        while ((next & KAGE_BVH_LEAF) == 0u) {
            BvhPair pair = bvh_pair(next);
            vec3 left_lo, left_hi, right_lo, right_hi;
            bvh_pair_boxes(pair, left_lo, left_hi, right_lo, right_hi);
            float enter_left = bvh_enter(left_lo, left_hi, origin, inv_dir, hit.t);
            float enter_right = bvh_enter(right_lo, right_hi, origin, inv_dir, hit.t);
            bool left_first;
            int entered = bvh_pair_order(pair, enter_left, enter_right, left_first);
            if (entered == 0) break;
            if (entered == 2) {
                stack[top] = left_first ? bvh_pair_right(pair) : bvh_pair_left(pair);
                stack_enter[top] = left_first ? enter_right : enter_left;
                ++top;
            }
            next = left_first ? bvh_pair_left(pair) : bvh_pair_right(pair);
        }
        // A leaf: its triangles, all lanes that hold one together (none where the walk above
        // ended on a pair with no child entered); an any-hit walk stops at its first hit.
        uint count = bvh_leaf_count(next);
        uint first = bvh_leaf_first(next);
        for (uint tri = first; tri < first + count; ++tri) {
            float t;
            vec2 bary;
            if (bvh_intersect_triangle(wray, tri, hit.t, t, bary)) {
                hit = RayHit(t, instance, tri, bary);
                found = true;
                if (any_hit) break;
            }
        }
        if (found && any_hit) return true;
        // Pop the next entry still within reach. An any-hit walk, whose tmax has not moved
        // since the entry was pushed within it, could pop without looking and keep no entry
        // distances, but on llvmpipe that walk ran at 0.57x these rays per second on a Zen 4
        // CPU (1.06x on a Zen 3; BENCHMARKS.md, "Ray casting").
        live = false;
        while (top > 0) {
            --top;
            if (stack_enter[top] < hit.t) {
                next = stack[top];
                live = true;
                break;
            }
        }
    }
    return found;
}

// Closest hits of KAGE_BVH_PACKET rays from one origin through one bottom-level tree, in
// object space (hits[r].t each ray's running tmax; a ray given a negative one is not cast: it
// enters no box and hits no triangle, with no mask to test in the loops below). The
// packet walks the tree once, entering a child where any of its rays does, so each pair and
// triangle is read once for all of them: on a CPU driver a read is a gather over the SIMD
// lanes, the largest cost of a step, and rays from one point in neighbouring directions (the
// PRT's) enter nearly the same nodes. A triangle's edge planes through the origin are shared
// too (bvh_fan), so each ray's test is three dot products: on the Stanford bunny's
// precomputation 1.04-1.22x faster than Woop's test ray by ray.
void bvh_closest_hits_packet(uint instance, vec3 origin, vec3 dirs[KAGE_BVH_PACKET],
                             inout RayHit hits[KAGE_BVH_PACKET]) {
    vec3 inv_dirs[KAGE_BVH_PACKET];
    for (int r = 0; r < KAGE_BVH_PACKET; ++r) inv_dirs[r] = 1.0 / dirs[r];
    uint stack[KAGE_BVH_STACK];
    // The nearest entry of any ray into each stacked child.
    float stack_enter[KAGE_BVH_STACK];
    int top = 0;
    uint next = bvh_instance_info(instance).w;
    bool live = true;
    while (live) {
        while ((next & KAGE_BVH_LEAF) == 0u) {
            BvhPair pair = bvh_pair(next);
            vec3 left_lo, left_hi, right_lo, right_hi;
            bvh_pair_boxes(pair, left_lo, left_hi, right_lo, right_hi);
            // The rays share their origin: the corners relative to it once, as bvh_enter has them.
            left_lo -= origin;
            left_hi -= origin;
            right_lo -= origin;
            right_hi -= origin;
            float enter_left = 1.0 / 0.0, enter_right = 1.0 / 0.0;
            for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
                enter_left = min(enter_left, bvh_enter_from(left_lo, left_hi, inv_dirs[r], hits[r].t));
                enter_right = min(enter_right, bvh_enter_from(right_lo, right_hi, inv_dirs[r], hits[r].t));
            }
            bool left_first;
            int entered = bvh_pair_order(pair, enter_left, enter_right, left_first);
            if (entered == 0) break;
            if (entered == 2) {
                stack[top] = left_first ? bvh_pair_right(pair) : bvh_pair_left(pair);
                stack_enter[top] = left_first ? enter_right : enter_left;
                ++top;
            }
            next = left_first ? bvh_pair_left(pair) : bvh_pair_right(pair);
        }
        uint count = bvh_leaf_count(next);
        uint first = bvh_leaf_first(next);
        for (uint tri = first; tri < first + count; ++tri) {
            BvhFan fan = bvh_fan(bvh_triangle(tri), origin);
            for (int r = 0; r < KAGE_BVH_PACKET; ++r) {
                float t;
                vec2 bary;
                if (bvh_intersect_fan(fan, dirs[r], hits[r].t, t, bary)) {
                    hits[r] = RayHit(t, instance, tri, bary);
                }
            }
        }
        // Pop the next entry some ray still reaches.
        float reach = 0.0;
        for (int r = 0; r < KAGE_BVH_PACKET; ++r) reach = max(reach, hits[r].t);
        live = false;
        while (top > 0) {
            --top;
            if (stack_enter[top] < reach) {
                next = stack[top];
                live = true;
                break;
            }
        }
    }
}

// Traverses the top-level tree (world space) and, at each instance leaf, that instance's tree.
// While-while as bvh_traverse_blas: down through inner nodes in a loop of its own, so that the
// instance's tree, whose code a CPU driver runs masked off on every pass that no lane needs
// it, runs once per instance entered and not also on the passes through inner nodes. The stack
// keeps entry distances as the bottom level's does: a pop tests the distance instead of
// fetching the node and its box again (closest hits 1.13-1.15x the rays per second on the
// Stanford bunny on a Zen 4 CPU, BENCHMARKS.md "Ray casting").
bool bvh_traverse(vec3 origin, vec3 dir, bool any_hit, inout RayHit hit) {
    vec3 inv_dir = 1.0 / dir;
    bool found = false;
    uint stack[KAGE_BVH_STACK];
    float stack_enter[KAGE_BVH_STACK];
    int top = 0;
    BvhNode node = bvh_tlas_node(0u);
    bool live = bvh_enter_box(node, origin, inv_dir, hit.t) != 1.0 / 0.0;
    while (live) {
        // Down through inner nodes while a child is entered.
        while (bvh_node_count(node) == 0u) {
            uint index = bvh_node_index(node);
            uint pushed;
            float pushed_enter;
            int entered = bvh_children(bvh_tlas_node(index), bvh_tlas_node(index + 1u), index, origin, inv_dir,
                                       hit.t, node, pushed, pushed_enter);
            if (entered == 0) break;
            if (entered == 2) {
                stack[top] = pushed;
                stack_enter[top] = pushed_enter;
                ++top;
            }
        }
        // An instance leaf (none where the walk above ended on a node with no child entered).
        if (bvh_node_count(node) > 0u) {
            uint index = bvh_node_index(node);
            mat4 to_object = bvh_world_to_object(index);
            vec3 o = (to_object * vec4(origin, 1.0)).xyz;
            vec3 d = mat3(to_object) * dir;
            if (bvh_traverse_blas(index, o, d, any_hit, hit)) {
                found = true;
                if (any_hit) return true;
            }
        }
        // Pop the next entry still within reach.
        live = false;
        while (top > 0) {
            --top;
            if (stack_enter[top] < hit.t) {
                node = bvh_tlas_node(stack[top]);
                live = true;
                break;
            }
        }
    }
    return found;
}

// The rays this invocation traced through bvh_closest_hit and bvh_occluded: a shader that
// reports its rays adds them up (reference_irradiance.comp); the others leave it unread.
uint bvh_rays_traced = 0u;
// A shader may define KAGE_BVH_TRACE as a condition (a push constant's): false, both take every
// ray as a miss, so that timing it measures everything but the traversal.
#ifndef KAGE_BVH_TRACE
#define KAGE_BVH_TRACE true
#endif

// Closest hit along a unit world-space ray within (0, tmax), over every group.
RayHit bvh_closest_hit(vec3 origin, vec3 dir, float tmax) {
    ++bvh_rays_traced;
    RayHit hit = RayHit(tmax, KAGE_NO_HIT, 0u, vec2(0.0));
    if (KAGE_BVH_TRACE) bvh_traverse(origin, dir, false, hit);
    return hit;
}

// Whether anything lies along the world-space ray within (0, tmax).
bool bvh_occluded(vec3 origin, vec3 dir, float tmax) {
    ++bvh_rays_traced;
    RayHit hit = RayHit(tmax, KAGE_NO_HIT, 0u, vec2(0.0));
    return KAGE_BVH_TRACE && bvh_traverse(origin, dir, true, hit);
}

// Whether any triangle of group `instance` lies along the ray, given in that group's object
// space, within (0, tmax).
bool bvh_occluded_object_space(uint instance, vec3 origin, vec3 dir, float tmax) {
    RayHit hit = RayHit(tmax, KAGE_NO_HIT, 0u, vec2(0.0));
    return bvh_traverse_blas(instance, origin, dir, true, hit);
}

// Texel coordinate i (any integer) of a side of n texels, wrapped as `wrap` says.
int bvh_wrap_texel(int i, int n, uint wrap) {
    if (wrap == KAGE_WRAP_CLAMP) return clamp(i, 0, n - 1);
    int period = wrap == KAGE_WRAP_MIRROR ? 2 * n : n;
    int j = ((i % period) + period) % period;
    return j < n ? j : period - 1 - j;
}

// Linear colour of texel (x, y) of albedo map `map`, wrapped.
vec3 bvh_albedo_texel_at(BvhAlbedoMap map, int x, int y) {
    int w = int(map.info.y), h = int(map.info.z);
    x = bvh_wrap_texel(x, w, map.info.w & 3u);
    y = bvh_wrap_texel(y, h, (map.info.w >> 2) & 3u);
    vec3 srgb = unpackUnorm4x8(bvh_albedo_texels[map.info.x + uint(y * w + x)].rgba).rgb;
    // The exact sRGB decoding (IEC 61966-2-1), as the rasterizer's R8G8B8A8_SRGB images do.
    return mix(srgb / 12.92, pow((srgb + 0.055) / 1.055, vec3(2.4)), greaterThan(srgb, vec3(0.04045)));
}

// Albedo map `index` at texture coordinate uv: level 0, bilinear in linear colour (or nearest,
// as its sampler magnifies), wrapped as its sampler wraps; white without a map. The
// rasterizer's mipmaps average the same texels over a pixel's footprint, as the reference's
// samples spread over each pixel do.
vec3 bvh_albedo_texel(uint index, vec2 uv) {
    if (index == 0u) return vec3(1.0);
    BvhAlbedoMap map = bvh_albedo_maps[index];
    vec2 f = uv * vec2(map.info.yz) - 0.5;
    if ((map.info.w & 16u) == 0u) {
        vec2 c = floor(f + 0.5);
        return bvh_albedo_texel_at(map, int(c.x), int(c.y));
    }
    vec2 c = floor(f), t = f - c;
    int x = int(c.x), y = int(c.y);
    return mix(mix(bvh_albedo_texel_at(map, x, y), bvh_albedo_texel_at(map, x + 1, y), t.x),
               mix(bvh_albedo_texel_at(map, x, y + 1), bvh_albedo_texel_at(map, x + 1, y + 1), t.x), t.y);
}

// What the albedo map of the triangle hit multiplies its albedo by at the hit (1 without one).
vec3 bvh_hit_texel(RayHit hit) {
    BvhTriangleAttributes a = bvh_attributes(hit.triangle);
    vec3 w = vec3(1.0 - hit.barycentric.x - hit.barycentric.y, hit.barycentric);
    vec2 uv = w.x * a.uv01.xy + w.y * a.uv01.zw + w.z * a.uv2.xy;
    return bvh_albedo_texel(floatBitsToUint(a.albedo.a), uv);
}

// The world-space surface at a hit. Both normals face against ray_dir; the shading normal flips
// together with the geometric one, as the rasterizer's gl_FrontFacing does. Its albedo is the
// mesh's times its albedo map's texel there.
SurfacePoint bvh_surface(RayHit hit, vec3 ray_dir) {
    BvhTriangle v = bvh_triangle(hit.triangle);
    BvhTriangleAttributes a = bvh_attributes(hit.triangle);
    mat4 to_world = bvh_object_to_world(hit.instance);
    vec3 w = vec3(1.0 - hit.barycentric.x - hit.barycentric.y, hit.barycentric);
    vec3 p = w.x * v.v0.xyz + w.y * v.v1.xyz + w.z * v.v2.xyz;
    // The scale is uniform, so the rotation part carries normals too.
    mat3 rotate = mat3(to_world);
    vec3 ng = normalize(rotate * cross(v.v1.xyz - v.v0.xyz, v.v2.xyz - v.v0.xyz));
    vec3 ns = normalize(rotate * (w.x * a.n0.xyz + w.y * a.n1.xyz + w.z * a.n2.xyz));
    float facing = dot(ng, ray_dir) > 0.0 ? -1.0 : 1.0;
    return SurfacePoint((to_world * vec4(p, 1.0)).xyz, facing * ng, facing * ns, a.albedo.rgb * bvh_hit_texel(hit));
}

// Moves p off its surface along n (to the side the new ray leaves on), by a few ulps of p's
// coordinates, or by a fixed tiny distance near the origin where ulps vanish (Wächter and
// Binder 2019, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems
// ch. 6).
vec3 offset_ray_origin(vec3 p, vec3 n) {
    const float origin = 1.0 / 32.0;
    const float float_scale = 1.0 / 65536.0;
    const float int_scale = 256.0;
    ivec3 of_i = ivec3(int_scale * n);
    vec3 p_i = intBitsToFloat(floatBitsToInt(p) + ivec3(p.x < 0.0 ? -of_i.x : of_i.x,
                                                         p.y < 0.0 ? -of_i.y : of_i.y,
                                                         p.z < 0.0 ? -of_i.z : of_i.z));
    return vec3(abs(p.x) < origin ? p.x + float_scale * n.x : p_i.x,
                abs(p.y) < origin ? p.y + float_scale * n.y : p_i.y,
                abs(p.z) < origin ? p.z + float_scale * n.z : p_i.z);
}

#endif
