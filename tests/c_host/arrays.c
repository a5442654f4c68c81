/* C host 1: uses only kage.h. Calls every function with NULL and invalid arguments and checks
 * the codes, then builds a scene from arrays, precomputes, moves a group over the frames and
 * checks pixels and pass timings. Exits 0 when all holds.
 *
 * Usage: arrays FRAMES SIZE VALIDATION TECHNIQUE, e.g. `arrays 10 64 1 2` (technique values as
 * in kage_technique); `arrays forget-a-scene` leaks a scene on purpose (the memcheck canary);
 * `arrays out-of-memory` builds a scene under an address-space limit it cannot fit in. */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, mkfifo */
#include "common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

/* Writes a scene file at `path` of one ball under the map `image` (or a constant sky), or of
 * the mesh `obj`. */
static void write_scene(const char *path, const char *image, const char *obj) {
  FILE *f = fopen(path, "w");
  REQUIRE(f != NULL);
  fprintf(f, "{\"camera\": {\"position\": [0, 2, 6], \"target\": [0, 0.5, 0], \"fov_y_deg\": 40},\n");
  if (image) fprintf(f, " \"environment\": {\"image\": \"%s\"},\n", image);
  else fprintf(f, " \"environment\": {\"constant\": [1, 1, 1]},\n");
  if (obj) fprintf(f, " \"groups\": [{\"name\": \"g\", \"meshes\": [{\"obj\": \"%s\", \"albedo\": [0.5, 0.5, 0.5]}]}]}\n", obj);
  else fprintf(f, " \"groups\": [{\"name\": \"g\", \"meshes\": [{\"sphere\": {\"radius\": 1, \"segments\": 8}, \"albedo\": [0.5, 0.5, 0.5]}]}]}\n");
  REQUIRE(fclose(f) == 0);
}

/* A host moves and changes the scene's light: the asm scene's spot light becomes a point light
 * and moves, each change lighting the next frame (shadowmap technique, 16x16), and bad values
 * are refused naming the field. */
static void check_lights(kage_context *context) {
  kage_scene *scene = NULL;
  kage_renderer *renderer = NULL;
  char text[512];
  CHECK(kage_scene_load("asm", &scene));
  kage_renderer_desc desc = {sizeof desc, 16, 16, {0}};
  CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_SHADOW_MAP, &desc.technique));
  CHECK(kage_renderer_create(context, scene, &desc, &renderer));
  static uint8_t before[16 * 16 * 16], after[16 * 16 * 16];
  CHECK(kage_renderer_render(renderer));
  CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, before, sizeof before));
  kage_light_desc light = {KAGE_LIGHT_KIND_POINT, {0, 6, 0}, {0, 0, 0}, 0.0f, {400, 400, 400}};
  CHECK(kage_renderer_set_light(renderer, 0, &light));
  CHECK(kage_renderer_render(renderer));
  CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, after, sizeof after));
  REQUIRE(memcmp(before, after, sizeof before) != 0);
  light.kind = 7;
  EXPECT(kage_renderer_set_light(renderer, 0, &light), KAGE_RESULT_INVALID_VALUE);
  light.kind = KAGE_LIGHT_KIND_SPOT, light.fov_deg = 179.0f;
  EXPECT(kage_renderer_set_light(renderer, 0, &light), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "light 0") != NULL);
  light.fov_deg = 60.0f, light.direction[1] = -1.0f, light.position[0] = NAN;
  EXPECT(kage_renderer_set_light(renderer, 0, &light), KAGE_RESULT_INVALID_VALUE);
  light.position[0] = 0;
  CHECK(kage_renderer_set_light(renderer, 0, &light));
  CHECK(kage_renderer_render(renderer));
  CHECK(kage_renderer_destroy(renderer));
  CHECK(kage_scene_destroy(scene));
}

/* Files that lie or are not files, named by a scene file: an image whose header claims 65536 x
 * 32768 pixels in a few bytes (it once made Kage allocate 24 GiB and abort the host), and a
 * FIFO as the mesh (it once blocked the host forever). Each is KAGE_RESULT_FILE at once, naming
 * what is wrong. */
static void check_hostile_files(void) {
  char dir[] = "/tmp/kage-arrays-XXXXXX", map[256], obj[256], scene_path[256], text[512];
  REQUIRE(mkdtemp(dir) != NULL);
  kage_scene *scene = NULL;
  snprintf(map, sizeof map, "%s/huge.hdr", dir);
  FILE *f = fopen(map, "wb");
  REQUIRE(f != NULL);
  fputs("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32768 +X 65536\n", f);
  fputs("\x80\x80\x80\x81", f);
  REQUIRE(fclose(f) == 0);
  snprintf(scene_path, sizeof scene_path, "%s/huge-map.json", dir);
  write_scene(scene_path, map, NULL);
  EXPECT(kage_scene_load(scene_path, &scene), KAGE_RESULT_FILE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "huge.hdr") != NULL && strstr(text, "65536x32768") != NULL);
  REQUIRE(scene == NULL);

  snprintf(obj, sizeof obj, "%s/pipe.obj", dir);
  REQUIRE(mkfifo(obj, 0600) == 0);
  snprintf(scene_path, sizeof scene_path, "%s/pipe-mesh.json", dir);
  write_scene(scene_path, NULL, obj);
  EXPECT(kage_scene_load(scene_path, &scene), KAGE_RESULT_FILE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "pipe.obj") != NULL && strstr(text, "not a regular file") != NULL);

  unlink(map), unlink(obj), unlink(scene_path);
  snprintf(scene_path, sizeof scene_path, "%s/huge-map.json", dir);
  unlink(scene_path);
  rmdir(dir);
}

