/* Every enumeration value and every struct field kage.h declares, used by name: a host that
 * sets a field or passes a value by name compiles. The test suite compiles this file as C11
 * and as C++17 with -Wall -Wextra -Werror -pedantic (tests/tests/c_header.rs).
 * Regenerate the lists by hand when the header changes: a name missing here is a name a host
 * cannot use. */
#include <stdio.h>

#include "kage.h"

/* Every value of every enumeration, by name. */
static const struct {
  const char *name;
  uint32_t value;
} VALUES[] = {
    {"KAGE_RESULT_OK", (uint32_t)KAGE_RESULT_OK},
    {"KAGE_RESULT_NULL_ARGUMENT", (uint32_t)KAGE_RESULT_NULL_ARGUMENT},
    {"KAGE_RESULT_INVALID_HANDLE", (uint32_t)KAGE_RESULT_INVALID_HANDLE},
    {"KAGE_RESULT_INVALID_VALUE", (uint32_t)KAGE_RESULT_INVALID_VALUE},
    {"KAGE_RESULT_BUFFER_TOO_SMALL", (uint32_t)KAGE_RESULT_BUFFER_TOO_SMALL},
    {"KAGE_RESULT_FILE", (uint32_t)KAGE_RESULT_FILE},
    {"KAGE_RESULT_NO_DEVICE", (uint32_t)KAGE_RESULT_NO_DEVICE},
    {"KAGE_RESULT_UNSUPPORTED", (uint32_t)KAGE_RESULT_UNSUPPORTED},
    {"KAGE_RESULT_VULKAN", (uint32_t)KAGE_RESULT_VULKAN},
    {"KAGE_RESULT_DEVICE_LOST", (uint32_t)KAGE_RESULT_DEVICE_LOST},
    {"KAGE_RESULT_OUT_OF_MEMORY", (uint32_t)KAGE_RESULT_OUT_OF_MEMORY},
    {"KAGE_RESULT_VALIDATION", (uint32_t)KAGE_RESULT_VALIDATION},
    {"KAGE_RESULT_PANIC", (uint32_t)KAGE_RESULT_PANIC},
    {"KAGE_RESULT_INTERNAL", (uint32_t)KAGE_RESULT_INTERNAL},
    {"KAGE_RESULT_BUSY", (uint32_t)KAGE_RESULT_BUSY},
    {"KAGE_RESULT_CANCELLED", (uint32_t)KAGE_RESULT_CANCELLED},
    {"KAGE_TECHNIQUE_UNSHADOWED", (uint32_t)KAGE_TECHNIQUE_UNSHADOWED},
    {"KAGE_TECHNIQUE_SLOAN_SELF", (uint32_t)KAGE_TECHNIQUE_SLOAN_SELF},
    {"KAGE_TECHNIQUE_SLOAN_SCENE", (uint32_t)KAGE_TECHNIQUE_SLOAN_SCENE},
    {"KAGE_TECHNIQUE_TAMURA", (uint32_t)KAGE_TECHNIQUE_TAMURA},
    {"KAGE_TECHNIQUE_TAMURA_PAPER", (uint32_t)KAGE_TECHNIQUE_TAMURA_PAPER},
    {"KAGE_TECHNIQUE_PARALLEL_LIGHTS", (uint32_t)KAGE_TECHNIQUE_PARALLEL_LIGHTS},
    {"KAGE_TECHNIQUE_SHADOW_MAP", (uint32_t)KAGE_TECHNIQUE_SHADOW_MAP},
    {"KAGE_TECHNIQUE_PROBES", (uint32_t)KAGE_TECHNIQUE_PROBES},
    {"KAGE_TECHNIQUE_ASM", (uint32_t)KAGE_TECHNIQUE_ASM},
    {"KAGE_PENUMBRA_FIXED", (uint32_t)KAGE_PENUMBRA_FIXED},
    {"KAGE_PENUMBRA_ADAPTIVE", (uint32_t)KAGE_PENUMBRA_ADAPTIVE},
    {"KAGE_PROBE_LIGHT_SKY", (uint32_t)KAGE_PROBE_LIGHT_SKY},
    {"KAGE_PROBE_LIGHT_SKY_AND_WALLS", (uint32_t)KAGE_PROBE_LIGHT_SKY_AND_WALLS},
    {"KAGE_ASM_TEST_ID", (uint32_t)KAGE_ASM_TEST_ID},
    {"KAGE_ASM_TEST_BIAS", (uint32_t)KAGE_ASM_TEST_BIAS},
    {"KAGE_PROBE_INTERPOLATION_TETRAHEDRAL", (uint32_t)KAGE_PROBE_INTERPOLATION_TETRAHEDRAL},
    {"KAGE_PROBE_INTERPOLATION_TRILINEAR", (uint32_t)KAGE_PROBE_INTERPOLATION_TRILINEAR},
    {"KAGE_STATIC_LIGHTING_UNSHADOWED", (uint32_t)KAGE_STATIC_LIGHTING_UNSHADOWED},
    {"KAGE_STATIC_LIGHTING_SLOAN", (uint32_t)KAGE_STATIC_LIGHTING_SLOAN},
    {"KAGE_PIXEL_FORMAT_RGBA8_SRGB", (uint32_t)KAGE_PIXEL_FORMAT_RGBA8_SRGB},
    {"KAGE_PIXEL_FORMAT_RGBA32F_LINEAR", (uint32_t)KAGE_PIXEL_FORMAT_RGBA32F_LINEAR},
    {"KAGE_PROBE_PLACEMENT_GRID", (uint32_t)KAGE_PROBE_PLACEMENT_GRID},
    {"KAGE_PROBE_PLACEMENT_AUTO", (uint32_t)KAGE_PROBE_PLACEMENT_AUTO},
    {"KAGE_PROBE_PLACEMENT_POSITIONS", (uint32_t)KAGE_PROBE_PLACEMENT_POSITIONS},
    {"KAGE_PROBE_DERING_OFF", (uint32_t)KAGE_PROBE_DERING_OFF},
    {"KAGE_PROBE_DERING_NON_NEGATIVE", (uint32_t)KAGE_PROBE_DERING_NON_NEGATIVE},
    {"KAGE_PROBE_DERING_HANNING", (uint32_t)KAGE_PROBE_DERING_HANNING},
    {"KAGE_PROBE_DERING_LANCZOS", (uint32_t)KAGE_PROBE_DERING_LANCZOS},
    {"KAGE_LIGHT_KIND_POINT", (uint32_t)KAGE_LIGHT_KIND_POINT},
    {"KAGE_LIGHT_KIND_SPOT", (uint32_t)KAGE_LIGHT_KIND_SPOT},
    {"KAGE_ABI_VERSION", (uint32_t)KAGE_ABI_VERSION},
};

