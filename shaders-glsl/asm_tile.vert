#version 460
// An ASM tile with polygon IDs: a mesh into the tile's depth and ID layers.
#include "layouts.glsl"

layout(push_constant) uniform Push { AsmTilePush draw; };
layout(location = 0) in vec3 position;

void main() {
    gl_Position = draw.transform * vec4(position, 1.0);
}
