#version 460
// The polygon ID of the nearest surface, per tile texel (the paper's ID buffer): the mesh's
// first ID plus the triangle's index in its draw.
#include "layouts.glsl"

layout(push_constant) uniform Push { AsmTilePush draw; };
layout(location = 0) out uint id;

void main() {
    id = draw.ids.x + uint(gl_PrimitiveID);
}
