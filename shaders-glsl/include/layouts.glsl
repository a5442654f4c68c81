// Struct layouts shared by GLSL and Rust, defined only here. engine/build.rs generates the
// matching `#[repr(C)]` Rust structs in `kage::layouts` with std430 offsets (valid in std140
// too), so this file may hold only plain struct definitions with members of type float, int,
// uint, vec2, vec4, ivec4, uvec4, mat4 or an earlier struct, and fixed-size arrays of the
// 16-byte-aligned ones. Comments right above a struct or member, or after a member on its line,
// become Rust doc comments.
#ifndef KAGE_LAYOUTS_GLSL
#define KAGE_LAYOUTS_GLSL

#include "constants.glsl"

// The eye ray through NDC point (x, y): world direction forward + x * ndc.x + y * ndc.y, of unit
// view depth (eye_ray.glsl). Built from the camera's basis in double precision: unprojecting an
// NDC point through the inverse view-projection in float strays about 1/50 px from the pixel
// (the near plane's ill-conditioning), so rays and raster coverage disagreed at edges.
struct EyeRays {
    vec4 x; // xyz: world vector per unit of NDC x, w: unused
    vec4 y; // xyz: world vector per unit of NDC y (rows downward), w: unused
    vec4 forward; // xyz: the unit view axis, w: unused
};

// Per-frame camera data (uniform buffer, std140).
struct FrameUniforms {
    mat4 view_proj;
    EyeRays eye_rays;
    vec4 camera_pos; // xyz: world-space camera position, w: unused
    vec4 env_params; // x: intensity, y: rotation in radians, z, w: unused
    vec4 viewport; // xy: the target's size in pixels, z: near plane, w: far plane (view depth)
};

// Per-draw data (push constants).
struct DrawPush {
    mat4 model;
    vec4 albedo; // rgb: diffuse albedo, a: unused
};

// SH irradiance coefficients, KAGE_SH_COEFFS per channel.
struct ShCoeffs {
    vec4 c[KAGE_SH_COEFFS]; // rgb: one coefficient per channel, w: unused
};

// Push constants of the SH projection compute pass.
struct ShProjectPush {
    uvec4 size; // x: width, y: height, z: texels per invocation, w: mapping (KAGE_SH_MAPPING_*)
};

// Irradiance of a moving group from the light probes: E(n) = (n, 1)^T M (n, 1) per channel
// (Ramamoorthi & Hanrahan 2001, eq. 12), M from the SH interpolated at the group's position.
struct ProbeLight {
    mat4 red;
    mat4 green;
    mat4 blue;
};

// A BVH node, 32 bytes; the children of an interior node are adjacent (index, index + 1).
// Bottom-level nodes (one tree per scene group) bound object-space triangles and a leaf holds
// triangles [index, index + count) of the BVH triangle buffer; top-level nodes bound world-space
// instances and a leaf holds exactly one instance, `index`.
struct BvhNode {
    vec4 lo; // xyz: box minimum, w: floatBitsToUint = index (first child, first triangle or instance)
    vec4 hi; // xyz: box maximum, w: floatBitsToUint = count (0: interior node)
};

// A bottom-level interior node as the ray casting shaders read it (engine/src/raycast/pairs.rs):
// its two children's boxes quantized to 8 bits per coordinate on a grid over the node's own box,
// and where each child leads (a pair's index, or KAGE_BVH_LEAF | count << 28 | first triangle,
// or KAGE_NO_HIT: no child). Two texels a step, against four for two BvhNodes.
struct BvhPair {
    uvec4 origin; // xyz: float bits of the grid's origin (the node box's minimum rounded down to a float whose lowest 8 mantissa bits are zero), those 8 bits holding the grid step's biased exponent along the axis (step 2^(e - 127)); w: the left child
    uvec4 boxes; // xyz: along x, y and z, the children's corners in grid steps, a byte each from the lowest: the left child's minimum, its maximum, the right child's minimum, its maximum; w: the right child
};

// A triangle's object-space vertex positions (w unused), for the intersection test.
struct BvhTriangle {
    vec4 v0;
    vec4 v1;
    vec4 v2;
};

