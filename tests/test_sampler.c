/* test_sampler.c -- the sampler is deterministic, stratified (0, m, 2)-nets,
 * decorrelated.
 *
 * The sampler (common/sampler.h): its numbers are a pure function of
 * pixel, index, dimension and seed; every power-of-two prefix of a pixel's
 * samples in a dimension pair is a (0, m, 2)-net (one point in each of the
 * 2^m elementary intervals of every shape); pairs and pixels are
 * decorrelated; smp_skip leaves the later pairs as they were. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "sampler.h"

#define PAIRS 12

/* Pairs 0..PAIRS-1 of sample `index` of pixel (x, y). */
static void pairs(uint32_t x, uint32_t y, uint32_t index, uint32_t seed, float uv[PAIRS][2])
{
    fr_sampler s;
    smp_start(&s, x, y, index, seed);
    for (int d = 0; d < PAIRS; d++)
        smp_2d(&s, &uv[d][0], &uv[d][1]);
}

/* Whether n = 2^m points are one per elementary interval of every shape
 * 2^-a x 2^-(m-a). */
static int is_net(const float (*p)[2], uint32_t n, int m)
{
    static unsigned char seen[1 << 12];
    for (int a = 0; a <= m; a++) {
        memset(seen, 0, n);
        for (uint32_t k = 0; k < n; k++) {
            uint32_t cx = (uint32_t)(p[k][0] * (float)(1u << a)), cy = (uint32_t)(p[k][1] * (float)(1u << (m - a)));
            uint32_t cell = cx << (m - a) | cy;
            if (cell >= n || seen[cell]++)
                return 0;
        }
    }
    return 1;
}

