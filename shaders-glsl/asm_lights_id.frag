#version 460
// ASM lighting with the polygon-ID test, depth as fallback (include/asm_lights.glsl).
#define ASM_ID_TEST
#define KAGE_ALBEDO_MAP_BINDING 6
#include "asm_lights.glsl"
