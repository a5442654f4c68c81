#include "common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void expect_result(const char *what, kage_result got, kage_result want, const char *file, int line) {
  if (got == want) return;
  char message[2048] = "";
  kage_last_error_message(message, sizeof message, NULL);
  fprintf(stderr, "%s:%d: %s returned %u, expected %u; last error: %s\n", file, line, what,
          (unsigned)got, (unsigned)want, message);
  exit(1);
}

void require(int condition, const char *what, const char *file, int line) {
  if (condition) return;
  fprintf(stderr, "%s:%d: failed: %s\n", file, line, what);
  exit(1);
}

/* The floor: a 5 x 5 vertex grid, 4 units wide, in XZ (PRT lighting is per vertex, so the
 * floor needs vertices under the box to show its shadow). */
enum { GRID = 5, FLOOR_VERTICES = GRID * GRID, FLOOR_INDICES = (GRID - 1) * (GRID - 1) * 6 };
static float floor_positions[FLOOR_VERTICES * 3];
static float floor_normals[FLOOR_VERTICES * 3];
static uint32_t floor_indices[FLOOR_INDICES];

/* The box: a unit cube, 4 vertices per face so that each face has its own normal. */
static float box_positions[24 * 3];
static float box_normals[24 * 3];
static uint32_t box_indices[36];

enum { ENV_WIDTH = 16, ENV_HEIGHT = 8 };
static float environment[ENV_WIDTH * ENV_HEIGHT * 3];

static void build_floor(void) {
  for (int z = 0; z < GRID; z++) {
    for (int x = 0; x < GRID; x++) {
      float *p = &floor_positions[(z * GRID + x) * 3];
      p[0] = -2.0f + 4.0f * x / (GRID - 1);
      p[1] = 0.0f;
      p[2] = -2.0f + 4.0f * z / (GRID - 1);
      float *n = &floor_normals[(z * GRID + x) * 3];
      n[0] = 0.0f, n[1] = 1.0f, n[2] = 0.0f;
    }
  }
  uint32_t *i = floor_indices;
  for (uint32_t z = 0; z + 1 < GRID; z++) {
    for (uint32_t x = 0; x + 1 < GRID; x++) {
      uint32_t a = z * GRID + x, b = a + 1, c = a + GRID, d = c + 1;
      /* Counter-clockwise seen from +Y. */
      *i++ = a, *i++ = c, *i++ = b;
      *i++ = b, *i++ = c, *i++ = d;
    }
  }
}

static void build_box(void) {
  /* Each face: its normal axis and sign; corners from the two other axes. */
  for (int face = 0; face < 6; face++) {
    int axis = face / 2;
    float sign = face % 2 ? -1.0f : 1.0f;
    int u = (axis + 1) % 3, v = (axis + 2) % 3;
    float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; k++) {
      float *p = &box_positions[(face * 4 + k) * 3];
      float *n = &box_normals[(face * 4 + k) * 3];
      p[axis] = 0.5f * sign;
      /* Mirror the winding on the negative face so both wind counter-clockwise from outside. */
      p[u] = 0.5f * corners[k][0] * sign;
      p[v] = 0.5f * corners[k][1];
      n[0] = n[1] = n[2] = 0.0f;
      n[axis] = sign;
    }
    uint32_t base = (uint32_t)face * 4;
    uint32_t *i = &box_indices[face * 6];
    i[0] = base, i[1] = base + 1, i[2] = base + 2;
    i[3] = base, i[4] = base + 2, i[5] = base + 3;
  }
}

static void build_environment(void) {
  for (int y = 0; y < ENV_HEIGHT; y++) {
    for (int x = 0; x < ENV_WIDTH; x++) {
      float *p = &environment[(y * ENV_WIDTH + x) * 3];
      /* Bright sky, dim ground; a warm patch high up makes the light directional. */
      float sky = y < ENV_HEIGHT / 2 ? 1.0f : 0.15f;
      float sun = (y == 1 && x >= 6 && x <= 9) ? 6.0f : 0.0f;
      p[0] = sky + sun, p[1] = sky + 0.8f * sun, p[2] = sky * 1.2f + 0.5f * sun;
    }
  }
}

/* The box's placement at `x` along the floor. */
static kage_transform box_at(float x) {
  kage_transform t = {{x, 0.5f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}, 1.0f};
  return t;
}

/* The test scene, built from arrays in the host's memory: a grey floor (group 0) and a red box
 * (group 1) standing on it, under a sky brighter above than below. */
kage_scene *make_scene(void) {
  build_floor();
  build_box();
  build_environment();
  kage_mesh_desc floor_mesh = {floor_positions, floor_normals, FLOOR_VERTICES, floor_indices,
                               FLOOR_INDICES, {0.6f, 0.6f, 0.6f}};
  /* No normals: Kage computes them; each face has its own vertices, so they are the faces'. */
  kage_mesh_desc box_mesh = {box_positions, NULL, 24, box_indices, 36, {0.8f, 0.1f, 0.1f}};
  kage_group_desc groups[2] = {
      {"floor", {{0, 0, 0}, {0, 0, 0, 1}, 1.0f}, &floor_mesh, 1},
      {"box", box_at(-1.0f), &box_mesh, 1},
  };
  kage_scene_desc desc = {
      sizeof(kage_scene_desc), groups, 2, {environment, ENV_WIDTH, ENV_HEIGHT}, {{0.0f, 3.0f, 4.0f}, {0.0f, 0.3f, 0.0f}, {0.0f, 1.0f, 0.0f}, 45.0f}, NULL, 0};
  kage_scene *scene = NULL;
  CHECK(kage_scene_create(&desc, &scene));
  return scene;
}