// What shading needs of a triangle, at the same index as its BvhTriangle.
struct BvhTriangleAttributes {
    vec4 n0; // xyz: unit object-space vertex normal of v0, w: unused
    vec4 n1;
    vec4 n2;
    vec4 albedo; // rgb: diffuse albedo, a: floatBitsToUint = its albedo map in BvhAlbedoMaps (0: none)
    vec4 uv01; // xy: albedo-map texture coordinate of v0, zw: of v1
    vec4 uv2; // xy: of v2, zw: unused
};

// One texel of an albedo map: RGBA8 sRGB, R in the lowest byte.
struct BvhTexel {
    uint rgba;
};

// An albedo map as the ray tracer samples it (level 0, bvh.glsl's bvh_albedo_texel).
struct BvhAlbedoMap {
    uvec4 info; // x: first texel in BvhAlbedoTexels, y: width, z: height, w: bits 0-1 wrap in u, 2-3 wrap in v (KAGE_WRAP_*), bit 4 linear magnification
};

// A scene group placed in the world; instance index == group index.
struct BvhInstance {
    mat4 object_to_world;
    mat4 world_to_object;
    uvec4 info; // x: BLAS root node (the CPU tree's), y: first triangle, z: triangle count, w: BLAS root pair (the GPU's)
};

// A ray of the ray casting test and benchmark shader.
struct CastRay {
    vec4 origin; // xyz: origin, w: tmax
    vec4 direction; // xyz: unit direction (object space for object-space queries), w: unused
};

// What the ray casting shader writes per ray; the surface members only for surface queries.
struct CastResult {
    vec4 hit; // x: t, yz: barycentric weights of v1 and v2, w: unused
    uvec4 ids; // x: instance (KAGE_NO_HIT on a miss), y: triangle, z, w: unused
    vec4 position; // xyz: bvh_surface's world-space position, w: unused
    vec4 geometric_normal; // xyz: bvh_surface's geometric normal, w: unused
    vec4 shading_normal; // xyz: bvh_surface's shading normal, w: unused
    vec4 albedo; // rgb: bvh_surface's albedo, a: unused
};

// Push constants of the ray casting shader.
struct CastPush {
    uvec4 params; // x: ray count, y: zero, z: instance (object-space queries), w: first ray
};

// The reference's running statistics of one pixel or point: mean and sum of squared deviations
// of its samples (Welford), merged batch by batch with Chan et al.'s formula, which stays
// accurate where a raw sum of squares would cancel.
struct ReferenceAccum {
    vec4 mean; // rgb: mean of the samples so far, w: local mode: the lowest luminance at the edge-tie offsets
    vec4 m2; // rgb: sum of squared deviations from the mean (local mode: x 1 where the primary ray meets a surface, 0 where it misses), w: local mode: the highest one
};

// A point or spot light as the reference's --light local mode reads it.
struct ReferenceLight {
    vec4 position; // xyz: world position, w: 0 point light, 1 spot light
    vec4 direction; // xyz: unit spot axis, w: cosine of half the spot's fov_deg
    vec4 intensity; // rgb: radiant intensity (W/sr), w: unused
};

// Push constants of the reference renderer (reference_render.comp).
struct ReferencePush {
    EyeRays eye_rays;
    vec4 camera_pos; // xyz: camera position, w: the environment's sum of luminance x solid angle (0: no environment sampling)
    uvec4 frame; // x: width, y: height, z: samples accumulated before this batch, w: samples in this batch
    uvec4 params; // x: 0 environment light, 1 local lights, y: light count, z: seed, w: the rasterizer's sub-pixel precision bits
};

// A point of the reference's irradiance mode.
struct IrradiancePoint {
    vec4 position; // xyz: world position, w: unused
    vec4 normal; // xyz: unit normal, w: unused
};

// Push constants of the reference irradiance shader (reference_irradiance.comp).
struct IrradiancePush {
    uvec4 params; // x: point count, y: samples accumulated before this batch, z: samples in this batch, w: seed
    vec4 env; // x: the environment's sum of luminance x solid angle (0: no environment sampling), yzw: unused
    uvec4 transport; // x: local light count, y: 1 when the surfaces hit radiate their per-vertex radiance (one more bounce), z: 1 to trace the rays, 0 to take each as a miss (timing all but the traversal), w: unused
};

// A vertex of the PRT precomputation, in its group's object space.
struct PrtVertex {
    vec4 position; // xyz: position, w: unused
    vec4 normal; // xyz: unit vertex normal, w: unused
};