/* One triangle under a constant sky, the smallest valid scene. Its arrays are static, so that
 * a check can spoil one field after the call, and the next call makes it whole again. */
static float tri_positions[9];
static uint32_t tri_indices[3];
static float tri_sky[2 * 1 * 3];
static kage_mesh_desc tri_mesh;
static kage_group_desc tri_group;

static kage_scene_desc triangle(void) {
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 0, -1};
  const uint32_t indices[3] = {0, 1, 2};
  memcpy(tri_positions, positions, sizeof positions);
  memcpy(tri_indices, indices, sizeof indices);
  for (int i = 0; i < 6; i++) tri_sky[i] = 1.0f;
  kage_mesh_desc mesh = {tri_positions, NULL, 3, tri_indices, 3, {0.5f, 0.5f, 0.5f}};
  kage_group_desc group = {NULL, {{0, 0, 0}, {0, 0, 0, 1}, 1.0f}, &tri_mesh, 1};
  tri_mesh = mesh, tri_group = group;
  kage_scene_desc desc = {sizeof(kage_scene_desc), &tri_group, 1, {tri_sky, 2, 1}, {{0, 1, 2}, {0, 0, 0}, {0, 1, 0}, 60.0f}, NULL, 0};
  return desc;
}

/* Lights from arrays: a spot light over the triangle, counted, shadowed by the shadowmap and
 * the asm technique (16x16), and changed through kage_renderer_set_light; each
 * renderer writes its last frame as PNG and EXR, and a path Kage cannot write is refused naming
 * what is wrong. */
static void check_scene_lights(kage_context *context) {
  char dir[] = "/tmp/kage-images-XXXXXX", path[256], text[512];
  REQUIRE(mkdtemp(dir) != NULL);
  kage_light_desc spot = {KAGE_LIGHT_KIND_SPOT, {0.3f, 2, -0.3f}, {0, -1, 0}, 90.0f, {20, 20, 20}};
  kage_scene_desc desc = triangle();
  desc.lights = &spot, desc.light_count = 1;
  kage_scene *scene = NULL;
  CHECK(kage_scene_create(&desc, &scene));
  uint32_t count = 0;
  CHECK(kage_scene_light_count(scene, &count));
  REQUIRE(count == 1);
  const uint32_t techniques[2] = {KAGE_TECHNIQUE_SHADOW_MAP, KAGE_TECHNIQUE_ASM};
  for (int t = 0; t < 2; t++) {
    kage_renderer_desc renderer_desc = {sizeof renderer_desc, 16, 16, {0}};
    CHECK(kage_technique_desc_default(techniques[t], &renderer_desc.technique));
    renderer_desc.technique.shadow_map_size = 64;
    kage_renderer *renderer = NULL;
    if (techniques[t] == KAGE_TECHNIQUE_ASM) {
      /* Beyond the 8 extra levels a setting may ask for: refused, naming the limit. */
      renderer_desc.technique.asm_extra_levels = 9;
      EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
      CHECK(kage_last_error_message(text, sizeof text, NULL));
      REQUIRE(strstr(text, "9 extra ASM levels: at most 8") != NULL);
      renderer_desc.technique.asm_extra_levels = 5;
      /* A tile budget of no share of the frame: refused, naming the setting. */
      renderer_desc.technique.asm_time_share = 0.0;
      EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
      CHECK(kage_last_error_message(text, sizeof text, NULL));
      REQUIRE(strstr(text, "ASM time share 0 must be above 0") != NULL);
      renderer_desc.technique.asm_time_share = 0.5;
    }
    CHECK(kage_renderer_create(context, scene, &renderer_desc, &renderer));
    snprintf(path, sizeof path, "%s/frame.png", dir);
    EXPECT(kage_renderer_write_image(renderer, path, 1.0f), KAGE_RESULT_INVALID_VALUE); /* no frame yet */
    static uint8_t lit[16 * 16 * 16], dark[16 * 16 * 16];
    CHECK(kage_renderer_render(renderer));
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, lit, sizeof lit));
    /* PNG and EXR, chosen by the extension (any case); each a file with something in it. */
    const char *names[2] = {"frame.png", "frame.EXR"};
    for (int n = 0; n < 2; n++) {
      struct stat st;
      snprintf(path, sizeof path, "%s/%s", dir, names[n]);
      CHECK(kage_renderer_write_image(renderer, path, 1.0f));
      REQUIRE(stat(path, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0);
      REQUIRE(unlink(path) == 0);
    }
    snprintf(path, sizeof path, "%s/frame.jpg", dir);
    EXPECT(kage_renderer_write_image(renderer, path, 1.0f), KAGE_RESULT_INVALID_VALUE);
    CHECK(kage_last_error_message(text, sizeof text, NULL));
    REQUIRE(strstr(text, "\".jpg\"") != NULL);
    snprintf(path, sizeof path, "%s/frame.png", dir);
    EXPECT(kage_renderer_write_image(renderer, path, NAN), KAGE_RESULT_INVALID_VALUE);
    snprintf(path, sizeof path, "%s/no-such-folder/frame.png", dir);
    EXPECT(kage_renderer_write_image(renderer, path, 1.0f), KAGE_RESULT_FILE);
    CHECK(kage_last_error_message(text, sizeof text, NULL));
    REQUIRE(strstr(text, path) != NULL);
    EXPECT(kage_renderer_write_image(renderer, NULL, 1.0f), KAGE_RESULT_NULL_ARGUMENT);
    EXPECT(kage_renderer_write_image(NULL, path, 1.0f), KAGE_RESULT_NULL_ARGUMENT);
    /* The light lights the frame: turned off, the picture changes. */
    kage_light_desc off = spot;
    off.intensity[0] = off.intensity[1] = off.intensity[2] = 0.0f;
    CHECK(kage_renderer_set_light(renderer, 0, &off));
    CHECK(kage_renderer_render(renderer));
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, dark, sizeof dark));
    REQUIRE(memcmp(lit, dark, sizeof lit) != 0);
    EXPECT(kage_renderer_set_light(renderer, 1, &off), KAGE_RESULT_INVALID_VALUE); /* one light */
    CHECK(kage_renderer_destroy(renderer));
  }
  CHECK(kage_scene_destroy(scene));
  REQUIRE(rmdir(dir) == 0);
}

