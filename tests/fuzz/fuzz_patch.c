/* fuzz_patch.c -- libFuzzer target for scene patches a worker applies
 * (common/fpatch.h: fpatch_apply, `franja-worker --unpack` of a patch),
 * sent by a coordinator over the network.
 *
 * The base scene and two patches of it are made once from JSON text: one
 * of a camera move (one small section), one of new geometry (sections of
 * new sizes).  The first byte picks the form: even, the rest is the
 * patch as it is; odd, bit 1 picks one of the two patches, and the rest
 * edits it: each 3 bytes a little-endian offset (up to 64 bytes past its
 * end, which grows it) and the byte to write there, and a last lone byte
 * cuts it to that fraction of its length (/ 256).  A fuzzer cannot forge
 * the content hash of a rebuilt scene, so this reaches every check before
 * the hash, and a patch left intact is checked to rebuild its scene.
 * Seeds: tests/fuzz/corpus/patch. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/freeze.h"
#include "compile/json_scene.h"
#include "fbin.h"
#include "fpatch.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define SCENE(CAM, EXTRA)                                                                                    \
    "{\"image\": {\"width\": 8, \"height\": 6, \"spp\": 1},"                                                  \
    " \"camera\": {\"position\": " CAM ", \"target\": [0, 0.5, 0], \"fov\": 50},"                            \
    " \"materials\": {\"w\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]}},"                         \
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [10, 10, 10]}],"             \
    " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.5, \"material\": \"w\"}"     \
    EXTRA "]}"

static fr_scene base, res[2];
static void *patch[2];
static size_t patch_size[2];

static void scene(const char *json, fr_scene *out)
{
    fr_builder b;
    fr_error err;
    bld_init(&b);
    if (json_scene_parse(json, "(fuzz)", NULL, &b, &err) < 0 || frz_scene(&b, out, &err) < 0) {
        fprintf(stderr, "fuzz_patch: %s\n", err.msg);
        exit(1);
    }
    bld_free(&b);
}

static void setup(void)
{
    scene(SCENE("[0, 1, -4]", ""), &base);
    scene(SCENE("[1, 1, -4]", ""), &res[0]);
    scene(SCENE("[0, 1, -4]", ", {\"type\": \"triangle\", \"vertices\": [[-2, 0, 1], [2, 0, 1], [0, 2, 1]], "
                              "\"material\": \"w\"}"), &res[1]);
    for (int i = 0; i < 2; i++) {
        uint64_t mask;
        fr_error err;
        if (fpatch_make(base.blob, base.blob_size, res[i].blob, res[i].blob_size, &patch[i], &patch_size[i], &mask,
                        &err) < 0) {
            fprintf(stderr, "fuzz_patch: %s\n", err.msg);
            exit(1);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ready;
    if (!ready) {
        setup();
        ready = 1;
    }
    if (size < 1)
        return 0;
    unsigned char *p;
    size_t n;
    int intact = 0, which = data[0] >> 1 & 1;
    if (!(data[0] & 1)) {
        n = size - 1;
        p = malloc(n ? n : 1);
        memcpy(p, data + 1, n);
    } else {
        n = patch_size[which];
        p = calloc(1, n + 64);
        memcpy(p, patch[which], n);
        size_t i = 1;
        for (; i + 3 <= size; i += 3) {
            size_t at = ((size_t)data[i] | (size_t)data[i + 1] << 8) % (patch_size[which] + 64);
            p[at] = data[i + 2];
            if (at >= n)
                n = at + 1;
        }
        if (i < size)
            n = n * data[i] / 256;
        intact = size == 1;
    }
    void *out = NULL;
    size_t osize = 0;
    fr_error err;
    int rc = fpatch_apply(p, n, base.blob, base.blob_size, &out, &osize, &err);
    if (intact && (rc != 0 || osize != res[which].blob_size || memcmp(out, res[which].blob, osize))) {
        fprintf(stderr, "fuzz_patch: an intact patch does not rebuild its scene: %s\n", rc ? err.msg : "bytes");
        abort();
    }
    if (rc == 0) {
        fr_scene s;
        if (fbin_open_mem(out, osize, 0, &s, &err) == 0)
            out = NULL; /* s owns it */
        scn_free(&s);
    }
    free(out);
    free(p);
    return 0;
}
