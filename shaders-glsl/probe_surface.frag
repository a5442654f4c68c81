#version 460
// The radiance was computed on the side the triangle's winding faces; seen from behind, a
// surface is black (it still hides what lies beyond), as the reference's bounce rays see it.
// The vertices' radiance holds the mesh's albedo; its albedo map multiplies it per pixel.
#define KAGE_ALBEDO_MAP_BINDING 1
#include "albedo_map.glsl"

layout(location = 0) in vec3 vertex_radiance;
layout(location = 1) in vec2 texcoord;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(gl_FrontFacing ? vertex_radiance * albedo_texel(texcoord) : vec3(0.0), 1.0);
}
