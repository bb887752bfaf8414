/* fuzz_fbin.c -- libFuzzer target for the binary scene loader.
 *
 * The input becomes a binary scene whose content hash is recomputed first,
 * so the fuzzer explores the structural checks rather than stopping at the
 * hash (which any random change trips).  A scene the loader accepts is
 * then used as the renderer uses it: rays through the BVH, surfaces at the
 * hits, a few path-traced samples and lookups into every texture at
 * ordinary, huge and NaN coordinates: validation must make all of that
 * safe. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include "fbin.h"
#include "pathtrace.h"
#include "texture.h"
#include "trace.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    unsigned char *p = aligned_alloc(64, size / 64 * 64 + 64);
    if (!p)
        return 0;
    memcpy(p, data, size);
    if (size >= 64) {
        uint64_t h = XXH3_64bits(p + 64, size - 64);
        memcpy(p + 32, &h, 8);
    }
    fr_scene s;
    fr_error err;
    if (fbin_open_mem(p, size, 0, &s, &err) < 0) {
        free(p);
        return 0;
    }
    /* A few rays from the camera and from the middle of the scene. */
    s.settings.width = s.settings.height = 4;
    for (uint32_t i = 0; i < 8; i++) {
        fr_ray r = pt_camera_ray(&s, i % 4, i / 4, 0.5f, 0.5f, 0.5f, 0.5f);
        if (i >= 4 && s.n_positions)
            r.o = s.positions[i % s.n_positions];
        fr_hit hit;
        if (trace_closest(&s, &r, INFINITY, &hit)) {
            fr_surface sf;
            trace_surface(&s, &r, &hit, &sf);
        }
        trace_occluded(&s, &r, 1.0f + (float)i, i);
    }
    s.settings.max_depth = s.settings.max_depth < 8 ? s.settings.max_depth : 8;
    for (uint32_t i = 0; i < 4; i++)
        pt_sample(&s, PT_MIS, i % 4, (i * 3) % 4, i);
    static const vec2 uvs[] = {{0.3f, 0.7f}, {-0.2f, 1.5f}, {1e30f, -1e30f}, {NAN, 0.5f}, {0.5f, INFINITY}};
    for (uint32_t t = 0; t < s.n_textures && t < 16; t++)
        for (size_t k = 0; k < sizeof uvs / sizeof uvs[0]; k++)
            tex_eval(&s, t, uvs[k]);
    scn_free(&s);
    return 0;
}
