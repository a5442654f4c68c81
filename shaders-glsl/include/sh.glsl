// Real spherical harmonics, bands 0..2 (9 coefficients), in the basis and order of
// engine/src/sh.rs: index l*(l+1)+m. The Cartesian formulas are the standard ones; Kage's
// +Y up does not change them (z is just an axis here).
#ifndef KAGE_SH_GLSL
#define KAGE_SH_GLSL

const float KAGE_PI = 3.14159265358979323846;

void sh9_basis(vec3 d, out float y[9]) {
    y[0] = 0.282094791773878;
    y[1] = 0.488602511902920 * d.y;
    y[2] = 0.488602511902920 * d.z;
    y[3] = 0.488602511902920 * d.x;
    y[4] = 1.092548430592079 * d.x * d.y;
    y[5] = 1.092548430592079 * d.y * d.z;
    y[6] = 0.315391565252520 * (3.0 * d.z * d.z - 1.0);
    y[7] = 1.092548430592079 * d.x * d.z;
    y[8] = 0.546274215296040 * (d.x * d.x - d.y * d.y);
}

// All 25 basis functions of bands 0..4 (the PRT transfer uses up to 5 bands), as in
// engine/src/sh (index l(l+1)+m, no Condon–Shortley phase), four to a vec4: y[4j + c] is c_j[c]. Vectors rather than a float[25]: lavapipe
// (Mesa 22.3) miscompiled the accumulation loop when it held local arrays next to the
// traversal's stack, ending the loop over rays early.
void sh25_basis(vec3 d, out vec4 c0, out vec4 c1, out vec4 c2, out vec4 c3, out vec4 c4,
                out vec4 c5, out vec4 c6) {
    float x = d.x, y = d.y, z = d.z;
    float xx = x * x, yy = y * y, zz = z * z;
    c0 = vec4(0.282094791773878, 0.488602511902920 * y, 0.488602511902920 * z,
              0.488602511902920 * x);
    c1 = vec4(1.092548430592079 * x * y, 1.092548430592079 * y * z,
              0.315391565252520 * (3.0 * zz - 1.0), 1.092548430592079 * x * z);
    c2 = vec4(0.546274215296040 * (xx - yy), 0.590043589926644 * y * (3.0 * xx - yy),
              2.890611442640554 * x * y * z, 0.457045799464466 * y * (5.0 * zz - 1.0));
    c3 = vec4(0.373176332590115 * z * (5.0 * zz - 3.0), 0.457045799464466 * x * (5.0 * zz - 1.0),
              1.445305721320277 * z * (xx - yy), 0.590043589926644 * x * (xx - 3.0 * yy));
    c4 = vec4(2.503342941796705 * x * y * (xx - yy), 1.770130769779930 * y * z * (3.0 * xx - yy),
              0.946174695757560 * x * y * (7.0 * zz - 1.0), 0.669046543557289 * y * z * (7.0 * zz - 3.0));
    c5 = vec4(0.105785546915204 * ((35.0 * zz - 30.0) * zz + 3.0),
              0.669046543557289 * x * z * (7.0 * zz - 3.0),
              0.473087347878780 * (xx - yy) * (7.0 * zz - 1.0),
              1.770130769779930 * x * z * (xx - 3.0 * yy));
    c6 = vec4(0.625835735449176 * (xx * (xx - 3.0 * yy) - yy * (3.0 * xx - yy)), 0.0, 0.0, 0.0);
}

// Irradiance E(n) from radiance coefficients (Ramamoorthi & Hanrahan 2001): the clamped cosine
// convolved band by band, A0 = pi, A1 = 2pi/3, A2 = pi/4.
vec3 sh9_irradiance(vec4 c[9], vec3 n) {
    float y[9];
    sh9_basis(n, y);
    const float a1 = 2.0 * KAGE_PI / 3.0;
    const float a2 = KAGE_PI / 4.0;
    vec3 e = KAGE_PI * y[0] * c[0].rgb;
    e += a1 * (y[1] * c[1].rgb + y[2] * c[2].rgb + y[3] * c[3].rgb);
    e += a2 * (y[4] * c[4].rgb + y[5] * c[5].rgb + y[6] * c[6].rgb + y[7] * c[7].rgb + y[8] * c[8].rgb);
    return e;
}

#endif
