/* test_continue.c -- more samples later, exactly: the sample sums of a
 * path-traced slab (pt_render_rows_sums) continued from any sample count
 * give the bits of a render of every sample at once, and the partial
 * image format carries them strictly (img_write_sums / img_read_partial):
 * hash, sizes, each sum finite, >= 0 and giving its pixel. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "image.h"
#include "pathtrace.h"
#include "protocol.h"
#include "scenes.h"

static const char scene[] =
    "{\"image\": {\"width\": 13, \"height\": 11, \"spp\": 20, \"max_depth\": 8, \"seed\": 3},"
    " \"camera\": {\"position\": [0, 1, -5], \"target\": [0, 0.8, 0], \"fov\": 50},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.4, 0.3, 0.3], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 40},"
    "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [8, 7, 6]}},"
    " \"lights\": [{\"type\": \"point\", \"position\": [2, 3, -2], \"intensity\": [20, 20, 20]}],"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [0.8, 0.6, -0.5], \"radius\": 0.6, \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"lamp\"}]}";

/* The partial of rows [y0, y1) with sums, in memory. */
static unsigned char *encode(const img_partial_info *info, const float *rgb, const double *sums, size_t *len)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    fr_error err;
    int rc = img_write_sums(f, info, rgb, sums, &err);
    fclose(f);
    CHECK(rc == 0, "img_write_sums: %s", err.msg);
    return (unsigned char *)buf;
}