/* The address space this process uses, in bytes. */
static size_t address_space_used(void) {
  FILE *f = fopen("/proc/self/statm", "r");
  unsigned long pages = 0;
  REQUIRE(f != NULL && fscanf(f, "%lu", &pages) == 1);
  fclose(f);
  return (size_t)pages * (size_t)sysconf(_SC_PAGESIZE);
}

/* kage_scene_create with the address space limited to what is used now and `headroom` bytes
 * more (as `ulimit -v` or a container's limit would), the limit restored after. */
static kage_result create_within(const kage_scene_desc *desc, size_t headroom, kage_scene **scene) {
  struct rlimit old, limited;
  REQUIRE(getrlimit(RLIMIT_AS, &old) == 0);
  limited = old;
  limited.rlim_cur = address_space_used() + headroom;
  REQUIRE(setrlimit(RLIMIT_AS, &limited) == 0);
  kage_result result = kage_scene_create(desc, scene);
  REQUIRE(setrlimit(RLIMIT_AS, &old) == 0);
  return result;
}

/* A mesh within Kage's limits whose copies the machine cannot hold: KAGE_RESULT_OUT_OF_MEMORY
 * naming what did not fit, not an abort of the host ("memory allocation failed"). First the
 * copy of the positions does not fit; then it does, but the normals Kage computes do not. */
static int out_of_memory(void) {
  enum { VERTICES = 100 * 1000 * 1000 }; /* 1.2 GB of positions */
  /* Zeros never written: address space, not memory. Only three vertices are used. */
  float *positions = calloc((size_t)VERTICES * 3, sizeof(float));
  REQUIRE(positions != NULL);
  static uint32_t indices[3] = {0, 1, 2};
  static float sky[6] = {1, 1, 1, 1, 1, 1};
  kage_mesh_desc mesh = {positions, NULL, VERTICES, indices, 3, {0.5f, 0.5f, 0.5f}};
  kage_group_desc group = {NULL, {{0, 0, 0}, {0, 0, 0, 1}, 1.0f}, &mesh, 1};
  kage_scene_desc desc = {sizeof desc, &group, 1, {sky, 2, 1}, {{0, 1, 2}, {0, 0, 0}, {0, 1, 0}, 60.0f}, NULL, 0};
  kage_scene *scene = NULL;
  char text[512];
  const size_t spare = (size_t)256 << 20, positions_bytes = (size_t)VERTICES * 12;
  EXPECT(create_within(&desc, spare, &scene), KAGE_RESULT_OUT_OF_MEMORY);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "out of host memory") && strstr(text, "positions"));
  EXPECT(create_within(&desc, positions_bytes + spare, &scene), KAGE_RESULT_OUT_OF_MEMORY);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "out of host memory") && strstr(text, "normals"));
  REQUIRE(scene == NULL);
  free(positions);
  printf("%s\nok\n", text);
  return 0;
}

