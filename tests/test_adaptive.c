/* test_adaptive.c -- adaptive sampling is split-invariant, keeps the mean and
 * checks its range.
 *
 * Adaptive sampling (settings.noise_threshold): any split of the rows
 * (2, 3, 7 slabs) renders the same bits; a threshold no pixel can reach renders the
 * image of the full sample count (but for pixels black so far); a reachable one stops pixels early
 * and keeps the image's mean; the scene reader and the worker command
 * line refuse thresholds outside their range. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pathtrace.h"
#include "protocol.h"
#include "scenes.h"

static const char scene[] =
    "{\"image\": {\"width\": 24, \"height\": 18, \"spp\": 128, \"max_depth\": 6, \"seed\": 3,"
    "   \"noise_threshold\": 0.05},"
    " \"camera\": {\"position\": [0, 1, -5], \"target\": [0, 0.8, 0], \"fov\": 50},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.45, 0.4]},"
    "   \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [8, 7, 6]}},"
    " \"lights\": [{\"type\": \"point\", \"position\": [2, 3, -2], \"intensity\": [20, 20, 20]}],"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [0.3, 0.6, -0.5], \"radius\": 0.6, \"material\": \"glass\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"lamp\"}]}";

static float *render(const fr_scene *s, uint32_t y0, uint32_t y1, float *into)
{
    size_t n = (size_t)s->settings.width * s->settings.height * 3;
    float *img = into ? into : calloc(n, sizeof *img);
    pt_render_rows(s, PT_MIS, y0, y1, img + (size_t)y0 * s->settings.width * 3);
    return img;
}

static double mean(const float *img, size_t n)
{
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += img[i];
    return sum / n;
}

int main(void)
{
    fr_scene s;
    test_scene(scene, &s);
    CHECK(s.settings.noise_threshold == 0.05f, "noise_threshold read from the image block: %g",
          (double)s.settings.noise_threshold);
    uint32_t w = s.settings.width, h = s.settings.height;
    size_t n = (size_t)w * h * 3, bytes = n * sizeof(float);

    /* Split invariance with adaptive sampling on. */
    float *full = render(&s, 0, h, NULL);
    /* 2, 3 and 7 uneven slabs, rendered last slab first. */
    const uint32_t cuts[][8] = {{0, 11, 18}, {0, 1, 7, 18}, {0, 2, 3, 7, 8, 13, 17, 18}};
    const int slabs[] = {2, 3, 7};
    for (int k = 0; k < 3; k++) {
        float *img = calloc(n, sizeof *img);
        for (int i = slabs[k] - 1; i >= 0; i--)
            render(&s, cuts[k][i], cuts[k][i + 1], img);
        CHECK(memcmp(img, full, bytes) == 0, "adaptive: %d slabs differ from the full image", slabs[k]);
        free(img);
    }

    /* Off, and a threshold no noisy pixel reaches: the same bits. */
    fr_scene off = s, strict = s;
    off.settings.noise_threshold = 0.0f;
    strict.settings.noise_threshold = 1e-7f;
    float *uniform = render(&off, 0, h, NULL), *tight = render(&strict, 0, h, NULL);
    /* Only pixels whose first samples were all black (their error estimate
     * is 0) stop early under it; every other pixel takes every sample. */
    size_t same = 0, black = 0;
    for (size_t i = 0; i < n; i += 3) {
        if (!memcmp(uniform + i, tight + i, 3 * sizeof(float)))
            same++;
        else if (tight[i] == 0.0f && tight[i + 1] == 0.0f && tight[i + 2] == 0.0f)
            black++;
    }
    printf("threshold 1e-7: %zu pixels as uniform, %zu stopped black, of %zu\n", same, black, n / 3);
    CHECK(same + black == n / 3 && same > n / 3 * 9 / 10, "a threshold no pixel reaches changes %zu pixels",
          n / 3 - same - black);

    /* A reachable threshold stops pixels early (the image differs), and the
     * image keeps its mean. */
    CHECK(memcmp(uniform, full, bytes) != 0, "threshold 0.05 stops no pixel early");
    double mu = mean(uniform, n), ma = mean(full, n);
    printf("image mean: uniform %.5f, adaptive %.5f\n", mu, ma);
    CHECK(mu > 0.01 && fabs(ma - mu) < 0.03 * mu, "adaptive mean %g, uniform %g", ma, mu);

    /* Out-of-range thresholds are refused by the scene reader and the
     * worker's command line; the command line carries a threshold exactly. */
    const char *bad[] = {"-0.1", "1.5", "\"x\""};
    for (int i = 0; i < 3; i++) {
        char json[512];
        snprintf(json, sizeof json,
                 "{\"image\": {\"width\": 2, \"height\": 2, \"noise_threshold\": %s},"
                 " \"camera\": {\"position\": [0, 0, -1], \"target\": [0, 0, 0], \"fov\": 40},"
                 " \"materials\": {\"m\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
                 " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 2], \"radius\": 1, \"material\": \"m\"}]}",
                 bad[i]);
        fr_builder b;
        fr_error err;
        bld_init(&b);
        int rc = json_scene_parse(json, "(test)", NULL, &b, &err);
        CHECK(rc < 0 && strstr(err.msg, "noise_threshold"), "noise_threshold %s accepted (%s)", bad[i],
              rc < 0 ? err.msg : "no error");
        bld_free(&b);
    }
    const char *bad_args[] = {"0", "-1", "2", "nan", "0.1x", ""};
    for (int i = 0; i < 6; i++) {
        char *argv[] = {"franja-worker", "--scene", "s.fbin", "--rows", "0:1", "--noise-threshold",
                        (char *)bad_args[i], NULL};
        proto_request r;
        fr_error err;
        CHECK(proto_parse_args(7, argv, &r, &err) < 0 && strstr(err.msg, "--noise-threshold"),
              "--noise-threshold '%s' accepted", bad_args[i]);
    }
    proto_slab sl = {.scene = "s.fbin", .y0 = 0, .y1 = 4, .noise_threshold = 0.0123f, .out = "-"};
    proto_argv a;
    fr_error err;
    int argc = 1;
    char *argv[20] = {"franja-worker"};
    CHECK(proto_slab_argv(&sl, &a, &err) == 0, "slab argv: %s", err.msg);
    for (int i = 0; a.argv[i]; i++)
        argv[argc++] = (char *)a.argv[i];
    proto_request r;
    CHECK(proto_parse_args(argc, argv, &r, &err) == 0 && r.slab.noise_threshold == 0.0123f,
          "the threshold does not survive the worker command line");

    free(full), free(uniform), free(tight);
    scn_free(&s);
    return check_done();
}
