// Vulkan depth d (0 at the near plane, 1 at the far one) of a right-handed perspective
// projection back to view depth: z = near * far / (far - d * (far - near)). The eye's depth
// buffer (ASM analysis) and the lights' maps (shadow_test.glsl) both store it.
#ifndef KAGE_VIEW_DEPTH_GLSL
#define KAGE_VIEW_DEPTH_GLSL

float view_depth(float d, float near, float far) {
    return near * far / (far - d * (far - near));
}

#endif
