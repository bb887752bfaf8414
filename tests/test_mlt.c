/* test_mlt.c -- the Metropolis kernel samples a known 1D density, accepts
 * large steps as often as theory says, keeps detailed balance, restores
 * rejected states and is a pure function of its seed.
 *
 * The chain of common/mlt.h on f(x) = 0.1 + x^2 over [0, 1): the visited
 * states' histogram and the expected-value splats' histogram against the
 * density (L1 distance), the large steps' acceptance rate against its
 * integral E[min(1, f(y) / f(x))] (x ~ f, y uniform) by quadrature, and the
 * transitions between bins counted both ways (a stationary reversible
 * chain makes as many i -> j as j -> i). */
#include <math.h>
#include <string.h>

#include "check.h"
#include "mlt.h"

#define BINS 16
#define ITERS 2000000

static double target(double x) { return 0.1 + x * x; }

/* Integral of the target over bin i, over its whole integral. */
static double bin_prob(int i)
{
    double a = (double)i / BINS, b = (double)(i + 1) / BINS;
    double cdf_a = 0.1 * a + a * a * a / 3.0, cdf_b = 0.1 * b + b * b * b / 3.0;
    return (cdf_b - cdf_a) / (0.1 + 1.0 / 3.0);
}

static int bin_of(float x) { return x * BINS < BINS ? (int)(x * BINS) : BINS - 1; }

