#version 460
// Projects an occluder group along a region's direction onto the receiver's plane: an
// orthographic view whose image is the occlusion layer (1 where the occluder is). Parts of the
// occluder behind that plane (farther from the light than the receiver's centre) are clipped:
// a flat mask has no depth, and without the clip a floor would shadow what stands on it. The
// mask's second channel holds the occluder's height above the plane, towards the light (for the
// adaptive penumbra).
#include "occlusion.glsl"

layout(set = 0, binding = 0, std430) readonly buffer Layers { OcclusionLayer layers[]; };
layout(push_constant) uniform Push { MaskPush p; };
layout(location = 0) in vec3 position;
layout(location = 0) out float height;

void main() {
    OcclusionLayer layer = layers[p.layer.x];
    vec3 world = (p.model * vec4(position, 1.0)).xyz;
    vec3 towards_light = cross(layer.axis_u.xyz, layer.axis_v.xyz);
    height = dot(world - layer.centre.xyz, towards_light);
    gl_ClipDistance[0] = height;
    gl_Position = vec4(occlusion_uv(layer, world) * 2.0 - 1.0, 0.5, 1.0);
}
