#version 460
// The radiance was computed on the side the triangle's winding faces; seen from behind, a
// surface is black (it still hides what lies beyond), as the reference's bounce rays see it.
layout(location = 0) in vec3 vertex_radiance;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(gl_FrontFacing ? vertex_radiance : vec3(0.0), 1.0);
}