int main(void)
{
    /* The chain on the 1D target. */
    mlt_chain c;
    CHECK(mlt_init(&c, 4, 1, 7, 0.3f) == 0, "mlt_init");
    static double visits[BINS], splats[BINS], trans[BINS][BINS];
    double large = 0, large_acc = 0, small = 0, small_acc = 0;
    int outside = 0, unrestored = 0;
    float x = mlt_next(&c, 0);
    double fx = target(x);
    for (int it = 0; it < ITERS; it++) {
        mlt_step(&c, 0);
        float y = mlt_next(&c, 0);
        outside += !(y >= 0.0f && y < 1.0f);
        double fy = target(y), a = fy >= fx ? 1.0 : fy / fx;
        splats[bin_of(y)] += a;
        splats[bin_of(x)] += 1.0 - a;
        int from = bin_of(x), acc = mlt_uniform(&c) < a;
        if (c.large) {
            large++;
            large_acc += acc;
        } else {
            small++;
            small_acc += acc;
        }
        if (acc) {
            mlt_accept(&c);
            x = y;
            fx = fy;
        } else {
            mlt_reject(&c);
            unrestored += c.x[0].value != x;
        }
        visits[bin_of(x)]++;
        trans[from][bin_of(x)]++;
    }
    CHECK(outside == 0, "%d proposals outside [0, 1)", outside);
    CHECK(unrestored == 0, "%d rejected proposals not restored", unrestored);
    double l1_visit = 0, l1_splat = 0;
    for (int i = 0; i < BINS; i++) {
        l1_visit += fabs(visits[i] / ITERS - bin_prob(i));
        l1_splat += fabs(splats[i] / ITERS - bin_prob(i));
    }
    CHECK(l1_visit < 0.02, "visited states' L1 distance to the density %g", l1_visit);
    CHECK(l1_splat < 0.02, "expected-value splats' L1 distance to the density %g", l1_splat);
    CHECK(fabs(large / ITERS - 0.3) < 0.005, "large steps %g of the iterations, expected 0.3", large / ITERS);

    /* Large steps are independent proposals: acceptance E[min(1, f(y)/f(x))]. */
    double expect = 0, norm = 0.1 + 1.0 / 3.0;
    const int Q = 1000;
    for (int i = 0; i < Q; i++)
        for (int j = 0; j < Q; j++) {
            double xi = (i + 0.5) / Q, yj = (j + 0.5) / Q, r = target(yj) / target(xi);
            expect += target(xi) / norm * (r < 1.0 ? r : 1.0);
        }
    expect /= (double)Q * Q;
    CHECK(fabs(large_acc / large - expect) < 0.01, "large-step acceptance %g, expected %g", large_acc / large,
          expect);
    /* Small steps move at most 1/64 on a smooth target: nearly all accepted. */
    CHECK(small_acc / small > 0.9 && small_acc / small < 1.0, "small-step acceptance %g", small_acc / small);

    /* Detailed balance: as many transitions i -> j as j -> i. */
    int unbalanced = 0;
    for (int i = 0; i < BINS; i++)
        for (int j = i + 1; j < BINS; j++) {
            double n = trans[i][j] + trans[j][i];
            if (fabs(trans[i][j] - trans[j][i]) > 4.0 * sqrt(n) + 10.0)
                unbalanced++;
        }
    CHECK(unbalanced == 0, "%d bin pairs out of detailed balance", unbalanced);
    mlt_free(&c);

    /* A number read only every 7th iteration is moved lazily by a
     * symmetric step: from uniform, it stays uniform (many short chains,
     * their last values). */
    CHECK(mlt_init(&c, 8, 2, 3, 0.0f) == 0, "mlt_init");
    static double lazy[BINS];
    const int CHAINS = 100000;
    for (int k = 0; k < CHAINS; k++) {
        mlt_restart(&c, (uint64_t)k + 1000);
        float v = 0.0f;
        for (int it = 0; it < 50; it++) {
            mlt_step(&c, 0);
            (void)mlt_next(&c, 0);
            if (it % 7 == 0)
                v = mlt_next(&c, 1);
            mlt_accept(&c);
        }
        lazy[bin_of(v)]++;
    }
    double l1_lazy = 0;
    for (int i = 0; i < BINS; i++)
        l1_lazy += fabs(lazy[i] / CHAINS - 1.0 / BINS);
    CHECK(l1_lazy < 0.03, "lazily mutated stream's L1 distance to uniform %g", l1_lazy);
    mlt_free(&c);

    /* Restore: a rejected large step gives back every number it changed. */
    CHECK(mlt_init(&c, 8, 2, 11, 0.5f) == 0, "mlt_init");
    float before[4];
    for (int i = 0; i < 4; i++)
        before[i] = mlt_next(&c, (uint32_t)i & 1);
    mlt_step(&c, 1);
    int changed = 0;
    for (int i = 0; i < 4; i++)
        changed += mlt_next(&c, (uint32_t)i & 1) != before[i];
    CHECK(changed == 4, "a large step changed %d of 4 numbers", changed);
    mlt_reject(&c);
    for (int i = 0; i < 4; i++)
        CHECK(c.x[i].value == before[i], "number %d not restored", i);
    mlt_free(&c);

    /* Determinism: the same seed, the same numbers; another seed, others. */
    mlt_chain p, q, o;
    CHECK(mlt_init(&p, 8, 2, 5, 0.3f) == 0 && mlt_init(&q, 8, 2, 5, 0.3f) == 0 && mlt_init(&o, 8, 2, 6, 0.3f) == 0,
          "mlt_init");
    int same = 1, other = 0;
    for (int it = 0; it < 1000; it++) {
        mlt_step(&p, 0);
        mlt_step(&q, 0);
        mlt_step(&o, 0);
        for (uint32_t k = 0; k < 4; k++) {
            float a = mlt_next(&p, k & 1), b = mlt_next(&q, k & 1);
            same &= memcmp(&a, &b, sizeof a) == 0;
            other += mlt_next(&o, k & 1) != a;
        }
        if (it & 1) {
            mlt_accept(&p);
            mlt_accept(&q);
            mlt_accept(&o);
        } else {
            mlt_reject(&p);
            mlt_reject(&q);
            mlt_reject(&o);
        }
    }
    CHECK(same, "two chains of one seed differ");
    CHECK(other > 3900, "chains of two seeds agree on %d of 4000 numbers", 4000 - other);
    mlt_free(&p);
    mlt_free(&q);
    mlt_free(&o);

    /* The small step stays in [0, 1) at the ends. */
    const float ends[] = {0.0f, 1e-9f, 0.5f, 0.99999994f};
    int inside = 1;
    for (int i = 0; i < 4; i++)
        for (int a = 0; a <= 16; a++)
            for (int b = 0; b < 2; b++) {
                float v = mlt_perturb(ends[i], a == 16 ? 0.99999994f : a / 16.0f, b ? 0.75f : 0.25f);
                inside &= v >= 0.0f && v < 1.0f;
            }
    CHECK(inside, "a small step left [0, 1)");
    return check_done();
}