int main(void)
{
    fr_scene s;
    test_scene(scene, &s);
    uint32_t w = s.settings.width, y0 = 2, y1 = 9, spp = s.settings.spp;
    size_t n = (size_t)w * (y1 - y0) * 3;
    float *ref = malloc(n * sizeof *ref), *rgb = malloc(n * sizeof *rgb);
    double *all = calloc(n, sizeof *all), *sums = calloc(n, sizeof *sums);

    /* Every sample at once, with and without sums: the same pixels. */
    pt_render_rows(&s, PT_MIS, y0, y1, ref);
    pt_render_rows_sums(&s, PT_MIS, y0, y1, 0, all, rgb);
    CHECK(!memcmp(ref, rgb, n * sizeof *ref), "pt_render_rows_sums from 0 differs from pt_render_rows");
    int nonzero = 0;
    for (size_t k = 0; k < n; k++)
        nonzero += all[k] > 0;
    CHECK(nonzero > (int)n / 4, "only %d sums are positive", nonzero);

    /* 7 samples, then 13, then all 20: the bits of one render of 20. */
    static const uint32_t steps[][3] = {{7, 20, 0}, {1, 13, 20}, {19, 20, 0}, {20, 20, 0}};
    for (size_t t = 0; t < sizeof steps / sizeof *steps; t++) {
        memset(sums, 0, n * sizeof *sums);
        uint32_t first = 0;
        for (int k = 0; k < 3 && steps[t][k]; k++) {
            s.settings.spp = steps[t][k];
            pt_render_rows_sums(&s, PT_MIS, y0, y1, first, sums, rgb);
            first = steps[t][k];
        }
        s.settings.spp = spp;
        CHECK(!memcmp(ref, rgb, n * sizeof *ref), "continued %u/%u/%u: pixels differ", steps[t][0], steps[t][1],
              steps[t][2]);
        CHECK(!memcmp(all, sums, n * sizeof *sums), "continued %u/%u/%u: sums differ", steps[t][0], steps[t][1],
              steps[t][2]);
    }
    /* Fewer samples are not the same image (the test can fail). */
    s.settings.spp = 19;
    memset(sums, 0, n * sizeof *sums);
    pt_render_rows_sums(&s, PT_MIS, y0, y1, 0, sums, rgb);
    s.settings.spp = spp;
    CHECK(memcmp(ref, rgb, n * sizeof *ref) != 0, "19 samples give the image of 20");

    /* The format: a round trip, then every kind of damage refused. */
    img_partial_info info = {.scene = s.hash, .y0 = y0, .y1 = y1, .spp = spp, .width = w, .height = s.settings.height};
    size_t len;
    unsigned char *buf = encode(&info, ref, all, &len);
    img_partial_info got;
    float *px = NULL;
    fr_error err;
    CHECK(img_read_partial(buf, len, &got, &px, &err) == 0, "a partial with sums is refused: %s", err.msg);
    if (px) {
        CHECK(got.sums_offset > 0 && got.splat_paths == 0 && got.spp == spp, "sums offset %zu", got.sums_offset);
        CHECK(!memcmp(px, ref, n * sizeof *ref), "pixels changed in the round trip");
        memset(sums, 0, n * sizeof *sums);
        img_sums_get(buf, &got, sums);
        CHECK(!memcmp(sums, all, n * sizeof *sums), "sums changed in the round trip");
        free(px);
        px = NULL;
    }
    CHECK(len == got.sums_offset + n * 8, "%zu bytes, sums at %zu", len, got.sums_offset);
    /* A flipped bit in the sums: the hash. */
    buf[len - 3] ^= 4;
    CHECK(img_read_partial(buf, len, &got, &px, &err) < 0 && strstr(err.msg, "does not match its hash"),
          "damaged sums: %s", err.msg);
    free(px);
    px = NULL;
    buf[len - 3] ^= 4;
    /* Truncated. */
    CHECK(img_read_partial(buf, len - 8, &got, &px, &err) < 0 && strstr(err.msg, "and sums"), "short: %s", err.msg);
    free(buf);
    /* A sum that does not give its pixel, a negative and an infinite one,
     * each with a matching hash (written so). */
    const double bad[] = {all[4] * 1.5 + 1.0, -1.0, 1.0 / 0.0};
    for (size_t b = 0; b < sizeof bad / sizeof *bad; b++) {
        double keep = all[4];
        all[4] = bad[b];
        buf = encode(&info, ref, all, &len);
        all[4] = keep;
        CHECK(img_read_partial(buf, len, &got, &px, &err) < 0 && strstr(err.msg, "the sum of pixel (1, 2)"),
              "bad sum %g: %s", bad[b], err.msg);
        free(px);
        px = NULL;
        free(buf);
    }
    /* The header: sums= needs 16 lowercase hex digits and nothing after. */
    buf = encode(&info, ref, all, &len);
    char *h = strstr((char *)buf, " sums=");
    static const char *const heads[] = {" sums=0x", " sums=ABC"};
    for (size_t k = 0; h && k < sizeof heads / sizeof *heads; k++) {
        unsigned char *copy = malloc(len);
        memcpy(copy, buf, len);
        memcpy(copy + (h - (char *)buf), heads[k], strlen(heads[k]));
        CHECK(img_read_partial(copy, len, &got, &px, &err) < 0 && strstr(err.msg, "sums=<16 hex digits>"),
              "header '%s': %s", heads[k], err.msg);
        free(px);
        px = NULL;
        free(copy);
    }
    free(buf);

    /* The command line: --sums and --continue FILE survive a round trip. */
    proto_slab sl = {.scene = "s.fbin", .y0 = 2, .y1 = 9, .spp = 20, .format = IMG_PF, .out = "-", .lifeline = 1,
                     .sums = 1, .continue_from = "job/rows-2-9.pf"};
    proto_argv pa;
    CHECK(proto_slab_argv(&sl, &pa, &err) == 0, "proto_slab_argv: %s", err.msg);
    char *args[32] = {"franja-worker"};
    int argc = 1;
    while (pa.argv[argc - 1] && argc < 31) {
        args[argc] = (char *)pa.argv[argc - 1];
        argc++;
    }
    proto_request req;
    CHECK(proto_parse_args(argc, args, &req, &err) == 0, "proto_parse_args: %s", err.msg);
    CHECK(req.slab.sums == 1 && req.slab.continue_from && !strcmp(req.slab.continue_from, "job/rows-2-9.pf") &&
              req.slab.lifeline && req.slab.spp == 20,
          "round trip: sums %d continue %s", req.slab.sums, req.slab.continue_from ? req.slab.continue_from : "-");
    free(ref);
    free(rgb);
    free(all);
    free(sums);
    scn_free(&s);
    return check_done();
}
