#version 460
// The scene pass of Sloan's PRT and of the Tamura technique. Per vertex: the self-shadowed
// radiance L_s from its texel of the self-shadow pass, and the transfer T(x, w_i) towards each
// region, reconstructed from the transfer vector (eq. (15)); the rasterizer interpolates both.
#include "constants.glsl"
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D self_shadow;
layout(set = 0, binding = 2, std430) readonly buffer Basis { RegionBasis region_basis[]; };
layout(push_constant) uniform Push { PrtDrawPush draw; };

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 transfer[KAGE_TRANSFER_VEC4];

layout(location = 0) out vec3 self_shadowed;
layout(location = 1) out vec3 world_position;
layout(location = 2) out vec4 region_transfer[KAGE_MAX_REGIONS / 4];

void main() {
    uint texel = draw.mesh.x + uint(gl_VertexIndex);
    self_shadowed = texelFetch(self_shadow, ivec2(texel % draw.mesh.y, texel / draw.mesh.y), 0).rgb;
    uint regions = draw.mesh.w;
    for (uint k = 0; k < KAGE_MAX_REGIONS / 4; ++k) region_transfer[k] = vec4(0.0);
    // The basis at each region's direction is evaluated exactly on the host once per group and
    // frame (Cartesian real SH, no table); here only the dot products remain.
    for (uint i = 0; i < regions; ++i) {
        RegionBasis b = region_basis[draw.mesh.z * regions + i];
        float t = 0.0;
        for (int j = 0; j < KAGE_TRANSFER_VEC4; ++j) t += dot(transfer[j], b.y[j]);
        region_transfer[i / 4][i % 4] = t;
    }
    vec4 world = draw.model * vec4(position, 1.0);
    world_position = world.xyz;
    gl_Position = frame.view_proj * world;
}
