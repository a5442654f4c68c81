#version 460
// Shadowmap technique: world-space position and normal for the per-pixel local lights.
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { LocalDrawPush draw; };
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 texcoord;
// depth_prepass.vert computes the same position; the shadowmap and ASM scene passes keep only
// fragments at exactly its depths (depth test EQUAL).
precise gl_Position;

void main() {
    // Uniform scale only: the model matrix's upper 3x3 keeps normals perpendicular.
    world_normal = mat3(draw.model) * normal;
    texcoord = uv;
    vec4 world = draw.model * vec4(position, 1.0);
    world_position = world.xyz;
    gl_Position = frame.view_proj * world;
}
