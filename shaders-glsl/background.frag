#version 460
// The environment seen directly: radiance along each pixel's view ray.
#include "layouts.glsl"
#include "envmap.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1) uniform sampler2D env;
layout(location = 0) in vec2 ndc;
layout(location = 0) out vec4 color;

void main() {
    vec4 far = frame.inv_view_proj * vec4(ndc, 0.5, 1.0);
    vec3 dir = normalize(far.xyz / far.w - frame.camera_pos.xyz);
    vec3 map_dir = env_world_to_map(dir, frame.env_params.y);
    color = vec4(textureLod(env, env_dir_to_uv(map_dir), 0.0).rgb, 1.0);
}
