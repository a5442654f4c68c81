/* The canary of the memcheck test: forgets a scene handle on purpose. Valgrind must report it
 * as definitely lost; that proves the leak check, with its suppressions, sees Kage's leaks. */
#include "kage.h"

int main(void) {
  float positions[9] = {0, 0, 0, 1, 0, 0, 0, 0, -1};
  uint32_t indices[3] = {0, 1, 2};
  float sky[2 * 1 * 3] = {1, 1, 1, 1, 1, 1};
  kage_mesh_desc mesh = {positions, NULL, 3, indices, 3, {0.5f, 0.5f, 0.5f}};
  kage_group_desc group = {NULL, {{0, 0, 0}, {0, 0, 0, 1}, 1.0f}, &mesh, 1};
  kage_scene_desc desc = {&group, 1, {sky, 2, 1}, {{0, 1, 2}, {0, 0, 0}, {0, 1, 0}, 60.0f}};
  kage_scene *scene = NULL;
  return kage_scene_create(&desc, &scene) == KAGE_RESULT_OK ? 0 : 1;
}
