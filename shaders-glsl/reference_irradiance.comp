#version 460
// The reference's irradiance mode: E(p, n) = integral of L_env V max(dot(n, w), 0) dw at listed
// points, one invocation per point, `params.z` samples per batch added to its statistics.
// Shadow rays leave from p offset along n; the point's own surface is whatever the scene holds
// there.
#include "constants.glsl"
#include "layouts.glsl"
#include "bvh.glsl"
#include "reference.glsl"

layout(local_size_x = KAGE_IRRADIANCE_GROUP) in;
layout(set = 0, binding = KAGE_BVH_BINDINGS + 4, std430) readonly buffer Points {
    IrradiancePoint points[];
};
layout(push_constant) uniform Push { IrradiancePush p; };

void main() {
    uint index = gl_GlobalInvocationID.x;
    if (index >= p.params.x) return;
    vec3 position = points[index].position.xyz;
    vec3 n = points[index].normal.xyz;
    uint before = p.params.y, count = p.params.z;
    vec3 mean = vec3(0.0), m2 = vec3(0.0);
    for (uint k = 0u; k < count; ++k) {
        Rng rng = rng_init(p.params.w, index, before + k);
        vec3 x = env_irradiance_sample(position, n, n, p.env.x, rng);
        vec3 delta = x - mean;
        mean += delta / float(k + 1u);
        m2 += delta * (x - mean);
    }
    accum_merge(index, before, count, mean, m2);
}
