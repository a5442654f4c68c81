#version 460
// The local-light techniques' depth prepass: local_lights.vert's position alone. The scene pass
// then shades only fragments at exactly these depths (depth test EQUAL), so both shaders compute
// gl_Position with the same operations from the same inputs, `precise` (no contraction or
// reordering by the compiler).
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { LocalDrawPush draw; };
layout(location = 0) in vec3 position;
precise gl_Position;

void main() {
    gl_Position = frame.view_proj * (draw.model * vec4(position, 1.0));
}
