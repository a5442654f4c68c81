// Equirectangular mapping, the one documented in README and engine/src/scene:
// u = atan2(x, -z) / 2pi wrapped into [0, 1), v = acos(y) / pi, row 0 at the top (+Y).
#ifndef KAGE_ENVMAP_GLSL
#define KAGE_ENVMAP_GLSL

vec2 env_dir_to_uv(vec3 d) {
    float u = atan(d.x, -d.z) / (2.0 * 3.14159265358979323846);
    return vec2(fract(u), acos(clamp(d.y, -1.0, 1.0)) / 3.14159265358979323846);
}

vec3 env_uv_to_dir(vec2 uv) {
    float theta = 3.14159265358979323846 * uv.y;
    float phi = 2.0 * 3.14159265358979323846 * uv.x;
    return vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
}

// A world direction as the map sees it when the environment is turned by `angle` radians about
// +Y (counter-clockwise seen from above): the inverse rotation.
vec3 env_world_to_map(vec3 d, float angle) {
    float c = cos(angle), s = sin(angle);
    return vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

// Where direction d (map frame) lies in a table over directions whose texel (i, k) holds
// u = i / W, v = k / (H - 1) (engine/src/frame/irradiance.rs): the shift puts each node at a
// texel centre, so the poles are rows, not points between them.
vec2 irradiance_uv(vec3 d, ivec2 size) {
    vec2 uv = env_dir_to_uv(d);
    return vec2(uv.x + 0.5 / float(size.x), (uv.y * float(size.y - 1) + 0.5) / float(size.y));
}

#endif