int main(void)
{
    /* Pure function: the same arguments give the same numbers, whatever
     * was drawn before. */
    float a[PAIRS][2], b[PAIRS][2];
    pairs(5, 7, 3, 11, a);
    pairs(100, 2, 9, 11, b);
    pairs(5, 7, 3, 11, b);
    CHECK(memcmp(a, b, sizeof a) == 0, "same pixel, index and seed give the same numbers");
    pairs(5, 7, 3, 12, b);
    CHECK(memcmp(a, b, sizeof a) != 0, "another seed gives other numbers");

    /* smp_skip passes a pair over and keeps the rest. */
    fr_sampler s;
    smp_start(&s, 5, 7, 3, 11);
    float u, v;
    smp_2d(&s, &u, &v);
    smp_skip(&s);
    smp_2d(&s, &u, &v);
    CHECK(u == a[2][0] && v == a[2][1], "skip: pair 2 is %g %g, not %g %g", u, v, a[2][0], a[2][1]);

    /* Every power-of-two prefix up to 4096 samples is a (0, m, 2)-net, in
     * every pair, for a few pixels; numbers lie in [0, 1). */
    enum { N = 4096 };
    static float pts[PAIRS][N][2];
    uint32_t px[][2] = {{0, 0}, {1, 0}, {511, 377}, {4000, 1}};
    int nets = 1, range = 1;
    for (size_t q = 0; q < sizeof px / sizeof *px; q++) {
        for (uint32_t i = 0; i < N; i++) {
            float uv[PAIRS][2];
            pairs(px[q][0], px[q][1], i, 0, uv);
            for (int d = 0; d < PAIRS; d++) {
                pts[d][i][0] = uv[d][0];
                pts[d][i][1] = uv[d][1];
                range &= uv[d][0] >= 0.0f && uv[d][0] < 1.0f && uv[d][1] >= 0.0f && uv[d][1] < 1.0f;
            }
        }
        for (int d = 0; d < PAIRS; d++)
            for (int m = 0; (1 << m) <= N; m++)
                if (!is_net((const float (*)[2])pts[d], 1u << m, m)) {
                    nets = 0;
                    printf("pixel %u,%u pair %d: the first %d samples are no net\n", px[q][0], px[q][1], d, 1 << m);
                }
    }
    CHECK(nets, "every power-of-two prefix is a (0, m, 2)-net");
    CHECK(range, "numbers lie in [0, 1)");

    /* Pairs are shuffled against each other: over 4096 samples of one
     * pixel the correlation of any two coordinates of different pairs is
     * near 0 (a pair that were a copy or a fixed permutation of another
     * would show ±1 or a structured value well off 0).  Bound: 5 standard
     * errors of a correlation over 4096 independent samples. */
    double worst = 0.0;
    for (int d = 0; d < PAIRS; d++)
        for (int e = d + 1; e < PAIRS; e++)
            for (int c = 0; c < 4; c++) {
                double sxy = 0, sx = 0, sy = 0;
                for (uint32_t i = 0; i < N; i++) {
                    double x = pts[d][i][c & 1], y = pts[e][i][c >> 1];
                    sx += x;
                    sy += y;
                    sxy += x * y;
                }
                double cov = sxy / N - (sx / N) * (sy / N), r = cov / (1.0 / 12.0);
                if (fabs(r) > worst)
                    worst = fabs(r);
            }
    CHECK(worst < 5.0 / 64.0, "largest correlation between pairs %.4f", worst);

    /* smp_random: uniform (16 bins of 65536 draws within 5 %), and
     * uncorrelated with the stratified pair drawn before it. */
    uint32_t bins[16] = {0};
    double sxy = 0, sx = 0, sy = 0;
    const uint32_t M = 65536;
    for (uint32_t i = 0; i < M; i++) {
        smp_start(&s, i % 256, i / 256, i % 7, 3);
        smp_2d(&s, &u, &v);
        float r = smp_random(&s);
        bins[(int)(r * 16.0f)]++;
        sx += u;
        sy += r;
        sxy += (double)u * r;
    }
    int flat = 1;
    for (int k = 0; k < 16; k++)
        flat &= fabs((double)bins[k] - M / 16.0) < 0.05 * M / 16.0;
    CHECK(flat, "smp_random is uniform");
    double r = (sxy / M - (sx / M) * (sy / M)) * 12.0;
    CHECK(fabs(r) < 5.0 / 256.0, "smp_random against the pair before it: correlation %.4f", r);

    /* Seeds shared between a pixel's samples (smp_start_shared) give the
     * numbers smp_start gives, bit for bit: samples of one pixel in a row,
     * another pixel in between (the shared seeds start over), a skipped
     * pair, smp_random among the pairs, more pairs than are shared, and a
     * shared block that held another pixel's seeds at the start. */
    smp_shared sh;
    memset(&sh, 0xa5, sizeof sh);
    int same = 1;
    uint32_t order[][2] = {{5, 7}, {5, 7}, {5, 7}, {6, 7}, {6, 7}, {5, 7}, {0, 0}, {0, 0}};
    for (uint32_t k = 0; k < sizeof order / sizeof *order; k++)
        for (uint32_t index = 0; index < 5; index++) {
            fr_sampler a, b;
            smp_start(&a, order[k][0], order[k][1], index + k, 11);
            smp_start_shared(&b, &sh, order[k][0], order[k][1], index + k, 11);
            for (int d = 0; d < SMP_SHARED_PAIRS + 6; d++) {
                float ua, va, ub, vb;
                if (d % 7 == 3) {
                    smp_skip(&a);
                    smp_skip(&b);
                } else if (d % 5 == 4) {
                    ua = smp_random(&a);
                    ub = smp_random(&b);
                    same &= ua == ub;
                } else {
                    smp_2d(&a, &ua, &va);
                    smp_2d(&b, &ub, &vb);
                    same &= ua == ub && va == vb;
                }
            }
        }
    CHECK(same, "shared seeds give the same numbers as smp_start");
    /* The same pixel under another scene seed, then a zeroed block and
     * pixel (0, 0) with seed 0, whose coordinates a zeroed block holds. */
    uint32_t seeds[] = {11, 12, 12, 0};
    for (uint32_t k = 0; k < 4; k++) {
        if (k == 3)
            memset(&sh, 0, sizeof sh);
        uint32_t x = k == 3 ? 0 : 5, y = k == 3 ? 0 : 7;
        fr_sampler a, b;
        smp_start(&a, x, y, 3, seeds[k]);
        smp_start_shared(&b, &sh, x, y, 3, seeds[k]);
        for (int d = 0; d < 8; d++) {
            float ua, va, ub, vb;
            smp_2d(&a, &ua, &va);
            smp_2d(&b, &ub, &vb);
            CHECK(ua == ub && va == vb, "seed %u, pixel (%u, %u): shared pair %d differs", seeds[k], x, y, d);
        }
    }

    /* Pixels differ: pair 0 of sample 0 over many pixels is uniform. */
    uint32_t cells[64] = {0};
    for (uint32_t k = 0; k < 64 * 256; k++) {
        float uv[PAIRS][2];
        pairs(k % 128, k / 128, 0, 0, uv);
        cells[(int)(uv[0][0] * 8.0f) * 8 + (int)(uv[0][1] * 8.0f)]++;
    }
    int even = 1;
    for (int k = 0; k < 64; k++)
        even &= cells[k] > 256 * 0.7 && cells[k] < 256 * 1.3;
    CHECK(even, "pixels are scrambled independently");
    return check_done();
}