/* Every function with a NULL handle or argument, and a few invalid values. */
static void check_bad_arguments(kage_context *context) {
  char text[256];
  size_t length = 0;
  kage_context *no_context = (kage_context *)1;
  kage_scene *no_scene = (kage_scene *)1;
  kage_renderer *no_renderer = (kage_renderer *)1;

  /* The ABI version, and a desc from a host compiled against another kage.h: an error, not a
   * misread struct. */
  REQUIRE(kage_abi_version() == KAGE_ABI_VERSION);
  REQUIRE(kage_version() != NULL && strlen(kage_version()) > 0);

  /* Contexts. */
  kage_context_desc context_desc = {sizeof(kage_context_desc), NULL, false};
  context_desc.size = sizeof(kage_context_desc) - 8;
  kage_context *made = no_context;
  EXPECT(kage_context_create(&context_desc, &made), KAGE_RESULT_INVALID_VALUE);
  context_desc.size = sizeof(kage_context_desc);
  EXPECT(kage_context_create(NULL, &made), KAGE_RESULT_NULL_ARGUMENT);
  REQUIRE(made == NULL); /* out-handles are NULL after a failure */
  EXPECT(kage_context_create(&context_desc, NULL), KAGE_RESULT_NULL_ARGUMENT);
  context_desc.device_name = "no such device anywhere";
  EXPECT(kage_context_create(&context_desc, &made), KAGE_RESULT_NO_DEVICE);
  kage_vulkan_handles handles = {sizeof(kage_vulkan_handles), NULL, NULL, NULL, 0, NULL, false};
  EXPECT(kage_context_create_from_vulkan(NULL, &made), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_context_create_from_vulkan(&handles, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_context_create_from_vulkan(&handles, &made), KAGE_RESULT_NULL_ARGUMENT);
  handles.size -= 8; /* an older host's shorter struct: refused before its handles are read */
  EXPECT(kage_context_create_from_vulkan(&handles, &made), KAGE_RESULT_INVALID_VALUE);
  handles.size += 8;
  EXPECT(kage_context_destroy(NULL), KAGE_RESULT_OK);
  EXPECT(kage_context_device_name(NULL, text, sizeof text, &length), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_context_device_name(context, NULL, sizeof text, &length), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_context_device_name(context, text, 2, &length), KAGE_RESULT_BUFFER_TOO_SMALL);
  REQUIRE(strlen(text) == 1 && length > 1);

  /* A count query, NULL with capacity 0, is answered with OK; a short array is too small. */
  length = 0;
  CHECK(kage_context_device_name(context, NULL, 0, &length));
  REQUIRE(length > 1);

  /* The last error message itself. */
  EXPECT(kage_last_error_message(NULL, sizeof text, NULL), KAGE_RESULT_NULL_ARGUMENT);
  length = 0;
  CHECK(kage_last_error_message(NULL, 0, &length));
  REQUIRE(length > 0);
  EXPECT(kage_last_error_message(text, 0, &length), KAGE_RESULT_BUFFER_TOO_SMALL);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "bytes do not hold") != NULL); /* still the device name's failure */
  REQUIRE(strlen(text) == length);

  /* Scenes. */
  kage_scene *scene = NULL;
  EXPECT(kage_scene_load(NULL, &scene), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_scene_load("teapot", NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_scene_load("/nonexistent/scene.json", &scene), KAGE_RESULT_FILE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "/nonexistent/scene.json") != NULL);
  EXPECT(kage_scene_load("no-such-builtin", &scene), KAGE_RESULT_INVALID_VALUE);
  /* Existing paths that are no scene file: a folder, a device. */
  EXPECT(kage_scene_load("/tmp", &scene), KAGE_RESULT_FILE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "/tmp") != NULL);
  EXPECT(kage_scene_load("/dev/zero", &scene), KAGE_RESULT_FILE);
  EXPECT(kage_scene_create(NULL, &scene), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_scene_destroy(NULL), KAGE_RESULT_OK);
  EXPECT(kage_scene_group_count(NULL, NULL), KAGE_RESULT_NULL_ARGUMENT);

  kage_scene_desc desc = triangle();
  CHECK(kage_scene_create(&desc, &scene));
  EXPECT(kage_scene_create(&desc, NULL), KAGE_RESULT_NULL_ARGUMENT);
  CHECK(kage_scene_destroy(scene));
  /* A destroyed handle is caught, not dereferenced. */
  EXPECT(kage_scene_destroy(scene), KAGE_RESULT_INVALID_HANDLE);
  uint32_t count = 0;
  EXPECT(kage_scene_group_count(scene, &count), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_scene_group_count(no_scene, &count), KAGE_RESULT_INVALID_HANDLE);

  /* Bad data, one field at a time on a fresh triangle. */
  desc = triangle(), tri_positions[4] = NAN;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), tri_indices[2] = 3;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), tri_mesh.index_count = 2;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), tri_mesh.positions = NULL;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_NULL_ARGUMENT);
  desc = triangle(), tri_mesh.albedo[1] = 2.0f;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), tri_group.transform.scale = 0.0f;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), desc.environment.width = 1, desc.environment.height = 2; /* not 2:1 */
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), desc.camera.target[1] = 1, desc.camera.target[2] = 2; /* target = position */
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), desc.group_count = 0;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  desc = triangle(), desc.groups = NULL;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_NULL_ARGUMENT);
  desc = triangle(), desc.size -= 8; /* an older host's shorter struct */
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  /* Counts beyond what Kage represents, refused before the arrays behind them are read or
   * copied (a 4-billion-vertex copy of a 3-vertex array once aborted the host), naming the
   * field, the value and the limit. */
  desc = triangle(), tri_mesh.vertex_count = 0xFFFFFFFFu;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "desc->groups[0].meshes[0].vertex_count") && strstr(text, "4294967295") &&
          strstr(text, "134217727"));
  desc = triangle(), tri_mesh.index_count = 0xFFFFFFFFu;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "meshes[0].index_count") && strstr(text, "4294967295") && strstr(text, "268435456"));
  desc = triangle(), desc.environment.width = 65536, desc.environment.height = 32768;
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "desc->environment") && strstr(text, "65536x32768") && strstr(text, "16384x8192"));
  /* Lights: checked as a scene file's are, with the same messages. */
  {
    kage_light_desc spot = {KAGE_LIGHT_KIND_SPOT, {0, 2, 0}, {0, -1, 0}, 179.0f, {1, 1, 1}};
    desc = triangle(), desc.lights = &spot, desc.light_count = 1;
    EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
    CHECK(kage_last_error_message(text, sizeof text, NULL));
    REQUIRE(strstr(text, "light 0: spot light fov_deg must be in (0, 170]") != NULL);
    spot.fov_deg = 60.0f, spot.kind = 7;
    EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
    CHECK(kage_last_error_message(text, sizeof text, NULL));
    REQUIRE(strstr(text, "desc->lights[0].kind 7") != NULL);
    desc.lights = NULL;
    EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_NULL_ARGUMENT);
  }
  desc = triangle(), tri_group.transform.translation[0] = 1e20f; /* finite, beyond the extent */
  EXPECT(kage_scene_create(&desc, &scene), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "group 0") != NULL && strstr(text, "1e6") != NULL);
  /* A quaternion of any length is its rotation, in a scene as in a moved group: the renderer
   * made from it draws (it once failed, naming a rotation [0, 0, 0, 0] never passed). */
  desc = triangle(), tri_group.transform.rotation[0] = 1e20f, tri_group.transform.rotation[3] = 0;
  CHECK(kage_scene_create(&desc, &scene));
  {
    kage_technique_desc unshadowed;
    CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_UNSHADOWED, &unshadowed));
    kage_renderer_desc long_desc = {sizeof(kage_renderer_desc), 8, 8, unshadowed};
    kage_renderer *drawn = NULL;
    CHECK(kage_renderer_create(context, scene, &long_desc, &drawn));
    CHECK(kage_renderer_render(drawn));
    CHECK(kage_renderer_destroy(drawn));
  }
  CHECK(kage_scene_destroy(scene));
  desc = triangle();
  CHECK(kage_scene_create(&desc, &scene));
  CHECK(kage_scene_group_count(scene, &count));
  REQUIRE(count == 1);
  EXPECT(kage_scene_group_count(scene, NULL), KAGE_RESULT_NULL_ARGUMENT);
  CHECK(kage_scene_light_count(scene, &count));
  REQUIRE(count == 0);
  EXPECT(kage_scene_light_count(scene, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_scene_light_count(NULL, &count), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_scene_light_count(no_scene, &count), KAGE_RESULT_INVALID_HANDLE);

  /* Techniques and precomputation. */
  kage_technique_desc technique;
  EXPECT(kage_technique_desc_default(KAGE_TECHNIQUE_TAMURA, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_technique_desc_default(99, &technique), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_TAMURA, &technique));
  REQUIRE(technique.sh_bands == 3 && technique.regions == 32);
  EXPECT(kage_precompute(NULL, scene, &technique), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_precompute(context, NULL, &technique), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_precompute(context, scene, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_precompute(context, (kage_scene *)context, &technique), KAGE_RESULT_INVALID_HANDLE);
  technique.sh_bands = 9;
  EXPECT(kage_precompute(context, scene, &technique), KAGE_RESULT_INVALID_VALUE);
  technique.sh_bands = 3;
  technique.regions = 0;
  EXPECT(kage_precompute(context, scene, &technique), KAGE_RESULT_INVALID_VALUE);
  technique.regions = 4;
  technique.penumbra = 7;
  EXPECT(kage_precompute(context, scene, &technique), KAGE_RESULT_INVALID_VALUE);
  technique.penumbra = KAGE_PENUMBRA_FIXED;

  /* Renderers. */
  kage_renderer *renderer = NULL;
  kage_renderer_desc renderer_desc = {sizeof(kage_renderer_desc), 8, 8, technique};
  EXPECT(kage_renderer_create(NULL, scene, &renderer_desc, &renderer), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_create(context, NULL, &renderer_desc, &renderer), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_create(context, scene, NULL, &renderer), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, NULL), KAGE_RESULT_NULL_ARGUMENT);
  renderer_desc.size -= 8; /* an older host's shorter struct */
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  renderer_desc.size += 8;
  renderer_desc.technique.size += 8;
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  renderer_desc.technique.size -= 8;
  EXPECT(kage_renderer_create(no_context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_HANDLE);
  /* Tamura before its precomputation. */
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "precompute") != NULL);
  renderer_desc.technique.technique = 42;
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  renderer_desc.technique.technique = KAGE_TECHNIQUE_UNSHADOWED;
  renderer_desc.width = 0;
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  renderer_desc.width = 8;
  /* The shadow-map techniques need lights, which the triangle has none of. */
  renderer_desc.technique.technique = KAGE_TECHNIQUE_SHADOW_MAP;
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  /* More probe positions than Kage takes, refused before the array is read. */
  {
    kage_renderer_desc probes = renderer_desc;
    const float one[3] = {0, 0.5f, 0};
    CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_PROBES, &probes.technique));
    probes.technique.probe_placement = KAGE_PROBE_PLACEMENT_POSITIONS;
    probes.technique.probe_positions = one, probes.technique.probe_position_count = 0xFFFFFFFFu;
    EXPECT(kage_renderer_create(context, scene, &probes, &renderer), KAGE_RESULT_INVALID_VALUE);
    CHECK(kage_last_error_message(text, sizeof text, NULL));
    REQUIRE(strstr(text, "probe_position_count") && strstr(text, "4294967295"));
  }
  renderer_desc.technique.technique = KAGE_TECHNIQUE_UNSHADOWED;
  CHECK(kage_renderer_create(context, scene, &renderer_desc, &renderer));

  kage_transform transform = {{0, 0, 0}, {0, 0, 0, 1}, 1.0f};
  EXPECT(kage_renderer_set_group_transform(NULL, 0, &transform), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_group_transform(renderer, 0, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_group_transform(no_renderer, 0, &transform), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_renderer_set_group_transform(renderer, 1, &transform), KAGE_RESULT_INVALID_VALUE);
  transform.translation[0] = INFINITY;
  EXPECT(kage_renderer_set_group_transform(renderer, 0, &transform), KAGE_RESULT_INVALID_VALUE);
  transform.translation[0] = 1e20f; /* finite, but beyond the scene extent */
  EXPECT(kage_renderer_set_group_transform(renderer, 0, &transform), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "group 0") != NULL && strstr(text, "1e6") != NULL);
  transform.translation[0] = 0;
  transform.rotation[3] = 0;
  EXPECT(kage_renderer_set_group_transform(renderer, 0, &transform), KAGE_RESULT_INVALID_VALUE);
  transform.rotation[3] = 1;
  CHECK(kage_renderer_set_group_transform(renderer, 0, &transform));

  kage_camera_desc camera = {{0, 1, 2}, {0, 0, 0}, {0, 1, 0}, 60.0f};
  EXPECT(kage_renderer_set_camera(NULL, &camera), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_camera(renderer, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_camera(no_renderer, &camera), KAGE_RESULT_INVALID_HANDLE);
  camera.fov_y_deg = 180.0f;
  EXPECT(kage_renderer_set_camera(renderer, &camera), KAGE_RESULT_INVALID_VALUE);
  camera.fov_y_deg = 60.0f;
  camera.target[1] = 1, camera.target[2] = 2; /* target on the position */
  EXPECT(kage_renderer_set_camera(renderer, &camera), KAGE_RESULT_INVALID_VALUE);
  camera.target[1] = 0, camera.target[2] = 0;
  CHECK(kage_renderer_set_camera(renderer, &camera));
  /* Lights: the triangle has none to replace. */
  kage_light_desc light = {KAGE_LIGHT_KIND_POINT, {0, 2, 0}, {0, -1, 0}, 60.0f, {1, 1, 1}};
  EXPECT(kage_renderer_set_light(NULL, 0, &light), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_light(renderer, 0, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_light(no_renderer, 0, &light), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_renderer_set_light(renderer, 0, &light), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_last_error_message(text, sizeof text, NULL));
  REQUIRE(strstr(text, "light 0 does not exist") != NULL);
  EXPECT(kage_renderer_set_env_rotation(NULL, 0.5f), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_set_env_rotation(no_renderer, 0.5f), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_renderer_set_env_rotation(renderer, NAN), KAGE_RESULT_INVALID_VALUE);
  CHECK(kage_renderer_set_env_rotation(renderer, 0.5f));
  kage_renderer_stats stats;
  EXPECT(kage_renderer_get_stats(NULL, &stats), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_get_stats(renderer, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_get_stats(no_renderer, &stats), KAGE_RESULT_INVALID_HANDLE);
  CHECK(kage_renderer_get_stats(renderer, &stats));
  REQUIRE(stats.gpu_bytes > 0 && stats.dropped_layers == 0);
  {
    /* Not the probes technique: no lookups. A size from another kage.h is refused. */
    kage_probe_lookups lookups = {sizeof(kage_probe_lookups), 9, 9, 9, 9};
    EXPECT(kage_renderer_get_probe_lookups(NULL, &lookups), KAGE_RESULT_NULL_ARGUMENT);
    EXPECT(kage_renderer_get_probe_lookups(renderer, NULL), KAGE_RESULT_NULL_ARGUMENT);
    EXPECT(kage_renderer_get_probe_lookups(no_renderer, &lookups), KAGE_RESULT_INVALID_HANDLE);
    lookups.size = 8;
    EXPECT(kage_renderer_get_probe_lookups(renderer, &lookups), KAGE_RESULT_INVALID_VALUE);
    REQUIRE(lookups.lookups == 9);
    lookups.size = sizeof(kage_probe_lookups);
    CHECK(kage_renderer_get_probe_lookups(renderer, &lookups));
    REQUIRE(lookups.lookups == 0 && lookups.renormalised == 0 && lookups.nearest == 0 && lookups.unweighted == 0);
  }

  uint8_t pixels[8 * 8 * 16];
  size_t passes = 99;
  kage_pass_timing timing;
  EXPECT(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, 1.0f, pixels, sizeof pixels),
         KAGE_RESULT_INVALID_VALUE); /* no frame yet */
  CHECK(kage_renderer_timings(renderer, NULL, 0, &passes));
  REQUIRE(passes == 0);
  {
    double frame_ms = 0.0;
    CHECK(kage_renderer_frame_time(renderer, &frame_ms));
    REQUIRE(frame_ms == -1.0); /* no frame yet */
    EXPECT(kage_renderer_frame_time(renderer, NULL), KAGE_RESULT_NULL_ARGUMENT);
    EXPECT(kage_renderer_frame_time(NULL, &frame_ms), KAGE_RESULT_NULL_ARGUMENT);
  }
  {
    float exposure = 0.0f;
    EXPECT(kage_renderer_auto_exposure(renderer, &exposure), KAGE_RESULT_INVALID_VALUE); /* no frame yet */
  }
  EXPECT(kage_renderer_render(NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_render((kage_renderer *)scene), KAGE_RESULT_INVALID_HANDLE);
  CHECK(kage_renderer_render(renderer));
  /* A quaternion of any length is its rotation: 1e20 along X draws what 1 along X draws. */
  {
    static uint8_t unit[8 * 8 * 4], long_one[8 * 8 * 4];
    kage_transform turned = {{0, 0, 0}, {1, 0, 0, 0}, 1.0f};
    CHECK(kage_renderer_set_group_transform(renderer, 0, &turned));
    CHECK(kage_renderer_render(renderer));
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, 1.0f, unit, sizeof unit));
    turned.rotation[0] = 1e20f;
    CHECK(kage_renderer_set_group_transform(renderer, 0, &turned));
    CHECK(kage_renderer_render(renderer));
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, 1.0f, long_one, sizeof long_one));
    REQUIRE(memcmp(unit, long_one, sizeof unit) == 0);
    CHECK(kage_renderer_set_group_transform(renderer, 0, &transform));
  }
  EXPECT(kage_renderer_read_pixels(NULL, KAGE_PIXEL_FORMAT_RGBA8_SRGB, 1.0f, pixels, sizeof pixels),
         KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, 1.0f, NULL, sizeof pixels),
         KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_read_pixels(renderer, 5, 1.0f, pixels, sizeof pixels), KAGE_RESULT_INVALID_VALUE);
  EXPECT(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, NAN, pixels, sizeof pixels),
         KAGE_RESULT_INVALID_VALUE);
  EXPECT(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, pixels, 8 * 8 * 16 - 1),
         KAGE_RESULT_BUFFER_TOO_SMALL);
  CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA32F_LINEAR, 1.0f, pixels, sizeof pixels));
  /* The auto exposure brings the frame's log-average luminance to 0.18, as documented. */
  {
    float exposure = 0.0f;
    EXPECT(kage_renderer_auto_exposure(NULL, &exposure), KAGE_RESULT_NULL_ARGUMENT);
    EXPECT(kage_renderer_auto_exposure(renderer, NULL), KAGE_RESULT_NULL_ARGUMENT);
    CHECK(kage_renderer_auto_exposure(renderer, &exposure));
    const float *linear = (const float *)pixels;
    double log_sum = 0.0;
    for (unsigned i = 0; i < 8 * 8; i++) {
      const float *p = &linear[4 * i];
      log_sum += log(1e-4 + 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
    }
    double average = exp(log_sum / (8 * 8));
    REQUIRE(fabs(exposure * average - 0.18) < 1e-4);
    static uint8_t exposed[8 * 8 * 4];
    CHECK(kage_renderer_read_pixels(renderer, KAGE_PIXEL_FORMAT_RGBA8_SRGB, exposure, exposed, sizeof exposed));
  }
  EXPECT(kage_renderer_timings(NULL, &timing, 1, &passes), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_timings(renderer, &timing, 1, NULL), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_timings(renderer, NULL, 1, &passes), KAGE_RESULT_NULL_ARGUMENT);
  EXPECT(kage_renderer_timings(renderer, &timing, 1, &passes), KAGE_RESULT_BUFFER_TOO_SMALL);
  REQUIRE(passes > 1 && strlen(timing.name) > 0);
  passes = 0;
  CHECK(kage_renderer_timings(renderer, NULL, 0, &passes)); /* the count alone */
  REQUIRE(passes > 1);
  EXPECT(kage_renderer_timings(renderer, &timing, 0, &passes), KAGE_RESULT_BUFFER_TOO_SMALL);
  EXPECT(kage_renderer_destroy(NULL), KAGE_RESULT_OK);
  EXPECT(kage_renderer_destroy((kage_renderer *)scene), KAGE_RESULT_INVALID_HANDLE);
  CHECK(kage_renderer_destroy(renderer));
  EXPECT(kage_renderer_destroy(renderer), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_context_destroy(no_context), KAGE_RESULT_INVALID_HANDLE);
  /* A destroyed context's handle stays dead when another is made in its place. */
  {
    kage_context_desc again = {sizeof(kage_context_desc), NULL, false};
    kage_context *first = NULL, *second = NULL;
    CHECK(kage_context_create(&again, &first));
    CHECK(kage_context_destroy(first));
    CHECK(kage_context_create(&again, &second));
    EXPECT(kage_context_destroy(first), KAGE_RESULT_INVALID_HANDLE);
    CHECK(kage_context_destroy(second));
  }
  CHECK(kage_scene_destroy(scene));
}