/* Every field of kage_context_desc. */
static size_t touch_kage_context_desc(kage_context_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->size;
  bytes += sizeof d->device_name;
  bytes += sizeof d->validation;
  return bytes;
}

/* Every field of kage_vulkan_handles. */
static size_t touch_kage_vulkan_handles(kage_vulkan_handles *d) {
  size_t bytes = 0;
  bytes += sizeof d->size;
  bytes += sizeof d->instance;
  bytes += sizeof d->physical_device;
  bytes += sizeof d->device;
  bytes += sizeof d->queue_family;
  bytes += sizeof d->queue;
  bytes += sizeof d->debug_utils;
  return bytes;
}

/* Every field of kage_technique_desc. */
static size_t touch_kage_technique_desc(kage_technique_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->size;
  bytes += sizeof d->technique;
  bytes += sizeof d->sh_bands;
  bytes += sizeof d->prt_rays;
  bytes += sizeof d->regions;
  bytes += sizeof d->mask_size;
  bytes += sizeof d->penumbra;
  bytes += sizeof d->shadow_map_size;
  bytes += sizeof d->probe_grid;
  bytes += sizeof d->probe_cube_size;
  bytes += sizeof d->probe_light;
  bytes += sizeof d->asm_budget_mb;
  bytes += sizeof d->asm_time_ms;
  bytes += sizeof d->asm_test;
  bytes += sizeof d->probe_placement;
  bytes += sizeof d->probe_candidates;
  bytes += sizeof d->probe_tolerance;
  bytes += sizeof d->probe_positions;
  bytes += sizeof d->probe_position_count;
  bytes += sizeof d->probe_interpolation;
  bytes += sizeof d->probe_bounces;
  bytes += sizeof d->probe_samples;
  bytes += sizeof d->probe_dering;
  bytes += sizeof d->probe_dering_width;
  bytes += sizeof d->probe_statics;
  bytes += sizeof d->dominant_lights;
  bytes += sizeof d->light_map_size;
  bytes += sizeof d->probe_visibility;
  bytes += sizeof d->asm_extra_levels;
  bytes += sizeof d->asm_time_share;
  return bytes;
}

