/* Helpers shared by the C hosts of Kage's test suite: result checks, a small scene built from
 * arrays, and a run that moves a group over frames and checks pixels and pass timings. */
#ifndef KAGE_TEST_COMMON_H
#define KAGE_TEST_COMMON_H

#include "kage.h"

/* Fails the program (exit 1) unless `call` returned `want`, printing Kage's message. */
#define EXPECT(call, want) expect_result(#call, (call), (want), __FILE__, __LINE__)
#define CHECK(call) EXPECT(call, KAGE_RESULT_OK)
void expect_result(const char *what, kage_result got, kage_result want, const char *file, int line);

/* Fails the program unless `condition` holds. */
#define REQUIRE(condition) require((condition), #condition, __FILE__, __LINE__)
void require(int condition, const char *what, const char *file, int line);

/* The test scene, built from arrays: a grey floor (group 0) and a red box (group 1) standing
 * on it, under a sky brighter above than below. */
kage_scene *make_scene(void);

/* Prints the context's device; builds the scene; precomputes for `technique` (a kage_technique,
 * with parameters small enough for a CPU driver); renders `frames` frames of `size`² pixels,
 * moving the box from left to right, and checks every frame: pixels finite and not all equal,
 * the box further right than in the frame before, the expected pass names with times that are
 * not negative and a frame time above 0. Prints each frame's passes. */
void render_moving_box(kage_context *context, uint32_t technique, unsigned frames, unsigned size);

#endif
