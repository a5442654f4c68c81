#version 460
// ASM lighting with the depth test and slope-scaled bias (include/asm_lights.glsl).
#include "asm_lights.glsl"
