#version 460
// A mesh into a shadow map (orthographic for parallel lights, perspective for local lights).
#include "layouts.glsl"

layout(push_constant) uniform Push { ShadowDepthPush draw; };
layout(location = 0) in vec3 position;

void main() {
    gl_Position = draw.view_proj * (draw.model * vec4(position, 1.0));
}
