// Constants shared by GLSL and Rust. engine/build.rs turns each `#define KAGE_NAME value` into
// `kage::layouts::constants::NAME` (integer literal: u32, literal with '.': f32); comment lines
// right above a define become its Rust doc comment.
#ifndef KAGE_CONSTANTS_GLSL
#define KAGE_CONSTANTS_GLSL

// SH coefficients per colour channel (bands 0 to 2).
#define KAGE_SH_COEFFS 9
// Invocations per workgroup of the SH projection and reduction shaders. Small groups with
// many texels per invocation keep workgroup barriers few: they dominate on CPU drivers.
#define KAGE_SH_GROUP 64
// Environment texels each SH projection invocation adds up.
#define KAGE_SH_TEXELS_PER_INVOCATION 16
// How the SH projection maps a texel of its source image to a direction and a solid angle
// (ShProjectPush.size.w): an equirectangular environment map, or the six faces of a probe's
// cube map stacked top to bottom in one image (include/cube.glsl).
#define KAGE_SH_MAPPING_EQUIRECT 0
#define KAGE_SH_MAPPING_CUBE 1
// Rows an equirectangular map's SH projection integrates over at least: a map of fewer rows
// has each texel split into n x n sub-texels (n = ceil(this / rows)), each with its exact solid angle and its centre's direction. With
// one sample per texel, a 2x1 map's single row put the whole sphere on the horizon (irradiance
// 1.18 and 7.07 for pi); with 512 rows the midpoint rule's error, O((pi / rows)^2), is ~1e-5.
#define KAGE_SH_MIN_ROWS 512

// The buffers that bvh.glsl declares at set 0, bindings 0 .. KAGE_BVH_BINDINGS - 1; a shader
// that includes it numbers its own bindings from here.
#define KAGE_BVH_BINDINGS 7
// How an albedo map reads beyond [0, 1] (BvhAlbedoMap.info.w): repeat, mirrored repeat, clamp.
#define KAGE_WRAP_REPEAT 0
#define KAGE_WRAP_MIRROR 1
#define KAGE_WRAP_CLAMP 2
// RayHit.instance of a ray that hit nothing (0xffffffff).
#define KAGE_NO_HIT 4294967295u
// A BvhPair child reference with this bit set is a leaf: its count in bits 28-30, its first
// triangle in bits 0-27.
#define KAGE_BVH_LEAF 2147483648u
// Rays traced together by bvh_closest_hits_packet (one Hammersley cell of the PRT): 4 measured
// faster than 2 or 8 once the BVH was read through texel buffers (BENCHMARKS.md).
#define KAGE_BVH_PACKET 4
// The uvec4 texels of one record in the BVH's texel buffers (bvh.glsl's accessors; sizes checked
// against layouts.glsl's structs by engine/src/raycast/gpu.rs): a BvhPair, a BvhNode, a
// BvhInstance (object to world at texel 0, world to object at 4, info at 8), a BvhTriangle and
// its BvhTriangleAttributes.
#define KAGE_BVH_PAIR_TEXELS 2
#define KAGE_BVH_NODE_TEXELS 2
#define KAGE_BVH_INSTANCE_TEXELS 9
#define KAGE_BVH_TRIANGLE_TEXELS 3
#define KAGE_BVH_ATTRIBUTE_TEXELS 6
// Traversal stack entries per BVH level; the CPU build keeps every tree shallower than this.
#define KAGE_BVH_STACK 32
// Invocations per workgroup of the ray casting test and benchmark shader.
#define KAGE_RAYCAST_GROUP 256
// What raycast.comp asks of each ray (its specialization constant): the closest hit; whether
// occluded; whether occluded in one group's object space; the closest hit and its surface; the
// closest hits in one group's object space by packets of KAGE_BVH_PACKET rays.
#define KAGE_CAST_CLOSEST 0u
#define KAGE_CAST_OCCLUDED 1u
#define KAGE_CAST_OCCLUDED_OBJECT_SPACE 2u
#define KAGE_CAST_SURFACE 3u
#define KAGE_CAST_PACKET_OBJECT_SPACE 4u

// Samples one invocation of the reference shaders takes per dispatch. llvmpipe silently ends an
// invocation's loops after about 65,535 iterations in all; with BVH traversals inside every
// sample, 16 samples stay far below that. Larger batches are split into several dispatches.
#define KAGE_SAMPLES_PER_DISPATCH 16
// Workgroup of the reference renderer: 8x8 pixels.
#define KAGE_REFERENCE_GROUP 8
// Invocations per workgroup of the reference irradiance shader (one point each).
#define KAGE_IRRADIANCE_GROUP 64

// Invocations per workgroup of the PRT transfer shader.
#define KAGE_PRT_GROUP 64
// Invocations that cast one vertex's rays side by side (a SIMD group on lavapipe's 256-bit
// vectors): its workgroup holds KAGE_PRT_GROUP / KAGE_PRT_LANES vertices.
#define KAGE_PRT_LANES 8

