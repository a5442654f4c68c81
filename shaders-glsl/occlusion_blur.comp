#version 460
// One of the two 1D passes over each occlusion layer (eq. (13)): each invocation walks one row
// (horizontal pass) or column (vertical pass) of one layer. With the paper's fixed penumbra it
// slides a box of width s = sqrt(Omega_i) R, so the cost does not grow with the width; with the
// adaptive penumbra it keeps the running sum instead, so that the two passes leave a
// summed-area table from which the scene pass takes a box of any width per pixel. Both
// channels (coverage, coverage x height) are filtered alike. Outside the mask counts as empty.
#include "constants.glsl"
#include "layouts.glsl"

layout(local_size_x = KAGE_BLUR_GROUP) in;
layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(set = 0, binding = 1, rg32f) uniform readonly image2DArray source;
layout(set = 0, binding = 2, rg32f) uniform writeonly image2DArray target;
layout(push_constant) uniform Push { BlurPush p; };

vec2 fetch(int along, int line, uint layer) {
    if (along < 0 || along >= int(p.params.y)) return vec2(0.0);
    ivec2 texel = p.params.x == 0u ? ivec2(along, line) : ivec2(line, along);
    return imageLoad(source, ivec3(texel, layer)).rg;
}

void main() {
    int line = int(gl_GlobalInvocationID.x);
    uint layer = gl_GlobalInvocationID.y;
    int size = int(p.params.y);
    if (line >= size || layer >= p.params.z) return;
    bool prefix = p.params.w == 1u;
    int radius = prefix ? 0 : int(layers[layer].axis_u.w) / 2;
    vec2 sum = vec2(0.0);
    for (int k = -radius; k <= radius; ++k) sum += fetch(k, line, layer);
    float scale = prefix ? 1.0 : 1.0 / float(2 * radius + 1);
    for (int x = 0; x < size; ++x) {
        ivec2 texel = p.params.x == 0u ? ivec2(x, line) : ivec2(line, x);
        imageStore(target, ivec3(texel, layer), vec4(sum * scale, 0.0, 0.0));
        sum += fetch(x + radius + 1, line, layer);
        if (!prefix) sum -= fetch(x - radius, line, layer);
    }
}