/* What a progress callback heard; it answers "stop" at its `stop_at`-th call (0: never). */
typedef struct {
  int calls;
  double last;
  int stop_at;
} progress_log;

static bool hear(void *user, double fraction) {
  progress_log *log = user;
  log->calls++;
  REQUIRE(fraction >= log->last && fraction <= 1.0);
  log->last = fraction;
  return log->calls != log->stop_at;
}

/* kage_precompute_with: a progress callback that cancels, and the disk cache. */
static void check_precompute_options(kage_context *context) {
  kage_scene *scene = make_scene();
  kage_technique_desc technique;
  CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_SLOAN_SELF, &technique));
  technique.prt_rays = 64;
  kage_renderer_desc renderer_desc = {sizeof(kage_renderer_desc), 8, 8, technique};
  kage_renderer *renderer = NULL;
  progress_log log = {0, 0.0, 1};
  kage_precompute_options options = {sizeof(kage_precompute_options), NULL, hear, &log};
  EXPECT(kage_precompute_with(context, scene, &technique, &options), KAGE_RESULT_CANCELLED);
  REQUIRE(log.calls == 1);
  /* Cancelled before it had a transfer: the scene still has none. */
  EXPECT(kage_renderer_create(context, scene, &renderer_desc, &renderer), KAGE_RESULT_INVALID_VALUE);
  options.size = 3;
  EXPECT(kage_precompute_with(context, scene, &technique, &options), KAGE_RESULT_INVALID_VALUE);
  options.size = sizeof(kage_precompute_options);

  /* Computed and written once, with progress up to 1; read back the second time, silently. */
  char dir[] = "/tmp/kage-c-cache-XXXXXX";
  REQUIRE(mkdtemp(dir) != NULL);
  options.cache_dir = dir;
  log = (progress_log){0, 0.0, 0};
  CHECK(kage_precompute_with(context, scene, &technique, &options));
  REQUIRE(log.calls >= 2 && log.last == 1.0);
  log = (progress_log){0, 0.0, 0};
  CHECK(kage_precompute_with(context, scene, &technique, &options));
  REQUIRE(log.calls == 0);
  CHECK(kage_renderer_create(context, scene, &renderer_desc, &renderer));
  CHECK(kage_renderer_render(renderer));
  CHECK(kage_renderer_destroy(renderer));
  /* One cache file, which goes with its folder. */
  char command[128];
  snprintf(command, sizeof command, "test $(ls %s | wc -l) -eq 1 && rm -r %s", dir, dir);
  REQUIRE(system(command) == 0);
  CHECK(kage_scene_destroy(scene));
}

