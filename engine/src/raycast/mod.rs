//! Ray casting through a BVH held in storage buffers (no ray-query extension): built on the
//! CPU, traversed by compute shaders (shaders-glsl/include/bvh.glsl).
