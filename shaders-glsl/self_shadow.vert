#version 460
// Vertex-per-texel SH evaluation (Tamura et al. section 4.1): every vertex is drawn as a point
// into its own texel, carrying its transfer vector as attributes.
#include "constants.glsl"
#include "layouts.glsl"

layout(push_constant) uniform Push { SelfShadowPush p; };
layout(location = 0) in vec4 transfer[KAGE_TRANSFER_VEC4];
layout(location = 0) flat out vec4 coefficients[KAGE_TRANSFER_VEC4];

void main() {
    uint texel = p.target.x + uint(gl_VertexIndex);
    vec2 size = vec2(p.target.y, p.target.z);
    vec2 centre = (vec2(texel % p.target.y, texel / p.target.y) + 0.5) / size;
    gl_Position = vec4(centre * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
    coefficients = transfer;
}
