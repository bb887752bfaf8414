/* test_passes_bdpt.c -- render passes of bidirectional path tracing and their partials.
 *
 * BDPT fills the passes of its camera subpaths (bdpt.h BD_PASSES): on the
 * Cornell box, whose surfaces are all Lambertian, they are the path
 * tracer's to the bit (the same camera rays, the same first hits, albedo
 * at the first hit); the image and the splats keep their bits with passes;
 * any split of rows gives the same passes; light passes are refused; a
 * partial carries splats and passes together and reads back to the bit.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bdpt.h"
#include "check.h"
#include "compile/json_scene.h"
#include "image.h"
#include "passes.h"
#include "pathtrace.h"

enum { W = 20, H = 20, SPP = 4 }; /* the scene's square image, smaller */

static void check_render(void)
{
    fr_scene s;
    fr_error err;
    if (json_scene_load("scenes/cornell.json", NULL, &s, &err) < 0) {
        CHECK(0, "cornell loads: %s", err.msg);
        return;
    }
    s.settings.width = W;
    s.settings.height = H;
    s.settings.spp = SPP;
    uint32_t nch = pass_channels(BD_PASSES);
    size_t n = (size_t)W * H, np = n * nch;
    float *rgb0 = calloc(n * 3, sizeof(float)), *rgb1 = calloc(n * 3, sizeof(float));
    float *bp = calloc(np, sizeof(float)), *half = calloc(np, sizeof(float)), *pp = calloc(np, sizeof(float));
    float *prgb = calloc(n * 3, sizeof(float));
    uint64_t *sp0 = calloc(n * 3, sizeof(uint64_t)), *sp1 = calloc(n * 3, sizeof(uint64_t));
    uint64_t *sp2 = calloc(n * 3, sizeof(uint64_t));
    CHECK(bd_render_rows(&s, 0, H, rgb0, sp0, &err) == 0, "bdpt renders: %s", err.msg);
    CHECK(bd_render_rows_passes(&s, 0, H, rgb1, sp1, BD_PASSES, bp, &err) == 0, "bdpt renders passes: %s", err.msg);
    CHECK(!memcmp(rgb0, rgb1, n * 3 * sizeof(float)) && !memcmp(sp0, sp1, n * 3 * sizeof(uint64_t)),
          "the image and the splats keep their bits with passes");
    /* Two slabs of rows give the same passes. */
    uint32_t cut = 7;
    bd_render_rows_passes(&s, 0, cut, rgb1, sp2, BD_PASSES, half, &err);
    bd_render_rows_passes(&s, cut, H, rgb1 + (size_t)cut * W * 3, sp2, BD_PASSES, half + (size_t)cut * W * nch, &err);
    CHECK(!memcmp(bp, half, np * sizeof(float)), "rows 0:7 and 7:20 give the passes of 0:20");
    /* The path tracer's passes on Lambertian surfaces. */
    pt_render_rows_passes(&s, PT_MIS, 0, H, prgb, BD_PASSES, pp);
    size_t differ = 0, hit = 0;
    for (size_t i = 0; i < np; i++)
        differ += memcmp(&bp[i], &pp[i], sizeof(float)) != 0;
    for (size_t i = 0; i < n; i++)
        hit += bp[i * nch + 10] > 0.0f; /* material_id after albedo, normal, depth, position: 10 channels */
    CHECK(differ == 0, "cornell: the passes are the path tracer's (%zu of %zu values differ)", differ, np);
    CHECK(hit * 4 >= n * 3, "cornell: most pixels hit a material (%zu of %zu)", hit, n);
    /* Light passes: not filled, refused. */
    CHECK(bd_render_rows_passes(&s, 0, 1, rgb1, sp2, 1u << PASS_EMISSION, bp, &err) < 0 && strstr(err.msg, "camera"),
          "the emission pass is refused: %s", err.msg);
    free(rgb0);
    free(rgb1);
    free(prgb);
    free(bp);
    free(half);
    free(pp);
    free(sp0);
    free(sp1);
    free(sp2);
    scn_free(&s);
}

/* A partial with splats and passes: both blocks back to the bit; a damaged
 * passes block is refused. */
static void check_partial(void)
{
    enum { PW = 5, PH = 3, FH = 9 };
    uint32_t mask = 1u << PASS_DEPTH | 1u << PASS_OBJECT_ID, nch = pass_channels(mask);
    float rgb[PW * PH * 3], pass[PW * PH * 2], back[PW * PH * 2];
    uint64_t splat[PW * FH * 3], acc[PW * FH * 3] = {0};
    for (int i = 0; i < PW * PH * 3; i++)
        rgb[i] = (float)i / 9.0f;
    for (int i = 0; i < PW * PH * 2; i++)
        pass[i] = (float)(i % 7) * 1.5f;
    for (int i = 0; i < PW * FH * 3; i++)
        splat[i] = (uint64_t)i * 0x10001u;
    CHECK(nch == 2, "depth and object_id: 2 channels, got %u", nch);
    img_partial_info info = {0xbeefull, 4, 4 + PH, 2, PW, FH, (uint64_t)PW * PH * 2, 0, 0, 0, mask, 0};
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    fr_error err;
    CHECK(img_write_splat_passes(f, &info, rgb, splat, pass, &err) == 0, "img_write_splat_passes: %s", err.msg);
    fclose(f);
    img_partial_info got;
    float *px = NULL;
    int rc = img_read_partial((unsigned char *)buf, len, &got, &px, &err);
    CHECK(rc == 0, "a partial with splats and passes reads back: %s", err.msg);
    if (rc == 0) {
        img_passes_get((unsigned char *)buf, &got, back);
        img_splat_add((unsigned char *)buf, &got, acc);
        CHECK(got.passes == mask && got.splat_paths == info.splat_paths && !memcmp(back, pass, sizeof pass) &&
                  !memcmp(acc, splat, sizeof splat) && !memcmp(px, rgb, sizeof rgb),
              "the pixels, splats and passes come back to the bit");
    }
    free(px);
    px = NULL;
    buf[len - 2] ^= 4;
    CHECK(img_read_partial((unsigned char *)buf, len, &got, &px, &err) < 0 && strstr(err.msg, "passes block"),
          "a damaged passes block after the splats is refused: %s", err.msg);
    free(px);
    free(buf);
}

int main(void)
{
    check_partial();
    check_render();
    return check_done();
}