// vec4s per vertex holding its PRT transfer vector: ceil(25 / 4), enough for 5 SH bands
// (fewer bands leave the rest zero).
#define KAGE_TRANSFER_VEC4 7
// Texels per row of the self-shadow texture (one texel per vertex).
#define KAGE_SELF_SHADOW_WIDTH 1024
// Most environment regions the Tamura technique handles (interpolated as vertex outputs).
#define KAGE_MAX_REGIONS 64
// Most occlusion layers per frame: their records sit in a uniform buffer (cheaper to read per
// fragment than a storage buffer on CPU drivers), 80 bytes each, within the 16 KiB every
// Vulkan device offers. A multiple of 32: the scene pass keeps one bit per layer.
#define KAGE_MAX_OCCLUSION_LAYERS 192
// uvec4s of one bit per occlusion layer (prt_scene's candidates).
#define KAGE_LAYER_UVEC4 2
// Invocations per workgroup of the occlusion box filter (one row or column each).
#define KAGE_BLUR_GROUP 64
// Most dominant lights (a sun, studio lamps) the Tamura technique lights per pixel beside its
// regions (see engine/src/techniques/tamura/dominant.rs), and most depth maps of groups along
// them per frame: their records sit in one uniform buffer (48 + 80 bytes each).
#define KAGE_MAX_DOMINANT_LIGHTS 8
#define KAGE_MAX_DOMINANT_MAPS 64

// Most regions the parallel-lights baseline (the paper's Fig. 3) treats as directional lights:
// one ParallelLight record each in a uniform buffer (96 bytes, 12 KiB in all, within the 16 KiB
// every Vulkan device offers) and one shadow-map layer each.
#define KAGE_MAX_PARALLEL_LIGHTS 128

// Most point and spot lights the shadowmap technique shadows: one ShadowLight record each in a
// uniform buffer and one shadow-map layer each.
#define KAGE_MAX_LOCAL_LIGHTS 8

// Adaptive shadow maps: texels per side of a tile (a node of the quadtree, rendered in one
// go). With texels a fixed fraction of the eye pixel, the memory a shadow edge takes grows with
// the tile's side (a tile covers a band of which the edge uses a strip): at equal memory 64²
// tiles misclassified 18 % fewer pixels of the `asm` walkthrough than 128² (BENCHMARKS.md); 32²
// little fewer again, at a frame cost over the paper's 1.74x.
#define KAGE_ASM_TILE_TEXELS 64
// Texels per side of a page of the pool: one slot of a tile's 4x4. A tile keeps
// pages only for the slots the analysis found eye pixels on shadow edges in and no finer tiles
// cover (engine/src/techniques/asm/pool.rs): texels a thirty-second of the eye pixel put a
// tile over a pixel or two, and most of its square holds no lookup.
#define KAGE_ASM_PAGE_TEXELS 16
// uvec4 texels of a depth page in the pool (asm_pack.comp): its depths row by row as 16-bit
// fractions of the page's own depth span, eight to a texel, then the span's nearest depth and
// step (float bits) in a texel of their own. Half the bytes of D32: twice the pages a budget holds.
#define KAGE_ASM_PAGE_DEPTH_TEXELS 33
// uvec4 texels of a page of polygon IDs (the ID test), four to a texel.
#define KAGE_ASM_PAGE_ID_TEXELS 64
// Workgroup of the ASM page packing (asm_pack.comp): a slot an invocation.
#define KAGE_ASM_PACK_GROUP 64
// The deepest quadtree level: 2^17 tiles per side, an effective 8,388,608² map (the paper
// reports the equivalent of 524,288²).
#define KAGE_ASM_MAX_LEVEL 17
// Levels the ASM refinement asks for by default (`AsmSettings::extra_levels`) beyond the one
// whose texels match the eye pixel's footprint: a reconstructed edge lies within a fraction of
// a texel of the true one, so texels a thirty-second of the pixel keep the lit/shadowed state of
// pixel centres right but near an edge. 5 against 4 (BENCHMARKS.md, "At 512²"): at 256 MiB 39
// pixels wrong instead of 90 at the asm overview, at 4 and 16 MiB the same (the pages run out
// first), and the same errors over the 256² walkthrough.
#define KAGE_ASM_EXTRA_LEVELS 5
// The page table's directory: one entry per tile of this level (64² entries, 16 KiB of the
// budget) naming the finest resident tile at or above it, where the lookup's descent starts.
// The descent is a chain of dependent reads, two levels each, that a CPU rasterizer pays per
// fragment in full. Level 8 (256 KiB) took 60 pages (20 tiles) at 4 MiB for no time the
// lighting pass showed once the descent went two levels a read (BENCHMARKS.md, "At 512²").
#define KAGE_ASM_DIRECTORY_LEVEL 6
// Levels below a pixel's finest resident tile the ASM analysis asks for at once (the tiles of
// its chain, each at most this many levels under the tile): a camera arriving at a new view
// refines that many levels in one frame instead of one.
#define KAGE_ASM_CHAIN_LEVELS 4
// Words of an edge record of the ASM analysis (AsmAnalysisPush): the pixel's finest resident
// tile's node | the levels missing from the tile its texels came from << KAGE_ASM_EDGE_NODE_BITS
// | the levels from that tile down to the node's << (KAGE_ASM_EDGE_NODE_BITS + 5), and where in
// the node's tile the pixel lies, KAGE_ASM_EDGE_CELL_BITS an axis (the host needs its cell at
// most KAGE_ASM_CHAIN_LEVELS levels down). Half the light uv as two floats took.
#define KAGE_ASM_EDGE_WORDS 2
#define KAGE_ASM_EDGE_CELL_BITS 16
#define KAGE_ASM_EDGE_NODE_BITS 22
// Workgroup of the ASM refinement analysis: 8x8 eye pixels.
#define KAGE_ASM_ANALYSIS_GROUP 8

#endif
