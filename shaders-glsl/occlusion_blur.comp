#version 460
// One pass of the separable box filter of width s (eq. (13)): each invocation slides a window
// along one row (horizontal pass) or column (vertical pass) of one layer, so the cost does not
// grow with the filter width. Outside the mask counts as unoccluded.
#include "constants.glsl"
#include "layouts.glsl"

layout(local_size_x = KAGE_BLUR_GROUP) in;
layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(set = 0, binding = 1, r32f) uniform readonly image2DArray source;
layout(set = 0, binding = 2, r32f) uniform writeonly image2DArray target;
layout(push_constant) uniform Push { BlurPush p; };

float fetch(int along, int line, uint layer) {
    if (along < 0 || along >= int(p.params.y)) return 0.0;
    ivec2 texel = p.params.x == 0u ? ivec2(along, line) : ivec2(line, along);
    return imageLoad(source, ivec3(texel, layer)).r;
}

void main() {
    int line = int(gl_GlobalInvocationID.x);
    uint layer = gl_GlobalInvocationID.y;
    int size = int(p.params.y);
    if (line >= size || layer >= p.params.z) return;
    int radius = int(layers[layer].axis_u.w) / 2;
    float sum = 0.0;
    for (int k = -radius; k <= radius; ++k) sum += fetch(k, line, layer);
    float scale = 1.0 / float(2 * radius + 1);
    for (int x = 0; x < size; ++x) {
        ivec2 texel = p.params.x == 0u ? ivec2(x, line) : ivec2(line, x);
        imageStore(target, ivec3(texel, layer), vec4(sum * scale));
        sum += fetch(x + radius + 1, line, layer) - fetch(x - radius, line, layer);
    }
}
