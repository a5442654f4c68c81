#version 460
// Diffuse surfaces: world-space normal and texture coordinate for the lighting in scene.frag
// and probe_scene.frag.
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { DrawPush draw; };
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec3 world_normal;
layout(location = 1) out vec2 texcoord;

void main() {
    // Group transforms have uniform scale only, so the model matrix's upper 3x3 keeps normals
    // perpendicular to the surface.
    world_normal = mat3(draw.model) * normal;
    texcoord = uv;
    gl_Position = frame.view_proj * (draw.model * vec4(position, 1.0));
}
