#version 460
// L_s = albedo * sum_i L_i T_i (eq. (6)), with the environment's coefficients L rotated into the
// vertex's group frame.
#include "constants.glsl"
#include "layouts.glsl"

layout(set = 0, binding = 0, std430) readonly buffer Lights { GroupLight lights[]; };
layout(push_constant) uniform Push { SelfShadowPush p; };
layout(location = 0) flat in vec4 coefficients[KAGE_TRANSFER_VEC4];
layout(location = 0) out vec4 color;

void main() {
    GroupLight light = lights[p.target.w];
    vec3 radiance = vec3(0.0);
    for (int j = 0; j < KAGE_TRANSFER_VEC4; ++j) {
        radiance += vec3(dot(coefficients[j], light.red[j]), dot(coefficients[j], light.green[j]),
                         dot(coefficients[j], light.blue[j]));
    }
    color = vec4(p.albedo.rgb * radiance, 1.0);
}
