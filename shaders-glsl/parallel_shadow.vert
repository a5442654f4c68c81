#version 460
// Parallel-lights baseline: a mesh into one region's shadow map (orthographic, along omega_i).
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Lights { ParallelLight lights[KAGE_MAX_PARALLEL_LIGHTS]; };
layout(push_constant) uniform Push { ParallelShadowPush draw; };
layout(location = 0) in vec3 position;

void main() {
    gl_Position = lights[draw.light.x].view_proj * (draw.model * vec4(position, 1.0));
}