// Push constants of the PRT transfer shader; one dispatch covers some rays of some vertices of one mesh.
struct PrtTransferPush {
    uvec4 range; // x: first vertex (into the vertex buffer), y: vertex count, z: group (BVH instance), w: rays per vertex
    uvec4 params; // x: first ray of this dispatch (a multiple of KAGE_BVH_PACKET), y: rays in it, zw: zero
};

// The environment's SH as one group's object space sees it, for the self-shadow pass: one
// vec4-padded coefficient vector per colour channel.
struct GroupLight {
    vec4 red[KAGE_TRANSFER_VEC4];
    vec4 green[KAGE_TRANSFER_VEC4];
    vec4 blue[KAGE_TRANSFER_VEC4];
};

// Push constants of the self-shadow pass (one draw of points per mesh).
struct SelfShadowPush {
    uvec4 target; // x: first texel, y: texture width, z: texture height, w: group
    vec4 albedo; // rgb: the mesh's diffuse albedo, a: unused
};

// The SH basis evaluated at one region's direction in one group's object space.
struct RegionBasis {
    vec4 y[KAGE_TRANSFER_VEC4];
};

// Push constants of the PRT scene pass (Sloan and Tamura): one draw per mesh.
struct PrtDrawPush {
    mat4 model;
    vec4 albedo; // rgb: diffuse albedo, a: the mesh's longest triangle edge in world units
    uvec4 mesh; // x: first self-shadow texel, y: texture width, z: group, w: regions (0: self-shadow only)
    uvec4 layers; // x: first occlusion layer of this receiver, y: its layer count, z: the group's slot among the dominant lights' self-shadow maps plus one (0: none), w: mask size in texels
    uvec4 covered; // bit s (of 128): an occluder sheet hides light source s (regions, then dominant lights) from the whole group
};

// One occlusion layer: the shadow of one occluder group on one receiver group for one region.
// The mask is an orthographic view along the region's direction fitted to the occluder: its
// plane goes through the occluder's bounding-sphere centre, perpendicular to the direction, and
// its depth runs away from the light over both groups' spheres.
struct OcclusionLayer {
    vec4 centre; // xyz: occluder bounding-sphere centre (world), w: 1 / (2 x half-extent of the mask)
    vec4 axis_u; // xyz: first unit axis of the plane, w: box width in texels (odd): fixed penumbra, the width of eq. (13); adaptive, the middle one
    vec4 axis_v; // xyz: second unit axis, w: adaptive penumbra: the widest box in texels (odd)
    vec4 footprint; // the mask uv rectangle beyond which the filtered layer is 0: xy min, zw max
    uint region; // the region's index
    uint occluder; // occluder group
    float widen; // adaptive penumbra: box width in texels per world unit between occluder and receiver, sqrt(Omega_i) / texel size
    float depth_range; // half the mask's depth range (world units), centred on the plane
};

// Push constants of the occluder mask pass: one draw per receiver or occluder mesh per layer.
struct MaskPush {
    mat4 model;
    uvec4 layer; // x: occlusion layer index, y: 0 receiver (depth only), 1 occluder, z, w: unused
    vec4 bias; // x: how far behind the receiver's surface an occluder fragment still counts as behind it (world units), yzw: unused
};

// A dominant light as the PRT scene pass lights it, with the groups' depth maps along it.
struct DominantLight {
    vec4 direction; // xyz: unit world direction towards the light, w: tangent of its angular radius
    vec4 energy; // rgb: its energy B (radiance integrated over its solid angle), a: unused
    uvec4 maps; // x: first of its maps in DominantLights.maps (one per group that shadows itself), y: their count, zw: unused
};

// One group's depth map along a dominant light, for its own shadow: an orthographic view of the
// group's bounding sphere along the light, depth 0 at the sphere's point nearest the light, 1 at
// its farthest.
struct DominantMap {
    mat4 view_proj; // world to the map's clip space
    vec4 params; // x: world size of a texel, y: map texels per side, zw: unused
};

// Every dominant light and map of the frame (a uniform buffer).
struct DominantLights {
    DominantLight lights[KAGE_MAX_DOMINANT_LIGHTS];
    DominantMap maps[KAGE_MAX_DOMINANT_MAPS];
};

