#version 460
// The depth prepass of the local-light and PRT techniques: local_lights.vert's and
// prt_scene.vert's position alone. The scene pass then shades only fragments at exactly these
// depths, so those shaders compute gl_Position with the same operations from the same inputs,
// `precise` (no contraction or reordering by the compiler). Every scene draw's push constants
// begin with the model matrix (LocalDrawPush, PrtDrawPush), the only one read here.
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { mat4 model; } draw;
layout(location = 0) in vec3 position;
precise gl_Position;

void main() {
    gl_Position = frame.view_proj * (draw.model * vec4(position, 1.0));
}
