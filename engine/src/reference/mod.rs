//! The ground truth every technique is measured against: Monte Carlo direct lighting with full
//! visibility, cast through the BVH on the GPU.
