#version 460
// One of the two 1D passes over each occlusion layer (eq. (13)): each invocation walks one row
// (horizontal pass) or column (vertical pass) of one layer, sliding a box whose cost does not
// grow with its width. With the paper's fixed penumbra, one box of width s = sqrt(Omega_i) R
// filters the coverage (channel R). With the adaptive penumbra the passes leave boxes of three
// widths side by side, so that the scene pass can pick any width between them per pixel with
// one read: R the coverage unfiltered (a box of 1), G a middle width, B and A the widest
// (coverage, and coverage x occluder height, which gives the mean occluder height around a
// pixel). The horizontal pass reads the mask's (coverage, coverage x height) texels; the
// vertical pass reads its four channels back. Outside the mask counts as empty. The layers are
// half floats: coverage sums of at most one, kept to 2^-10 of their value.
#include "constants.glsl"
#include "layouts.glsl"

layout(local_size_x = KAGE_BLUR_GROUP) in;
layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(set = 0, binding = 1) uniform sampler2DArray source;
layout(set = 0, binding = 2, rgba16f) uniform writeonly image2DArray target;
layout(push_constant) uniform Push { BlurPush p; };
// 0: the paper's one box, 1: the adaptive penumbra's three (a pipeline constant, so that
// llvmpipe, which runs both sides of a branch, reads only what the mode needs).
layout(constant_id = 0) const bool ADAPTIVE = false;

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
    OcclusionLayer l = layers[layer];
    if (!ADAPTIVE) {
        // One box over the coverage.
        int radius = int(l.axis_u.w) / 2;
        float sum = 0.0;
        for (int k = -radius; k <= radius; ++k) sum += fetch(k, line, layer, from_mask).r;
        float scale = 1.0 / float(2 * radius + 1);
        for (int x = 0; x < size; ++x) {
            ivec2 texel = p.params.x == 0u ? ivec2(x, line) : ivec2(line, x);
            imageStore(target, ivec3(texel, layer), vec4(sum * scale, 0.0, 0.0, 0.0));
            sum += fetch(x + radius + 1, line, layer, from_mask).r - fetch(x - radius, line, layer, from_mask).r;
        }
        return;
    }
    // R passes through (a box of 1); G slides the middle box, B and A the widest.
    int middle = int(l.axis_u.w) / 2, widest = int(l.axis_v.w) / 2;
    vec3 sum = vec3(0.0);
    for (int k = -widest; k <= widest; ++k) {
        vec4 t = fetch(k, line, layer, from_mask);
        sum += vec3(abs(k) <= middle ? t.g : 0.0, t.ba);
    }
    vec3 scale = 1.0 / vec3(2 * middle + 1, 2 * widest + 1, 2 * widest + 1);
    for (int x = 0; x < size; ++x) {
        ivec2 texel = p.params.x == 0u ? ivec2(x, line) : ivec2(line, x);
        imageStore(target, ivec3(texel, layer), vec4(fetch(x, line, layer, from_mask).r, sum * scale));
        sum += vec3(fetch(x + middle + 1, line, layer, from_mask).g, fetch(x + widest + 1, line, layer, from_mask).ba)
            - vec3(fetch(x - middle, line, layer, from_mask).g, fetch(x - widest, line, layer, from_mask).ba);
    }
}
