//! Ray casting through a BVH held in GPU buffers (no ray-query extension): built on the CPU,
//! traversed by compute shaders (shaders-glsl/include/bvh.glsl).
//!
//! # Structure
//! Two levels. Each scene group has a bottom-level BVH (binned SAH, leaves of at most 4
//! triangles) over all its meshes' triangles in the group's object space; instance index ==
//! group index. A top-level BVH over the groups' world-space bounds (each group's root box moved
//! by its transform), one instance per leaf, is rebuilt by [`SceneBvh::set_transform`], which
//! never touches the bottom level. Rays enter an instance through its world-to-object matrix
//! without renormalising the direction, so t is the same world-space distance in both spaces.
//!
//! # GPU layout (bindings 0 .. `KAGE_BVH_BINDINGS` - 1, structs in layouts.glsl)
//! Bindings 0-4, what the traversal and every hit read, are texel buffers of `uvec4`s read
//! through bvh.glsl's accessors (`bvh_pair`, `bvh_tlas_node`, `bvh_instance_info`,
//! `bvh_triangle`, `bvh_attributes`, ...): llvmpipe reads a storage buffer one lane and word at
//! a time, and texel fetches made the traversal 1.6-3.5x faster there (BENCHMARKS.md, "Ray
//! casting"). 5-6, the albedo maps, are storage buffers.
//! 0. `BvhPair[]`, the bottom-level trees of every group as the GPU reads them, one pair per
//!    interior node holding its two children's quantized boxes and references (see `raycast/pairs.rs`),
//!    each group's from its root pair (`BvhInstance.info.w`); 1. `BvhNode[]`, the top level,
//!    root at 0; 2. `BvhInstance[]`, per group: both matrices, root node (of the CPU's tree),
//!    first triangle, triangle count, root pair; 3. `BvhTriangle[]`,
//!    object-space positions; 4. `BvhTriangleAttributes[]`: vertex normals, albedo, albedo map
//!    and texture coordinates at the same index; 5. `BvhAlbedoMap[]`, the albedo maps (entry 0
//!    unused); 6. `u32[]`, their texels (RGBA8 sRGB), sampled at level 0 (`bvh_albedo_texel`).
//!
//! The CPU keeps the bottom level as built ([`SceneBvh::blas_nodes`], traversed by
//! [`SceneBvh::closest_hit`] and the checks). A node is 32 bytes: `lo = (min.xyz, index)`, `hi = (max.xyz, count)`, index and count as
//! float bits. `count == 0`: interior node whose children are `index` and `index + 1`.
//! `count > 0`: a leaf; in the bottom level its triangles are `index .. index + count` (global
//! indices into the triangle buffer, which is ordered leaf by leaf), in the top level
//! `count == 1` and `index` is the instance. An empty group or scene gets a root with an empty
//! box (min = +inf, max = -inf) that every ray misses, so no shader needs a special case.
//!
//! Intersection is the watertight test of Woop, Benthin and Wald (2013) on both sides
//! ([`WatertightRay`]), except for packets of rays from one origin (the PRT's), which the GPU
//! tests in the Plücker form that shares each triangle's edge planes through the origin among
//! them (`bvh_fan` in bvh.glsl), watertight as well; [`offset_ray_origin`] follows Wächter and
//! Binder (2019).
mod aabb;
mod brute_force;
mod caster;
mod gpu;
mod pairs;
mod sah;
mod scene_bvh;
mod traverse;
mod triangle;

pub use aabb::Aabb;
pub use brute_force::{closest_hit_brute_force, edge_distance, occluded_object_space_brute_force};
pub use caster::{GpuRays, Query, RayCaster};
pub use gpu::GpuBvh;
pub use scene_bvh::{SceneBvh, TriangleOrigin};
pub use traverse::Hit;
pub use triangle::{offset_ray_origin, WatertightRay};
