#version 460
// One of the two 1D passes over each occlusion layer (eq. (13)): each invocation walks one row
// (horizontal pass) or column (vertical pass) of one layer, sliding a box whose cost does not
// grow with its width. With the paper's fixed penumbra, one box of width s = sqrt(Omega_i) R
// filters the coverage (channel R). With the adaptive penumbra the passes leave boxes of three
// widths side by side, so that the scene pass can pick any width between them per pixel with
// one read: R the coverage unfiltered (a box of 1), G a middle width, B and A the widest
// (coverage, and coverage x occluder height, which gives the mean occluder height around a
// pixel). The horizontal pass reads the mask's (coverage, coverage x height) texels and writes
// its boxes as half floats packed in a storage buffer; the vertical pass reads them back (a
// buffer load costs llvmpipe less than a half-float texel fetch) and writes the filtered
// layers, half floats too. Each rounding to half keeps a value to 2^-11 of itself, and a box
// mean of rounded values stays within that of the exact mean: the filtered coverage, at most
// one, is kept to 2^-10 of its value, far below an 8-bit pixel's step. Outside the mask counts
// as empty.
#include "constants.glsl"
#include "layouts.glsl"

layout(local_size_x = KAGE_BLUR_GROUP) in;
layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(set = 0, binding = 1) uniform sampler2DArray mask;
// The horizontal pass's boxes, [layer][row][column], read back by the vertical pass: four
// half floats each (packHalf2x16), half the memory of f32.
layout(set = 0, binding = 2, std430) buffer RowBoxes { uvec2 row_boxes[]; };
layout(set = 0, binding = 3, rgba16f) uniform writeonly image2DArray target;
layout(push_constant) uniform Push { BlurPush p; };
// 0: the paper's one box, 1: the adaptive penumbra's three (a pipeline constant, so that
// llvmpipe, which runs both sides of a branch, reads only what the mode needs).
layout(constant_id = 0) const bool ADAPTIVE = false;
// 0: the horizontal pass (mask rows to row_boxes), 1: the vertical one (its columns to the
// filtered layers).
layout(constant_id = 1) const bool VERTICAL = false;

vec4 fetch(int along, int line, uint layer) {
    if (along < 0 || along >= int(p.params.y)) return vec4(0.0);
    int size = int(p.params.y);
    if (VERTICAL) {
        uvec2 packed = row_boxes[(int(layer) * size + along) * size + line];
        return vec4(unpackHalf2x16(packed.x), unpackHalf2x16(packed.y));
    }
    return texelFetch(mask, ivec3(along, line, layer), 0).rrrg;
}

void store(int along, int line, uint layer, vec4 value) {
    int size = int(p.params.y);
    if (VERTICAL) {
        imageStore(target, ivec3(line, along, layer), value);
    } else {
        row_boxes[(int(layer) * size + line) * size + along] = uvec2(packHalf2x16(value.xy), packHalf2x16(value.zw));
    }
}

void main() {
    int line = int(gl_GlobalInvocationID.x);
    uint layer = gl_GlobalInvocationID.y;
    int size = int(p.params.y);
    if (line >= size || layer >= p.params.z) return;
    OcclusionLayer l = layers[layer];
    if (!ADAPTIVE) {
        // One box over the coverage.
        int radius = int(l.axis_u.w) / 2;
        float sum = 0.0;
        for (int k = -radius; k <= radius; ++k) sum += fetch(k, line, layer).r;
        float scale = 1.0 / float(2 * radius + 1);
        for (int x = 0; x < size; ++x) {
            store(x, line, layer, vec4(sum * scale, 0.0, 0.0, 0.0));
            sum += fetch(x + radius + 1, line, layer).r - fetch(x - radius, line, layer).r;
        }
        return;
    }
    // R passes through (a box of 1); G slides the middle box, B and A the widest.
    int middle = int(l.axis_u.w) / 2, widest = int(l.axis_v.w) / 2;
    vec3 sum = vec3(0.0);
    for (int k = -widest; k <= widest; ++k) {
        vec4 t = fetch(k, line, layer);
        sum += vec3(abs(k) <= middle ? t.g : 0.0, t.ba);
    }
    vec3 scale = 1.0 / vec3(2 * middle + 1, 2 * widest + 1, 2 * widest + 1);
    for (int x = 0; x < size; ++x) {
        store(x, line, layer, vec4(fetch(x, line, layer).r, sum * scale));
        sum += vec3(fetch(x + middle + 1, line, layer).g, fetch(x + widest + 1, line, layer).ba)
            - vec3(fetch(x - middle, line, layer).g, fetch(x - widest, line, layer).ba);
    }
}
