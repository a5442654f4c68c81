// A probe's cube map as one image: face f occupies rows f*n .. f*n + n - 1 of an n x 6n image.
// Face f looks along cube_forward(f) with cube_up(f) at the top of the face and
// cross(forward, up) to the right, as the capture's cameras render it (the same table is
// CUBE_FACES in engine/src/techniques/probes/capture.rs).
#ifndef KAGE_CUBE_GLSL
#define KAGE_CUBE_GLSL

vec3 cube_forward(uint f) {
    const vec3 forward[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0),
                                    vec3(0, 0, 1), vec3(0, 0, -1));
    return forward[f];
}

vec3 cube_up(uint f) {
    const vec3 up[6] = vec3[6](vec3(0, 1, 0), vec3(0, 1, 0), vec3(0, 0, -1), vec3(0, 0, 1),
                               vec3(0, 1, 0), vec3(0, 1, 0));
    return up[f];
}

// Texel (i, row) of the n x 6n image: its face, and its corners on the face plane at distance
// 1, x to the right and y up, each in [-1, 1].
void cube_texel(uvec2 texel, uint n, out uint face, out vec2 lo, out vec2 hi) {
    face = texel.y / n;
    uint i = texel.x, j = texel.y % n;
    lo = vec2(2.0 * float(i) / float(n) - 1.0, 1.0 - 2.0 * float(j + 1) / float(n));
    hi = vec2(2.0 * float(i + 1) / float(n) - 1.0, 1.0 - 2.0 * float(j) / float(n));
}

vec3 cube_direction(uint face, vec2 xy) {
    vec3 forward = cube_forward(face), up = cube_up(face);
    return normalize(forward + xy.x * cross(forward, up) + xy.y * up);
}

// Solid angle of the face rectangle [lo, hi]: with A(x, y) = atan(xy / sqrt(x^2 + y^2 + 1)),
// the solid angle of [0, x] x [0, y] on the plane at distance 1, the rectangle's is
// A(hi) - A(hi.x, lo.y) - A(lo.x, hi.y) + A(lo). Exact: the texels of the six faces add up to
// 4 pi up to float rounding.
float cube_corner(float x, float y) {
    return atan(x * y, sqrt(x * x + y * y + 1.0));
}

float cube_solid_angle(vec2 lo, vec2 hi) {
    return cube_corner(hi.x, hi.y) - cube_corner(hi.x, lo.y) - cube_corner(lo.x, hi.y)
        + cube_corner(lo.x, lo.y);
}

#endif
