/* scenes.h -- building small scenes in tests straight from JSON text. */
#ifndef FRANJA_TEST_SCENES_H
#define FRANJA_TEST_SCENES_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/freeze.h"
#include "compile/json_scene.h"

/* Parse and freeze a scene from JSON text as if read from `file` (relative
 * names resolve beside it), with asset loaders `hooks` (may be NULL);
 * aborts the test on error since every later check would be meaningless. */
static inline void test_scene_with(const char *json, const char *file, const scene_hooks *hooks, fr_scene *out)
{
    fr_builder b;
    fr_error err;
    bld_init(&b);
    if (json_scene_parse(json, file, hooks, &b, &err) < 0 || frz_scene(&b, out, &err) < 0) {
        printf("FAIL scene: %s\n", err.msg);
        exit(1);
    }
    bld_free(&b);
}

/* Load the scene file `path` (relative to the project's root, where tests
 * run); aborts the test on error, as test_scene_with does. */
static inline void test_scene_file(const char *path, fr_scene *out)
{
    fr_error err;
    if (json_scene_load(path, NULL, out, &err) < 0) {
        printf("FAIL scene %s: %s\n", path, err.msg);
        exit(1);
    }
}

/* Parse and freeze a scene from JSON text (no asset loaders). */
static inline void test_scene(const char *json, fr_scene *out) { test_scene_with(json, "(test)", NULL, out); }

/* Whether a scene's JSON text is refused with a message containing
 * `want`; the message (or "accepted") into *msg, which stays valid until
 * the next call. */
static inline int test_scene_refused(const char *json, const char *want, const char **msg)
{
    static fr_error err;
    fr_builder b;
    bld_init(&b);
    int rc = json_scene_parse(json, "(test)", NULL, &b, &err);
    bld_free(&b);
    *msg = rc < 0 ? err.msg : "accepted";
    return rc < 0 && strstr(err.msg, want) != NULL;
}

#endif
