/* fuzz_json.c -- libFuzzer target for the JSON scene reader: parse any
 * text and, when it is a valid scene, freeze it (BVH build, serialization
 * and the loader's validation of what the builder wrote). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "freeze.h"
#include "scene_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    fr_builder b;
    fr_error err;
    bld_init(&b);
    if (scn_parse_json(text, "fuzz.json", NULL, &b, &err) == 0) {
        fr_scene s;
        if (frz_scene(&b, &s, &err) == 0)
            scn_free(&s);
    }
    bld_free(&b);
    free(text);
    return 0;
}