/* The mean column of the box's pixels (red clearly above green), or -1 if none. */
static double box_column(const uint8_t *rgba, unsigned size) {
  double sum = 0.0;
  unsigned count = 0;
  for (unsigned i = 0; i < size * size; i++) {
    const uint8_t *p = &rgba[i * 4];
    if (p[0] > 40 && p[0] > 2 * p[1]) sum += i % size, count++;
  }
  return count ? sum / count : -1.0;
}

static int has_pass(const kage_pass_timing *timings, size_t count, const char *name) {
  for (size_t i = 0; i < count; i++)
    if (strcmp(timings[i].name, name) == 0) return 1;
  return 0;
}

static void run_frames(kage_context *context, kage_scene *scene, const kage_technique_desc *technique,
                       unsigned frames, unsigned size) {
  kage_renderer_desc desc = {sizeof(kage_renderer_desc), size, size, *technique};
  kage_renderer *renderer = NULL;
  CHECK(kage_renderer_create(context, scene, &desc, &renderer));
  uint8_t *rgba8 = malloc((size_t)size * size * 4);
  float *linear = malloc((size_t)size * size * 16);
  REQUIRE(rgba8 && linear);
  double previous = -1.0;
  kage_renderer_stats first_stats = {0};
  for (unsigned frame = 0; frame < frames; frame++) {
    float x = -1.0f + 2.0f * frame / (frames > 1 ? frames - 1 : 1);
    kage_transform t = box_at(x);
    CHECK(kage_renderer_set_group_transform(renderer, 1, &t));
    CHECK(kage_renderer_render(renderer));
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, 1.0f, rgba8, (size_t)size * size * 4));
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, (uint8_t *)linear,
                                    (size_t)size * size * 16));

    int all_equal = 1;
    for (unsigned i = 1; i < size * size; i++) all_equal &= memcmp(&rgba8[i * 4], rgba8, 4) == 0;
    REQUIRE(!all_equal);
    for (unsigned i = 0; i < size * size * 4; i++) REQUIRE(isfinite(linear[i]) && linear[i] >= 0.0f);
    REQUIRE(linear[3] == 1.0f && rgba8[3] == 255);

    double column = box_column(rgba8, size);
    REQUIRE(column >= 0.0);
    if (frame > 0) REQUIRE(column > previous);
    previous = column;

    size_t count = 0;
    CHECK(kage_renderer_timings(renderer, NULL, 0, &count)); /* the count alone */
    REQUIRE(count >= 3 && count <= 16);
    kage_pass_timing timings[16];
    size_t written = 0;
    CHECK(kage_renderer_timings(renderer, timings, 16, &written));
    REQUIRE(written == count);
    double total = 0.0;
    for (size_t i = 0; i < count; i++) {
      REQUIRE(timings[i].milliseconds >= 0.0);
      total += timings[i].milliseconds;
    }
    REQUIRE(total > 0.0);
    /* The frame spans its first pass's start to its last pass's end: never less than the sum of
     * the passes that ran one after another... up to rounding of the tick conversion. */
    double frame_ms = 0.0;
    CHECK(kage_renderer_frame_time(renderer, &frame_ms));
    REQUIRE(frame_ms >= 0.999 * total);
    REQUIRE(has_pass(timings, count, "background") && has_pass(timings, count, "scene") &&
            has_pass(timings, count, "readback"));
    /* The environment's SH projection and Tamura's self-shadowing run when their input changed:
     * in the first frame (moving a group does not change them). */
    int tamura = technique->technique == KAGE_TECHNIQUE_TAMURA;
    if (tamura) REQUIRE(has_pass(timings, count, "occluder_masks"));
    if (frame == 0) REQUIRE(has_pass(timings, count, "sh_project") && (!tamura || has_pass(timings, count, "self_shadow")));
    /* Every object a frame needs exists after the first: the device's allocations stay flat. */
    kage_renderer_stats stats;
    CHECK(kage_renderer_get_stats(renderer, &stats));
    REQUIRE(stats.gpu_bytes > 0 && stats.dropped_layers == 0);
    if (frame == 0) first_stats = stats;
    REQUIRE(stats.gpu_bytes == first_stats.gpu_bytes);
    printf("frame %u: box at column %.1f, %zu passes, %.3f ms (passes %.3f):", frame, column, count, frame_ms, total);
    for (size_t i = 0; i < count; i++) printf(" %s %.3f", timings[i].name, timings[i].milliseconds);
    printf("\n");
  }
  free(rgba8);
  free(linear);
  CHECK(kage_renderer_destroy(renderer));
}

void render_moving_box(kage_context *context, uint32_t technique_kind, unsigned frames, unsigned size) {
  char name[256];
  CHECK(kage_context_device_name(context, name, sizeof name, NULL));
  printf("device: %s\n", name);
  kage_scene *scene = make_scene();
  kage_technique_desc technique;
  CHECK(kage_technique_desc_default(technique_kind, &technique));
  /* Small enough to precompute and render in a moment on a CPU driver. */
  technique.prt_rays = 64;
  technique.regions = 4;
  technique.mask_size = 32;
  technique.shadow_map_size = 64;
  CHECK(kage_precompute(context, scene, &technique));
  run_frames(context, scene, &technique, frames, size);
  CHECK(kage_scene_destroy(scene));
}
