#version 460
// One of the two 1D passes over each occlusion layer (eq. (13)): each invocation walks one row
// (horizontal pass) or column (vertical pass) of one layer, sliding a box whose cost does not
// grow with its width. With the paper's fixed penumbra, one box of width s = sqrt(Omega_i) R
// filters the coverage (channel R). With the adaptive penumbra the passes leave boxes of three
// widths side by side, so that the scene pass can pick any width between them per pixel with
// one read: R the coverage unfiltered (a box of 1), G a middle width, B and A the widest
// (coverage, and coverage x occluder height, which gives the mean occluder height around a
// pixel). The horizontal pass reads the mask's (coverage, coverage x height) texels; the
// vertical pass reads its four channels back. Outside the mask counts as empty.
#include "constants.glsl"
#include "layouts.glsl"

layout(local_size_x = KAGE_BLUR_GROUP) in;
layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(set = 0, binding = 1) uniform sampler2DArray source;
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2DArray target;
layout(push_constant) uniform Push { BlurPush p; };

vec4 fetch(int along, int line, uint layer, bool from_mask) {
    if (along < 0 || along >= int(p.params.y)) return vec4(0.0);
    ivec2 texel = p.params.x == 0u ? ivec2(along, line) : ivec2(line, along);
    vec4 t = texelFetch(source, ivec3(texel, layer), 0);
    return from_mask ? t.rrrg : t;
}

void main() {
    int line = int(gl_GlobalInvocationID.x);
    uint layer = gl_GlobalInvocationID.y;
    int size = int(p.params.y);
    if (line >= size || layer >= p.params.z) return;
    bool from_mask = p.params.x == 0u;
    // Half-widths per channel (box widths are odd).
    OcclusionLayer l = layers[layer];
    ivec4 radius = p.params.w == 0u
        ? ivec4(int(l.axis_u.w) / 2, 0, 0, 0)
        : ivec4(0, int(l.axis_u.w) / 2, int(l.axis_v.w) / 2, int(l.axis_v.w) / 2);
    int widest = max(radius.x, max(radius.y, radius.z));
    vec4 sum = vec4(0.0);
    for (int k = -widest; k <= widest; ++k) {
        vec4 t = fetch(k, line, layer, from_mask);
        sum += mix(vec4(0.0), t, lessThanEqual(ivec4(abs(k)), radius));
    }
    vec4 scale = 1.0 / vec4(2 * radius + 1);
    for (int x = 0; x < size; ++x) {
        ivec2 texel = p.params.x == 0u ? ivec2(x, line) : ivec2(line, x);
        imageStore(target, ivec3(texel, layer), sum * scale);
        // Slide each channel's box by one texel (B and A share their width).
        vec4 enter = vec4(fetch(x + radius.x + 1, line, layer, from_mask).r,
                          fetch(x + radius.y + 1, line, layer, from_mask).g,
                          fetch(x + radius.z + 1, line, layer, from_mask).ba);
        vec4 leave = vec4(fetch(x - radius.x, line, layer, from_mask).r,
                          fetch(x - radius.y, line, layer, from_mask).g,
                          fetch(x - radius.z, line, layer, from_mask).ba);
        sum += enter - leave;
    }
}
