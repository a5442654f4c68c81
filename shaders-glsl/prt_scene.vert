#version 460
#extension GL_EXT_control_flow_attributes : require
// The scene pass of Sloan's PRT and of the Tamura technique. Per vertex: the self-shadowed
// radiance L_s from its texel of the self-shadow pass, and the transfer T(x, w_i) towards each
// region, reconstructed from the transfer vector (eq. (15)); the rasterizer interpolates both.
// With PIXEL_COSINE (beyond the paper), the vertex passes on what its group hides of the
// unshadowed light instead, albedo / pi E(n) - L_s, and the fragment takes E(n) at its own
// normal: the cosine is exact per pixel and only the self-shadow is interpolated.
#include "constants.glsl"
#include "layouts.glsl"
#include "sh.glsl"
#include "envmap.glsl"
#include "occlusion.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D self_shadow;
// Each region's RegionBasis as KAGE_TRANSFER_VEC4 texels, group after group (a texel buffer:
// llvmpipe reads a storage buffer lane by lane, vendor-notes.md).
layout(set = 0, binding = 2) uniform usamplerBuffer region_basis;
layout(set = 0, binding = 3, std140) uniform Energy { vec4 region_energy[KAGE_MAX_REGIONS]; };
// The SH of the light L_s is made of (the map less its dominant lights), in the map's frame.
layout(set = 0, binding = 5, std140) uniform Layers { OcclusionLayer layers[KAGE_MAX_OCCLUSION_LAYERS]; };
layout(set = 0, binding = 8, std140) uniform Sh { ShCoeffs sh; };
layout(push_constant) uniform Push { PrtDrawPush draw; };
// Pipeline constants (see GraphicsDesc::constants; id 0 is the fragment shader's): vec4s of
// region transfers, ceil(q / 4) (at least 1), and of SH coefficients, ceil(bands^2 / 4).
// llvmpipe interpolates every declared output for every fragment, so the outputs are sized to
// q; with constant bounds the loops below unroll and every output index is a constant (a
// dynamically indexed output costs a select over all of them per write on llvmpipe).
layout(constant_id = 1) const uint REGION_VEC4 = KAGE_MAX_REGIONS / 4;
layout(constant_id = 2) const uint BASIS_VEC4 = KAGE_TRANSFER_VEC4;
layout(constant_id = 4) const bool PIXEL_COSINE = false;

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 transfer[KAGE_TRANSFER_VEC4];

// L_s, or with PIXEL_COSINE albedo / pi E(n) - L_s; less, or more, what occluder sheets hide
// (albedo B_i T_i of the regions they take away whole).
layout(location = 0) out vec3 self_term;
layout(location = 1) out vec3 world_position;
layout(location = 2) out vec3 world_normal;
layout(location = 3) out vec2 texcoord;
// Bit k: the receiver's occlusion layer k may hold a shadow somewhere on a triangle this vertex
// provokes (prt_scene.frag's candidates).
layout(location = 4) flat out uvec4 candidates[KAGE_LAYER_UVEC4];
layout(location = 4 + KAGE_LAYER_UVEC4) out vec4 region_transfer[REGION_VEC4];
// The same operations as depth_prepass.vert's, which lays the depth down first.
precise gl_Position;

void main() {
    uint texel = draw.mesh.x + uint(gl_VertexIndex);
    self_term = texelFetch(self_shadow, ivec2(texel % draw.mesh.y, texel / draw.mesh.y), 0).rgb;
    uint regions = draw.mesh.w, first = draw.mesh.z * regions;
    // The basis at each region's direction is evaluated exactly on the host once per group and
    // frame (Cartesian real SH, no table); here only the dot products remain.
    // The regions an occluder sheet hides wholly from this group take their whole share,
    // B_i max(T_i, 0), here (they have no occlusion layers).
    vec3 hidden = vec3(0.0);
    [[unroll]] for (uint k = 0u; k < REGION_VEC4; ++k) {
        vec4 t = vec4(0.0);
        [[unroll]] for (uint c = 0u; c < 4u; ++c) {
            uint i = 4u * k + c;
            if (i < regions) {
                int basis = int((first + i) * uint(KAGE_TRANSFER_VEC4));
                [[unroll]] for (uint j = 0u; j < BASIS_VEC4; ++j) {
                    t[c] += dot(transfer[j], uintBitsToFloat(texelFetch(region_basis, basis + int(j))));
                }
                bool gone = (draw.covered[i / 32u] & (1u << (i % 32u))) != 0u;
                hidden += gone ? region_energy[i].rgb * max(t[c], 0.0) : vec3(0.0);
            }
        }
        region_transfer[k] = t;
    }
    // Uniform scale only: the model matrix's upper 3x3 keeps normals perpendicular.
    world_normal = mat3(draw.model) * normal;
    texcoord = uv;
    if (PIXEL_COSINE) {
        vec3 unshadowed = max(sh9_irradiance(sh.c, env_world_to_map(normalize(world_normal), frame.env_params.y)), vec3(0.0));
        self_term = draw.albedo.rgb / KAGE_PI * unshadowed - self_term;
    }
    self_term += (PIXEL_COSINE ? 1.0 : -1.0) * draw.albedo.rgb * hidden;
    vec4 world = draw.model * vec4(position, 1.0);
    world_position = world.xyz;
    // Which layers' footprints a triangle with this corner can reach: every point of the
    // triangle lies within the mesh's longest edge of it, which a layer's uv scale turns into
    // mask units. The fragments then read only these layers, not all of the receiver's.
    uvec4 bits[KAGE_LAYER_UVEC4];
    [[unroll]] for (uint w = 0u; w < KAGE_LAYER_UVEC4; ++w) bits[w] = uvec4(0u);
    for (uint k = 0u; k < draw.layers.y; ++k) {
        OcclusionLayer layer = layers[draw.layers.x + k];
        if (within_footprint(layer, world_position, draw.albedo.a * layer.centre.w)) {
            bits[k / 128u][(k / 32u) % 4u] |= 1u << (k % 32u);
        }
    }
    [[unroll]] for (uint w = 0u; w < KAGE_LAYER_UVEC4; ++w) candidates[w] = bits[w];
    gl_Position = frame.view_proj * world;
}
