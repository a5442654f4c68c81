// Random numbers and direction sampling for the Monte Carlo reference.
#ifndef KAGE_SAMPLING_GLSL
#define KAGE_SAMPLING_GLSL

// The PCG hash of Jarzynski and Olano, "Hash Functions for GPU Rendering" (JCGT 2020): one
// round of a 32-bit PCG generator with its output permutation; passes BigCrush as a hash.
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A stream of uniform numbers per (seed, pixel or point, sample index): hashing all three makes
// every sample of every batch independent without storing any generator state.
struct Rng {
    uint state;
};

Rng rng_init(uint seed, uint item, uint sample_index) {
    return Rng(pcg_hash(pcg_hash(pcg_hash(seed) + item) + sample_index));
}

// A uniform word: the generator's next state.
uint rng_next_word(inout Rng rng) {
    rng.state = pcg_hash(rng.state);
    return rng.state;
}

// Uniform in [0, 1): the top 24 bits, so the float is exact and never rounds up to 1.
float rng_next(inout Rng rng) {
    return float(rng_next_word(rng) >> 8u) * (1.0 / 16777216.0);
}

// Uniform in [0, n) for n > 0, unbiased: the high word of a word times n, drawn again while the
// low word falls in the 2^32 mod n values that would make some results likelier (Lemire,
// "Fast Random Integer Generation in an Interval", 2019).
uint rng_below(inout Rng rng, uint n) {
    uint reject = (0u - n) % n;
    uint high, low;
    do {
        umulExtended(rng_next_word(rng), n, high, low);
    } while (low < reject);
    return high;
}

// An orthonormal basis around unit n without branches on near-axis normals (Duff et al.,
// "Building an Orthonormal Basis, Revisited", JCGT 2017).
mat3 basis_around(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
    return mat3(t, bt, n);
}

// Cosine-weighted direction about unit n (Malley's method: uniform on the disc, lifted);
// its pdf per unit solid angle is max(dot(n, w), 0) / pi.
vec3 sample_cosine(vec3 n, vec2 u) {
    float r = sqrt(u.x);
    float phi = 2.0 * 3.14159265358979323846 * u.y;
    vec3 local = vec3(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
    return basis_around(n) * local;
}

// Rec. 709 luminance, as engine/src/reference/env_sampling.rs computes it.
float luminance(vec3 rgb) {
    return dot(rgb, vec3(0.2126, 0.7152, 0.0722));
}

// The power heuristic with exponent 2 (Veach 1997) for a sample of pdf `a` against the other
// strategy's `b`, written as a ratio so that large pdfs cannot overflow when squared.
float power_heuristic(float a, float b) {
    if (a <= 0.0) return 0.0;
    float r = b / a;
    return 1.0 / (1.0 + r * r);
}

#endif