/* kage_renderer_create_with: the light probes' capture heard probe by probe, and cancelled. */
static void check_renderer_progress(kage_context *context) {
  /* The room: its probes' grid lies inside it (the arrays scene's static box would hold them). */
  kage_scene *scene = NULL;
  CHECK(kage_scene_load("probe-room", &scene));
  kage_technique_desc technique;
  CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_PROBES, &technique));
  technique.probe_placement = KAGE_PROBE_PLACEMENT_GRID;
  technique.probe_grid[0] = technique.probe_grid[1] = technique.probe_grid[2] = 2;
  technique.probe_cube_size = 8;
  technique.probe_light = KAGE_PROBE_LIGHT_SKY;
  kage_renderer_desc desc = {sizeof(kage_renderer_desc), 8, 8, technique};
  kage_renderer *renderer = NULL;
  progress_log log = {0, 0.0, 3};
  EXPECT(kage_renderer_create_with(context, scene, &desc, hear, &log, &renderer), KAGE_RESULT_CANCELLED);
  REQUIRE(log.calls == 3 && renderer == NULL);
  /* Eight probes: a call before each capture, one before the placement, one at the end. */
  log = (progress_log){0, 0.0, 0};
  CHECK(kage_renderer_create_with(context, scene, &desc, hear, &log, &renderer));
  REQUIRE(log.calls == 10 && log.last == 1.0);
  CHECK(kage_renderer_render(renderer));
  /* probe-room's bunny hops: any instant of its motion renders; a time must be finite. */
  CHECK(kage_renderer_set_time(renderer, 0.25f));
  CHECK(kage_renderer_render(renderer));
  /* One lookup per frame for the one moving group, the bunny. */
  {
    kage_probe_lookups lookups = {sizeof(kage_probe_lookups), 0, 0, 0, 0};
    CHECK(kage_renderer_get_probe_lookups(renderer, &lookups));
    REQUIRE(lookups.lookups == 2);
  }
  EXPECT(kage_renderer_set_time(renderer, NAN), KAGE_RESULT_INVALID_VALUE);
  EXPECT(kage_renderer_set_time(NULL, 0.0f), KAGE_RESULT_NULL_ARGUMENT);
  CHECK(kage_renderer_destroy(renderer));
  CHECK(kage_scene_destroy(scene));
}

