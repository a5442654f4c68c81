#version 460
// One occlusion layer's mask: an orthographic view along the region's direction, fitted to the
// occluder. The receiver is drawn first, depth only: its surface nearest the light. The occluder
// then marks the texels where it lies in front of that surface (nearer the light by more than
// the bias), so an occluder part below or behind the receiver casts nothing on it, whatever
// the light's direction and however the two touch (contact). The receiver's points a mask
// texel does not hold (below its first surface along the light) are self-shadowed in that
// direction, and eq. (15) weights them by their transfer, which is small there.
#include "occlusion.glsl"

layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(push_constant) uniform Push { MaskPush p; };
layout(location = 0) in vec3 position;
// 1 for the occluder, 0 for the receiver; and the occluder's height above the mask's plane.
layout(location = 0) out flat float weight;
layout(location = 1) out float height;

void main() {
    OcclusionLayer layer = layers[p.layer.x];
    vec3 world = (p.model * vec4(position, 1.0)).xyz;
    height = occlusion_height(layer, world);
    bool occluder = p.layer.y == 1u;
    weight = occluder ? 1.0 : 0.0;
    // Depth grows away from the light; the occluder is drawn `bias` farther than it is.
    float depth = -height + (occluder ? p.bias.x : 0.0);
    gl_Position = vec4(occlusion_uv(layer, world) * 2.0 - 1.0, 0.5 + 0.5 * depth / layer.depth_range, 1.0);
}
