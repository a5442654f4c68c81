/* Kage called as a multithreaded host calls it, with validation on: one renderer from four
 * threads at once, one renderer per thread on one context, a renderer destroyed while another
 * thread renders it, and handles used after they were destroyed. Every call must return OK, or
 * KAGE_RESULT_BUSY where another thread holds the handle, or KAGE_RESULT_INVALID_HANDLE once it
 * is gone: never crash, never a validation message. Usage: threads (prints "ok"). */
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "common.h"

enum { THREADS = 4, FRAMES = 12, SIZE = 24 };

static kage_context *context;
static kage_scene *scene;

static kage_renderer *new_renderer(void) {
  kage_renderer_desc desc = {sizeof(kage_renderer_desc), SIZE, SIZE, {0}};
  CHECK(kage_technique_desc_default(KAGE_TECHNIQUE_UNSHADOWED, &desc.technique));
  kage_renderer *renderer = NULL;
  kage_result result;
  /* The context and the scene are busy while another thread makes its renderer from them. */
  while ((result = kage_renderer_create(context, scene, &desc, &renderer)) == KAGE_RESULT_BUSY) {
  }
  EXPECT(result, KAGE_RESULT_OK);
  return renderer;
}

typedef struct {
  kage_renderer *renderer;
  int ok, busy, gone, other;
  kage_result first_other;
} tally;

static void count(tally *t, kage_result result) {
  switch (result) {
  case KAGE_RESULT_OK: t->ok++; break;
  case KAGE_RESULT_BUSY: t->busy++; break;
  case KAGE_RESULT_INVALID_HANDLE: t->gone++; break;
  default:
    if (t->other++ == 0) t->first_other = result;
  }
}

/* Renders FRAMES frames (or until the renderer is gone), counting the results. */
static void *render_frames(void *arg) {
  tally *t = arg;
  for (int i = 0; i < FRAMES && t->gone == 0; i++) {
    count(t, kage_renderer_render(t->renderer));
  }
  return NULL;
}

static void run_threads(tally *tallies) {
  pthread_t threads[THREADS];
  for (int i = 0; i < THREADS; i++) REQUIRE(pthread_create(&threads[i], NULL, render_frames, &tallies[i]) == 0);
  for (int i = 0; i < THREADS; i++) REQUIRE(pthread_join(threads[i], NULL) == 0);
}

static void report_other(const tally *t) {
  if (t->other > 0) {
    char message[512];
    kage_last_error_message(message, sizeof message, NULL);
    fprintf(stderr, "unexpected result %u: %s\n", (unsigned)t->first_other, message);
  }
}

/* One renderer, four threads: each call renders or finds the renderer busy. */
static void one_renderer_from_four_threads(void) {
  kage_renderer *shared = new_renderer();
  tally tallies[THREADS];
  memset(tallies, 0, sizeof tallies);
  for (int i = 0; i < THREADS; i++) tallies[i].renderer = shared;
  run_threads(tallies);
  int ok = 0, busy = 0;
  for (int i = 0; i < THREADS; i++) {
    report_other(&tallies[i]);
    REQUIRE(tallies[i].other == 0 && tallies[i].gone == 0);
    ok += tallies[i].ok;
    busy += tallies[i].busy;
  }
  REQUIRE(ok >= FRAMES && ok + busy == THREADS * FRAMES);
  printf("one renderer, %d threads: %d frames rendered, %d calls found it busy\n", THREADS, ok, busy);
  CHECK(kage_renderer_destroy(shared));
}

/* A renderer per thread, all made from one context: every frame renders. */
static void a_renderer_per_thread(void) {
  tally tallies[THREADS];
  memset(tallies, 0, sizeof tallies);
  for (int i = 0; i < THREADS; i++) tallies[i].renderer = new_renderer();
  run_threads(tallies);
  for (int i = 0; i < THREADS; i++) {
    report_other(&tallies[i]);
    REQUIRE(tallies[i].ok == FRAMES && tallies[i].other == 0);
    CHECK(kage_renderer_destroy(tallies[i].renderer));
  }
  printf("%d renderers on one context, %d threads: every frame rendered\n", THREADS, THREADS);
}

static void *destroy_when_free(void *arg) {
  kage_renderer *renderer = arg;
  kage_result result;
  while ((result = kage_renderer_destroy(renderer)) == KAGE_RESULT_BUSY) {
  }
  EXPECT(result, KAGE_RESULT_OK);
  return NULL;
}

/* One thread renders while another destroys: the destroy waits out the frame (BUSY), and the
 * renderer is then gone for the renderer's thread. */
static void destroyed_while_rendering(void) {
  tally t;
  memset(&t, 0, sizeof t);
  t.renderer = new_renderer();
  pthread_t render, destroy;
  REQUIRE(pthread_create(&render, NULL, render_frames, &t) == 0);
  REQUIRE(pthread_create(&destroy, NULL, destroy_when_free, t.renderer) == 0);
  REQUIRE(pthread_join(render, NULL) == 0 && pthread_join(destroy, NULL) == 0);
  report_other(&t);
  REQUIRE(t.other == 0);
  EXPECT(kage_renderer_render(t.renderer), KAGE_RESULT_INVALID_HANDLE);
  printf("destroyed while rendering: %d frames, then gone\n", t.ok);
}

/* Destroyed handles stay invalid, also when a new object of the same kind is made after. */
static void stale_handles(void) {
  kage_scene *a = make_scene();
  CHECK(kage_scene_destroy(a));
  kage_scene *b = make_scene();
  uint32_t groups = 0;
  EXPECT(kage_scene_group_count(a, &groups), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_scene_destroy(a), KAGE_RESULT_INVALID_HANDLE);
  CHECK(kage_scene_group_count(b, &groups));
  REQUIRE(groups == 2);
  CHECK(kage_scene_destroy(b));

  kage_renderer *r = new_renderer();
  CHECK(kage_renderer_destroy(r));
  kage_renderer *s = new_renderer();
  EXPECT(kage_renderer_render(r), KAGE_RESULT_INVALID_HANDLE);
  EXPECT(kage_renderer_destroy(r), KAGE_RESULT_INVALID_HANDLE);
  CHECK(kage_renderer_render(s));
  CHECK(kage_renderer_destroy(s));

  kage_context_desc desc = {sizeof(kage_context_desc), NULL, 1};
  kage_context *c = NULL;
  CHECK(kage_context_create(&desc, &c));
  CHECK(kage_context_destroy(c));
  EXPECT(kage_context_destroy(c), KAGE_RESULT_INVALID_HANDLE);
  /* A scene handle is no renderer, whatever its value. */
  EXPECT(kage_renderer_render((kage_renderer *)(void *)scene), KAGE_RESULT_INVALID_HANDLE);
  printf("stale handles: refused\n");
}

int main(void) {
  kage_context_desc desc = {sizeof(kage_context_desc), NULL, 1};
  CHECK(kage_context_create(&desc, &context));
  scene = make_scene();
  one_renderer_from_four_threads();
  a_renderer_per_thread();
  destroyed_while_rendering();
  stale_handles();
  CHECK(kage_scene_destroy(scene));
  CHECK(kage_context_destroy(context));
  printf("ok\n");
  return 0;
}