int main(int argc, char **argv) {
  if (argc == 2 && strcmp(argv[1], "forget-a-scene") == 0) {
    /* The canary of the memcheck test: valgrind must report this scene as lost, which proves
     * that the leak check, with its suppressions, sees Kage's leaks. */
    kage_scene_desc desc = triangle();
    kage_scene *scene = NULL;
    CHECK(kage_scene_create(&desc, &scene));
    return 0;
  }
  if (argc == 2 && strcmp(argv[1], "out-of-memory") == 0) return out_of_memory();
  if (argc != 5) {
    fprintf(stderr, "usage: %s FRAMES SIZE VALIDATION TECHNIQUE | %s forget-a-scene | %s out-of-memory\n",
            argv[0], argv[0], argv[0]);
    return 2;
  }
  unsigned frames = (unsigned)atoi(argv[1]), size = (unsigned)atoi(argv[2]);
  kage_context_desc context_desc = {sizeof(kage_context_desc), NULL, atoi(argv[3]) != 0};
  kage_context *context = NULL;
  CHECK(kage_context_create(&context_desc, &context));
  check_bad_arguments(context);
  check_hostile_files();
  check_lights(context);
  check_scene_lights(context);
  check_precompute_options(context);
  check_renderer_progress(context);
  render_moving_box(context, (uint32_t)atoi(argv[4]), frames, size);
  CHECK(kage_context_destroy(context));
  printf("ok\n");
  return 0;
}
