/* test_invariance.c -- images do not depend on quad diagonals or distance from
 * the origin.
 *
 * An image must not depend on how its geometry is written down: the
 * Cornell box renders the same, within noise and region by region, when
 * the corners of a quad are listed from another corner (so the quad is
 * split into two triangles along the other diagonal) and when the whole
 * scene, camera included, is moved far from the origin.  Rays leaving a
 * surface that find it again (a too small ray-origin offset, walls at
 * coordinate 0) darken some directions and not others, which shows here as
 * blocks of the image that differ by more than their noise. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pathtrace.h"
#include "scenes.h"

#define SIZE 128
#define SPP 64
#define BLOCK 8

/* The Cornell box of scenes/cornell.json: material and four corners. */
static const struct {
    const char *material;
    float v[4][3];
} quads[] = {
    {"white", {{552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {552.8f, 0, 559.2f}}},
    {"white", {{552.8f, 548.8f, 0}, {552.8f, 548.8f, 559.2f}, {0, 548.8f, 559.2f}, {0, 548.8f, 0}}},
    {"white", {{552.8f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {552.8f, 548.8f, 559.2f}}},
    {"red", {{552.8f, 0, 0}, {552.8f, 0, 559.2f}, {552.8f, 548.8f, 559.2f}, {552.8f, 548.8f, 0}}},
    {"green", {{0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f}}},
    {"light", {{343, 548.7f, 227}, {343, 548.7f, 332}, {213, 548.7f, 332}, {213, 548.7f, 227}}},
    {"white", {{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}}},
    {"white", {{290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}}},
    {"white", {{130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}}},
    {"white", {{82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}}},
    {"white", {{240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}}},
    {"white", {{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}}},
    {"white", {{423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}}},
    {"white", {{472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}}},
    {"white", {{314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}}},
    {"white", {{265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}}},
};
#define NQUADS (sizeof quads / sizeof quads[0])

/* The scene moved by `shift`, with the corners of the quads whose
 * material is `rotate` (NULL: none) listed from their second corner, and
 * the green wall's albedo `green`. */
static char *cornell(const float shift[3], const char *rotate, const char *green)
{
    size_t cap = 16384, n = 0;
    char *s = malloc(cap);
    n += (size_t)snprintf(s + n, cap - n,
                          "{\"image\": {\"width\": %d, \"height\": %d, \"spp\": %d, \"max_depth\": 8, \"seed\": 0},"
                          " \"camera\": {\"position\": [%.9g, %.9g, %.9g], \"target\": [%.9g, %.9g, %.9g],"
                          " \"up\": [0, 1, 0], \"fov\": 39.3077},"
                          " \"materials\": {\"white\": {\"type\": \"lambert\", \"albedo\": [0.725, 0.71, 0.68]},"
                          " \"red\": {\"type\": \"lambert\", \"albedo\": [0.63, 0.065, 0.05]},"
                          " \"green\": {\"type\": \"lambert\", \"albedo\": [%s]},"
                          " \"light\": {\"type\": \"emitter\", \"emission\": [17, 12, 4]}}, \"shapes\": [",
                          SIZE, SIZE, SPP, 278 + shift[0], 273 + shift[1], -800 + shift[2], 278 + shift[0],
                          273 + shift[1], shift[2], green);
    for (size_t q = 0; q < NQUADS; q++) {
        int first = rotate && !strcmp(quads[q].material, rotate);
        n += (size_t)snprintf(s + n, cap - n, "%s{\"type\": \"quad\", \"material\": \"%s\", \"vertices\": [",
                              q ? ", " : "", quads[q].material);
        for (int k = 0; k < 4; k++) {
            const float *v = quads[q].v[(k + first) % 4];
            n += (size_t)snprintf(s + n, cap - n, "%s[%.9g, %.9g, %.9g]", k ? ", " : "", v[0] + shift[0],
                                  v[1] + shift[1], v[2] + shift[2]);
        }
        n += (size_t)snprintf(s + n, cap - n, "]}");
    }
    snprintf(s + n, cap - n, "]}");
    return s;
}

static float *render(const char *json)
{
    fr_scene s;
    test_scene(json, &s);
    float *rgb = malloc((size_t)SIZE * SIZE * 3 * sizeof *rgb);
    pt_render_rows(&s, PT_MIS, 0, SIZE, rgb);
    scn_free(&s);
    return rgb;
}

/* Compare two renders block by block: the mean of the per-pixel
 * differences (summed over channels) must lie within 5 standard errors
 * (the pixels of a block are independent samples) plus 0.3 % of the
 * block's mean, which tolerates the rounding a move changes.  Returns the
 * number of blocks beyond that; prints the block of largest relative
 * difference. */
static int compare(const float *a, const float *b, const char *what)
{
    int bad = 0, wx = 0, wy = 0;
    double worst = 0;
    for (int by = 0; by < SIZE; by += BLOCK) {
        for (int bx = 0; bx < SIZE; bx += BLOCK) {
            double sum = 0, sum2 = 0, mean_a = 0;
            int n = BLOCK * BLOCK;
            for (int y = by; y < by + BLOCK; y++) {
                for (int x = bx; x < bx + BLOCK; x++) {
                    const float *pa = a + ((size_t)y * SIZE + x) * 3, *pb = b + ((size_t)y * SIZE + x) * 3;
                    double va = (double)pa[0] + pa[1] + pa[2], d = va - ((double)pb[0] + pb[1] + pb[2]);
                    sum += d;
                    sum2 += d * d;
                    mean_a += va;
                }
            }
            double mean = sum / n, var = (sum2 - sum * mean) / (n - 1);
            double se = sqrt(var > 0 ? var / n : 0);
            mean_a /= n;
            bad += fabs(mean) > 5 * se + 0.003 * mean_a;
            double rel = mean_a > 0 ? -mean / mean_a : 0;
            if (fabs(rel) > fabs(worst)) {
                worst = rel;
                wx = bx;
                wy = by;
            }
        }
    }
    printf("%s: %d of %d blocks beyond noise; largest difference %+.3f %% (rows %d-%d, columns %d-%d)\n", what,
           bad, (SIZE / BLOCK) * (SIZE / BLOCK), 100 * worst, wy, wy + BLOCK, wx, wx + BLOCK);
    return bad;
}

#define GREEN "0.14, 0.45, 0.091"

int main(void)
{
    const float zero[3] = {0, 0, 0}, far[3] = {1000, 1000, 0}, other[3] = {-3000, 250, 4000};
    char *json = cornell(zero, NULL, GREEN);
    float *base = render(json);
    free(json);
    /* The comparison can see a difference: the green wall 3 % darker must
     * fail it. */
    json = cornell(zero, NULL, "0.1358, 0.4365, 0.08827");
    float *darker = render(json);
    free(json);
    CHECK(compare(base, darker, "green wall 3 % darker (control)") > 0,
          "the comparison does not see a wall 3 %% darker");
    free(darker);

    struct { const float *shift; const char *rotate; const char *what; } cases[] = {
        {zero, "green", "green wall's corners listed from the second"},
        {zero, "white", "white quads' corners listed from the second"},
        {far, NULL, "scene moved by (1000, 1000, 0)"},
        {other, NULL, "scene moved by (-3000, 250, 4000)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        json = cornell(cases[i].shift, cases[i].rotate, GREEN);
        float *img = render(json);
        CHECK(compare(base, img, cases[i].what) == 0, "%s: the image changed", cases[i].what);
        free(img);
        free(json);
    }
    free(base);
    return check_done();
}