/* Every field of kage_renderer_desc. */
static size_t touch_kage_renderer_desc(kage_renderer_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->size;
  bytes += sizeof d->width;
  bytes += sizeof d->height;
  bytes += sizeof d->technique;
  return bytes;
}

/* Every field of kage_transform. */
static size_t touch_kage_transform(kage_transform *d) {
  size_t bytes = 0;
  bytes += sizeof d->translation;
  bytes += sizeof d->rotation;
  bytes += sizeof d->scale;
  return bytes;
}

/* Every field of kage_light_desc. */
static size_t touch_kage_light_desc(kage_light_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->kind;
  bytes += sizeof d->position;
  bytes += sizeof d->direction;
  bytes += sizeof d->fov_deg;
  bytes += sizeof d->intensity;
  return bytes;
}

/* Every field of kage_camera_desc. */
static size_t touch_kage_camera_desc(kage_camera_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->position;
  bytes += sizeof d->target;
  bytes += sizeof d->up;
  bytes += sizeof d->fov_y_deg;
  return bytes;
}

/* Every field of kage_renderer_stats. */
static size_t touch_kage_renderer_stats(kage_renderer_stats *d) {
  size_t bytes = 0;
  bytes += sizeof d->gpu_bytes;
  bytes += sizeof d->dropped_layers;
  bytes += sizeof d->probes;
  bytes += sizeof d->probe_candidates;
  bytes += sizeof d->probes_inside_geometry;
  return bytes;
}

/* Every field of kage_pass_timing. */
static size_t touch_kage_pass_timing(kage_pass_timing *d) {
  size_t bytes = 0;
  bytes += sizeof d->name;
  bytes += sizeof d->milliseconds;
  return bytes;
}

/* Every field of kage_mesh_desc. */
static size_t touch_kage_mesh_desc(kage_mesh_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->positions;
  bytes += sizeof d->normals;
  bytes += sizeof d->vertex_count;
  bytes += sizeof d->indices;
  bytes += sizeof d->index_count;
  bytes += sizeof d->albedo;
  return bytes;
}

/* Every field of kage_group_desc. */
static size_t touch_kage_group_desc(kage_group_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->name;
  bytes += sizeof d->transform;
  bytes += sizeof d->meshes;
  bytes += sizeof d->mesh_count;
  return bytes;
}

/* Every field of kage_environment_desc. */
static size_t touch_kage_environment_desc(kage_environment_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->pixels;
  bytes += sizeof d->width;
  bytes += sizeof d->height;
  return bytes;
}

/* Every field of kage_scene_desc. */
static size_t touch_kage_scene_desc(kage_scene_desc *d) {
  size_t bytes = 0;
  bytes += sizeof d->size;
  bytes += sizeof d->groups;
  bytes += sizeof d->group_count;
  bytes += sizeof d->environment;
  bytes += sizeof d->camera;
  bytes += sizeof d->lights;
  bytes += sizeof d->light_count;
  return bytes;
}

int main(void) {
  size_t fields = 0;
  kage_context_desc context_desc_value;
  fields += touch_kage_context_desc(&context_desc_value);
  kage_vulkan_handles vulkan_handles_value;
  fields += touch_kage_vulkan_handles(&vulkan_handles_value);
  kage_technique_desc technique_desc_value;
  fields += touch_kage_technique_desc(&technique_desc_value);
  kage_renderer_desc renderer_desc_value;
  fields += touch_kage_renderer_desc(&renderer_desc_value);
  kage_transform transform_value;
  fields += touch_kage_transform(&transform_value);
  kage_camera_desc camera_desc_value;
  fields += touch_kage_camera_desc(&camera_desc_value);
  kage_light_desc light_desc_value;
  fields += touch_kage_light_desc(&light_desc_value);
  kage_renderer_stats renderer_stats_value;
  fields += touch_kage_renderer_stats(&renderer_stats_value);
  kage_pass_timing pass_timing_value;
  fields += touch_kage_pass_timing(&pass_timing_value);
  kage_mesh_desc mesh_desc_value;
  fields += touch_kage_mesh_desc(&mesh_desc_value);
  kage_group_desc group_desc_value;
  fields += touch_kage_group_desc(&group_desc_value);
  kage_environment_desc environment_desc_value;
  fields += touch_kage_environment_desc(&environment_desc_value);
  kage_scene_desc scene_desc_value;
  fields += touch_kage_scene_desc(&scene_desc_value);
  printf("%u values, %u bytes of fields\n", (unsigned)(sizeof VALUES / sizeof VALUES[0]), (unsigned)fields);
  return kage_abi_version() == KAGE_ABI_VERSION ? 0 : 1;
}
