#version 460
// ASM lighting with the depth test and slope-scaled bias (include/asm_lights.glsl).
#define KAGE_ALBEDO_MAP_BINDING 5
#include "asm_lights.glsl"
