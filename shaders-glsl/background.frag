#version 460
// The environment seen directly: radiance along each pixel's view ray.
#include "layouts.glsl"
#include "envmap.glsl"
#include "eye_ray.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D env;
layout(location = 0) in vec2 ndc;
layout(location = 0) out vec4 color;

void main() {
    vec3 dir = normalize(eye_ray(frame.eye_rays, ndc));
    vec3 map_dir = env_world_to_map(dir, frame.env_params.y);
    color = vec4(textureLod(env, env_dir_to_uv(map_dir), 0.0).rgb, 1.0);
}
