#version 460
// Projects an image of radiance onto 9 SH coefficients per channel, with each texel's exact
// solid angle: an equirectangular environment map or a probe's cube map (p.size.w, one of
// KAGE_SH_MAPPING_*). A small equirectangular map's texels are split into cells (see
// subdivisions), a cube map's texels are its cells. Invocation `lane` of group `g` adds cells
// g*N*T + t*N + lane (t < T, N invocations per group), so neighbouring invocations read
// neighbouring cells; each group writes one partial, which sh_reduce.comp
// adds up.
#include "constants.glsl"
#include "layouts.glsl"
#include "sh.glsl"
#include "envmap.glsl"
#include "cube.glsl"
#include "sh_reduce.glsl"

layout(local_size_x = KAGE_SH_GROUP) in;
layout(set = 0, binding = 0) uniform sampler2D env;
layout(set = 0, binding = 1, std430) writeonly buffer Partials { ShCoeffs partials[]; };
layout(push_constant) uniform Push { ShProjectPush p; };

// Sub-texels per side of an equirectangular texel (see KAGE_SH_MIN_ROWS); 1 for a cube map.
// The host sizes the dispatch with the same number (Mapping::subdivisions).
uint subdivisions(uint h) {
    if (p.size.w == KAGE_SH_MAPPING_CUBE) return 1u;
    return (KAGE_SH_MIN_ROWS + h - 1u) / h;
}

// The direction of cell `cell` (of the texels split n x n) and the solid angle it covers.
void cell_direction(uvec2 cell, uint n, uint w, uint h, out vec3 dir, out float solid_angle) {
    if (p.size.w == KAGE_SH_MAPPING_CUBE) {
        uint face;
        vec2 lo, hi;
        cube_texel(cell, w, face, lo, hi);
        dir = cube_direction(face, 0.5 * (lo + hi));
        solid_angle = cube_solid_angle(lo, hi);
    } else {
        vec2 cells = vec2(w * n, h * n);
        dir = env_uv_to_dir((vec2(cell) + 0.5) / cells);
        // Exact solid angle of an equirectangular cell: (2pi / columns) (cos theta0 - cos theta1).
        solid_angle = (2.0 * KAGE_PI / cells.x)
            * (cos(KAGE_PI * float(cell.y) / cells.y) - cos(KAGE_PI * float(cell.y + 1u) / cells.y));
    }
}

void main() {
    uint w = p.size.x, h = p.size.y;
    uint n = subdivisions(h);
    vec3 acc[9];
    for (int i = 0; i < 9; ++i) acc[i] = vec3(0.0);
    uint first = gl_WorkGroupID.x * KAGE_SH_GROUP * p.size.z + gl_LocalInvocationIndex;
    for (uint t = 0; t < p.size.z; ++t) {
        uint index = first + t * KAGE_SH_GROUP;
        if (index >= w * h * n * n) break;
        uvec2 cell = uvec2(index % (w * n), index / (w * n));
        vec3 dir;
        float solid_angle;
        cell_direction(cell, n, w, h, dir, solid_angle);
        vec3 weighted = texelFetch(env, ivec2(cell / n), 0).rgb * solid_angle;
        float y[9];
        sh9_basis(dir, y);
        for (int i = 0; i < 9; ++i) acc[i] += weighted * y[i];
    }
    sh_workgroup_sum(acc);
    if (gl_LocalInvocationIndex == 0) {
        for (int i = 0; i < 9; ++i) partials[gl_WorkGroupID.x].c[i] = vec4(acc[i], 0.0);
    }
}
