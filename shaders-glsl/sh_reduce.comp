#version 460
// Adds the partials of sh_project.comp into the final 9 coefficients, in a fixed order so that
// every run gives the same bits.
#include "constants.glsl"
#include "layouts.glsl"
#include "sh_reduce.glsl"

layout(local_size_x = KAGE_SH_GROUP) in;
layout(set = 0, binding = 0, std430) readonly buffer Partials { ShCoeffs partials[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Result { ShCoeffs result; };
layout(push_constant) uniform Push { ShProjectPush p; };  // size.x: number of partials

void main() {
    vec3 acc[9];
    for (int i = 0; i < 9; ++i) acc[i] = vec3(0.0);
    for (uint k = gl_LocalInvocationIndex; k < p.size.x; k += KAGE_SH_GROUP) {
        for (int i = 0; i < 9; ++i) acc[i] += partials[k].c[i].rgb;
    }
    sh_workgroup_sum(acc);
    if (gl_LocalInvocationIndex == 0) {
        for (int i = 0; i < 9; ++i) result.c[i] = vec4(acc[i], 0.0);
    }
}
