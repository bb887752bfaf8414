/* scenes.h -- building small scenes in tests straight from JSON text. */
#ifndef FRANJA_TEST_SCENES_H
#define FRANJA_TEST_SCENES_H

#include <stdio.h>
#include <stdlib.h>

#include "freeze.h"
#include "scene_json.h"

/* Parse and freeze a scene from JSON text; aborts the test on error since
 * every later check would be meaningless. */
static inline void test_scene(const char *json, fr_scene *out)
{
    fr_builder b;
    fr_error err;
    bld_init(&b);
    if (scn_parse_json(json, "(test)", NULL, &b, &err) < 0 || frz_scene(&b, out, &err) < 0) {
        printf("FAIL scene: %s\n", err.msg);
        exit(1);
    }
    bld_free(&b);
}

#endif