// Push constants of the occlusion box filter.
struct BlurPush {
    uvec4 params; // x: unused (the pass is a pipeline constant), y: mask size in texels, z: layer count, w: unused
};

// One region of the parallel-lights baseline as a directional light with a binary shadow map.
struct ParallelLight {
    mat4 view_proj; // world to the light's orthographic clip space (depth 0 to 1)
    vec4 direction; // xyz: unit world direction towards the light (omega_i), w: unused
    vec4 energy; // rgb: B_i, a: unused
};

// Push constants of the depth-only shadow-map pass (parallel lights and local lights): one draw
// per mesh per map. 128 bytes, the push-constant size every Vulkan device offers.
struct ShadowDepthPush {
    mat4 model;
    mat4 view_proj; // world to the map's clip space (depth 0 to 1)
};

// Push constants of the parallel-lights scene pass: one draw per mesh.
struct ParallelDrawPush {
    mat4 model;
    vec4 albedo; // rgb: diffuse albedo, a: unused
    uvec4 params; // x: light count, y: shadow-map side in texels, z, w: unused
    vec4 shadow; // x: slope-scaled normal offset (world units, times the sine of the light's angle to the normal), y: constant normal offset (world units), z: depth bias (light depth units), w: unused
};

// A point or spot light of the shadowmap technique with its conventional shadow map (one
// layer of a D32 array image), in the reference's conventions (ReferenceLight).
struct ShadowLight {
    mat4 view_proj; // world to the map's perspective clip space (depth 0 to 1)
    ReferenceLight light;
    vec4 map; // x: near, y: far plane of the map's projection (world units), z: world size of a texel at unit depth, w: unused
};

// Push constants of the shadowmap technique's scene pass: one draw per mesh.
struct LocalDrawPush {
    mat4 model;
    vec4 albedo; // rgb: diffuse albedo, a: unused
    uvec4 params; // x: light count, y: polygon ID of the mesh's first triangle (ASM's ID test), z: the frame number ASM's use marks record, w: unused
    vec4 bias; // x: constant depth bias, y: slope-scaled depth bias (both in texels at the receiver's depth), z: the largest slope (tangent) the bias follows, w: unused
};

// A node of the adaptive shadow map's page table: one resident tile of the quadtree over the
// light's view. Node 0 is the root; the lookup descends two levels a step, through the finest
// resident tile up to two levels below each node, and uses the last node's page
// (engine/src/techniques/asm/page_table.rs).
struct AsmNode {
    uvec4 below[4]; // over cell (x & 3, y & 3) of the tile's grandchildren, below[y & 3][x & 3]: the grandchild's node index | 2 << 24 where it is resident, else the child's | 1 << 24 where that is, else 0
    uvec4 pages[4]; // per slot (x, y) of the tile's 4x4, row y component x: the index of the page holding it in the pool | the levels up to the tile that stores it << 24 (0: this one), where no resident child covers the slot (else unused)
};

// Push constants of an ASM tile render with polygon IDs (asm_tile.vert/frag): one draw per mesh.
struct AsmTilePush {
    mat4 transform; // object to the tile's clip space (the tile's view-projection times the model)
    uvec4 ids; // x: polygon ID of the mesh's first triangle (IDs start at 1; 0: no surface), y, z, w: unused
};

// Push constants of the ASM page packing (asm_pack.comp).
struct AsmPackPush {
    uvec4 count; // x: the slots listed; y, z, w: unused
};

// Push constants of the ASM refinement analysis (asm_analysis.comp). Its output buffer is uint
// words: `[0]` the number of edge records written; then two words per page table node (up to
// size.z), the slots of its 4x4 (bit x + 4y) where a pixel's lookup ended: the first those it
// read from a tile two levels up or more | those on a shadow edge its own texels resolve << 16,
// the second those it read from its own texels | those it read from an ancestor's << 16; then
// up to size.w edge records of KAGE_ASM_EDGE_WORDS words, one per eye pixel on a shadow edge
// short of resolution (their layout where constants.glsl defines KAGE_ASM_EDGE_WORDS).
struct AsmAnalysisPush {
    uvec4 size; // x: width, y: height (pixels), z: most page table nodes, w: most edge records
    uvec4 phase; // x: the pixel of each 2x2 block analysed this frame (x + 2y), y, z, w: unused
    vec4 bias; // as LocalDrawPush.bias
};

#endif
