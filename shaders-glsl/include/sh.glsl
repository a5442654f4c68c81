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
