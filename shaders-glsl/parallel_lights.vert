#version 460
// Parallel-lights baseline: world-space position and normal for the per-pixel lights.
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { ParallelDrawPush draw; };
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 texcoord;
// The same operations as depth_prepass.vert's, which lays the depth down first.
precise gl_Position;

void main() {
    // Uniform scale only: the model matrix's upper 3x3 keeps normals perpendicular.
    world_normal = mat3(draw.model) * normal;
    texcoord = uv;
    vec4 world = draw.model * vec4(position, 1.0);
    world_position = world.xyz;
    gl_Position = frame.view_proj * world;
}
