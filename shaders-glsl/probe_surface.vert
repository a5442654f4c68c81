#version 460
// Static surfaces in a probe's cube map: each vertex carries its outgoing radiance
// (techniques/probes/capture.rs), interpolated across the triangle as the reference's bounce
// interpolates it (reference_irradiance.comp).
#include "layouts.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { DrawPush draw; };
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 radiance;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec3 vertex_radiance;
layout(location = 1) out vec2 texcoord;

void main() {
    vertex_radiance = radiance.rgb;
    texcoord = uv;
    gl_Position = frame.view_proj * (draw.model * vec4(position, 1.0));
}
