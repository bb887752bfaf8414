/* mlt_path.c -- multiplexed Metropolis light transport over bidirectional
 * strategies: bootstrap, chains, expected-value splats (see mlt_path.h). */

#include "mlt_path.h"

#include <stdlib.h>
#include <string.h>

#include "bdpt.h"
#include "mlt.h"
#include "splat.h"

/* Streams of a state's numbers (mlt_path.h). */
enum { ST_CAMERA, ST_LIGHT, ST_STRATEGY, N_STREAMS };

/* Seeds of the generators: bootstrap state i and chain k, apart. */
#define SEED_BOOT 1ull
#define SEED_CHAIN 2ull

typedef struct {
    vec3 c;                    /* the value C */
    float f;                   /* luminance(C); 0: no path */
    uint32_t px, py;           /* its pixel */
} state;

typedef struct {
    const fr_scene *s;
    bd_work *w;
    mlt_chain ch;
    uint64_t *splat;
    double scale;              /* the current chain's: b_d * n_chains / (chains of depth d) */
} runner;

static uint64_t key(uint64_t tag, uint32_t seed, uint32_t k) { return tag << 62 ^ (uint64_t)seed << 32 ^ k; }

static float next_camera(void *ctx) { return mlt_next(ctx, ST_CAMERA); }
static float next_light(void *ctx) { return mlt_next(ctx, ST_LIGHT); }

int mlt_supported(const fr_scene *s, fr_error *err)
{
    if (s->motion.flags)
        return fr_fail(err, "the scene has motion blur, which Metropolis light transport does not support; render "
                            "it with the path or bidirectional integrator");
    fr_error why;
    if (bd_supported(s, &why) < 0)
        return fr_fail(err, "the scene has participating media (fog or a medium inside a shape), which Metropolis "
                            "light transport (over bidirectional paths) does not support; render it with the path "
                            "integrator");
    return 0;
}

/* The state of the chain's current proposal at depth d. */
static void evaluate(runner *r, int d, state *out)
{
    const fr_scene *s = r->s;
    int n = d == 0 ? 1 : d + 2;
    int k = (int)(mlt_next(&r->ch, ST_STRATEGY) * (float)n);
    if (k >= n)
        k = n - 1;
    int t = d == 0 ? 2 : k + 1, s_ = d + 2 - t;
    bd_stream cam = {next_camera, &r->ch}, light = {next_light, &r->ch};
    float rx = 0.0f, ry = 0.0f;
    vec3 c = bd_path(s, r->w, s_, t, &cam, &light, &rx, &ry);
    c = v3_scale(c, (float)n);
    float f = v3_luma(c);
    if (!(f > 0.0f) || !isfinite(f)) {
        out->f = 0.0f;
        out->c = v3s(0.0f);
        out->px = out->py = 0;
        return;
    }
    uint32_t w = s->settings.width, h = s->settings.height;
    out->c = c;
    out->f = f;
    out->px = rx >= 0.0f && rx < (float)w ? (uint32_t)rx : rx >= (float)w ? w - 1 : 0;
    out->py = ry >= 0.0f && ry < (float)h ? (uint32_t)ry : ry >= (float)h ? h - 1 : 0;
}

/* Dimensions a state can use: per stream a strategy number, the camera
 * ray's two pairs or the light's three, and at most 7 numbers per vertex. */
static uint32_t dims(const fr_scene *s) { return N_STREAMS * (8 + 7 * (s->settings.max_depth + 3)); }

static int runner_open(runner *r, const fr_scene *s, uint64_t *splat, fr_error *err)
{
    r->s = s;
    r->splat = splat;
    r->scale = 0.0;
    r->w = bd_work_new(s);
    if (!r->w || mlt_init(&r->ch, dims(s), N_STREAMS, 0, MLT_P_LARGE) < 0) {
        bd_work_free(r->w);
        return fr_fail(err, "out of memory for the Metropolis chains");
    }
    return 0;
}

static void runner_close(runner *r)
{
    mlt_free(&r->ch);
    bd_work_free(r->w);
}

/* The radical inverse of m in base 2, to 24 bits. */
static float radical2(uint32_t m)
{
    uint32_t r = 0;
    for (int b = 0; b < 24; b++, m >>= 1)
        r = r << 1 | (m & 1);
    return (float)r * (1.0f / 16777216.0f);
}

/* Bootstrap states of depth d among n. */
static uint32_t depth_count(uint32_t n, uint32_t nd, uint32_t d) { return n / nd + (d < n % nd); }

/* Bootstrap state i of n, evaluated at its depth (into *st, its depth
 * returned).  Its camera ray is stratified: state m of depth d's count
 * takes the m-th point of a Hammersley set over the image, shifted by a
 * random offset per depth (Cranley-Patterson rotation), so that b_d does
 * not carry the noise of random pixels (small bright lights seen directly
 * would make it). */
static int boot_state(runner *r, uint32_t i, uint32_t n, state *st)
{
    uint32_t nd = r->s->settings.max_depth + 1, d = i % nd, m = i / nd, count = depth_count(n, nd, d);
    mlt_restart(&r->ch, key(SEED_BOOT, r->s->settings.seed, 0xffffffu - d));
    float r0 = mlt_uniform(&r->ch), r1 = mlt_uniform(&r->ch);
    mlt_restart(&r->ch, key(SEED_BOOT, r->s->settings.seed, i));
    float u0 = ((float)m + r0) / (float)count, u1 = radical2(m) + r1;
    mlt_set(&r->ch, ST_CAMERA, 0, u0 < 1.0f ? u0 : 0.99999994f);
    mlt_set(&r->ch, ST_CAMERA, 1, u1 < 1.0f ? u1 : u1 - 1.0f);
    evaluate(r, (int)d, st);
    return (int)d;
}

int mlt_bootstrap(const fr_scene *s, uint32_t n, mlt_boot *bt, fr_error *err)
{
    memset(bt, 0, sizeof *bt);
    uint32_t nd = bt->nd = s->settings.max_depth + 1;
    bt->cdf = malloc(((size_t)n + 1) * sizeof *bt->cdf);
    bt->bd = calloc(nd, sizeof *bt->bd);
    bt->off = calloc((size_t)nd + 1, sizeof *bt->off);
    runner r;
    if (!bt->cdf || !bt->bd || !bt->off || runner_open(&r, s, NULL, err) < 0) {
        mlt_boot_free(bt);
        return fr_fail(err, "out of memory for the Metropolis bootstrap");
    }
    bt->n = n;
    for (uint32_t d = 0; d < nd; d++)
        bt->off[d + 1] = bt->off[d] + depth_count(n, nd, d);
    /* f of state i = d + nd * m at position off[d] + m + 1, then summed up. */
    bt->cdf[0] = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        state st;
        int d = boot_state(&r, i, n, &st);
        bt->cdf[bt->off[d] + i / nd + 1] = st.f;
    }
    /* b_d: each depth's mean luminance by bidirectional path tracing over
     * the image, all strategies MIS-weighted and the pixels stratified (the
     * states' own mean, one random strategy each, is several times noisier
     * where light comes through narrow passages). */
    if (bd_depth_means(s, MLT_BOOTSTRAP_BDPT, bt->bd) < 0) {
        runner_close(&r);
        mlt_boot_free(bt);
        return fr_fail(err, "out of memory for the Metropolis bootstrap");
    }
    for (uint32_t d = 0; d < nd; d++)
        bt->b += bt->bd[d];
    for (uint32_t p = 0; p < n; p++)
        bt->cdf[p + 1] += bt->cdf[p];
    runner_close(&r);
    return 0;
}

void mlt_boot_free(mlt_boot *bt)
{
    free(bt->cdf);
    free(bt->bd);
    free(bt->off);
    bt->cdf = NULL;
    bt->bd = NULL;
    bt->off = NULL;
}

/* Add v * C / f of state st to its pixel's sums. */
static void splat_state(runner *r, const state *st, float v)
{
    if (!(st->f > 0.0f) || !(v > 0.0f))
        return;
    float k = (float)(r->scale / st->f) * v;
    uint64_t *p = r->splat + ((size_t)st->py * r->s->settings.width + st->px) * 3;
    spl_add(&p[0], spl_fixed(st->c.x * k));
    spl_add(&p[1], spl_fixed(st->c.y * k));
    spl_add(&p[2], spl_fixed(st->c.z * k));
}

/* The bootstrap state of depth d whose f-interval holds the fraction u of
 * the depth's total. */
static uint32_t pick(const mlt_boot *bt, uint32_t d, double u)
{
    uint32_t lo = bt->off[d], hi = bt->off[d + 1] - 1;
    double x = bt->cdf[lo] + u * (bt->cdf[hi + 1] - bt->cdf[lo]);
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (bt->cdf[mid + 1] <= x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (lo - bt->off[d]) * bt->nd + d;
}

/* How many of n_chains chains each depth gets (per_depth, bt->nd
 * entries): one for each depth that has light (when there are chains
 * enough), the rest in proportion to b_d by largest remainders. */
static void allocate(const mlt_boot *bt, uint32_t n_chains, uint32_t *per_depth)
{
    uint32_t lit = 0, given = 0;
    for (uint32_t d = 0; d < bt->nd; d++)
        lit += bt->bd[d] > 0.0;
    uint32_t one = n_chains >= lit, rest = n_chains - (one ? lit : 0);
    for (uint32_t d = 0; d < bt->nd; d++) {
        per_depth[d] = bt->bd[d] > 0.0 ? one + (uint32_t)(rest * (bt->bd[d] / bt->b)) : 0;
        given += per_depth[d];
    }
    while (given < n_chains) {
        uint32_t best = 0;
        double best_rem = -1.0;
        for (uint32_t d = 0; d < bt->nd; d++) {
            double share = rest * (bt->bd[d] / bt->b), rem = share - (double)(per_depth[d] - (bt->bd[d] > 0.0) * one);
            if (bt->bd[d] > 0.0 && rem > best_rem) {
                best = d;
                best_rem = rem;
            }
        }
        per_depth[best]++;
        given++;
    }
}

/* Run chain k of n_chains: the chains of depth 0 first, then depth 1's...
 * (per_depth); the q-th of depth d's count starts from the bootstrap state
 * picked by systematic resampling, stratum q of depth d's cumulative f. */
static void run_chain(runner *r, const mlt_boot *bt, uint32_t k, uint32_t n_chains, const uint32_t *per_depth,
                      uint64_t mutations)
{
    uint32_t seed = r->s->settings.seed, d = 0, q = k;
    while (q >= per_depth[d]) {
        q -= per_depth[d];
        d++;
    }
    mlt_restart(&r->ch, key(SEED_CHAIN, seed, k));
    uint32_t j = pick(bt, d, ((double)q + mlt_uniform(&r->ch)) / per_depth[d]);
    state x, y;
    boot_state(r, j, bt->n, &x);
    /* Depth d's light over its chains' share of the mutations. */
    r->scale = bt->bd[d] * n_chains / per_depth[d];
    mlt_reseed(&r->ch, key(SEED_CHAIN, seed, k) ^ 0x5bd1e995u);
    for (uint64_t m = 0; m < mutations; m++) {
        mlt_step(&r->ch, 0);
        evaluate(r, (int)d, &y);
        float a = x.f > 0.0f ? (y.f >= x.f ? 1.0f : y.f / x.f) : 1.0f;
        splat_state(r, &y, a);
        splat_state(r, &x, 1.0f - a);
        if (mlt_uniform(&r->ch) < a) {
            mlt_accept(&r->ch);
            x = y;
        } else {
            mlt_reject(&r->ch);
        }
    }
}

int mlt_chains(const fr_scene *s, const mlt_boot *bt, uint32_t k0, uint32_t k1, uint32_t n_chains, uint64_t mutations,
               uint64_t *splat, fr_error *err)
{
    if (!(bt->b > 0.0) || bt->n == 0)
        return 0;              /* no light reaches the camera: a black image */
    runner r;
    uint32_t *per_depth = calloc(bt->nd, sizeof *per_depth);
    if (!per_depth)
        return fr_fail(err, "out of memory for the Metropolis chains");
    if (runner_open(&r, s, splat, err) < 0) {
        free(per_depth);
        return -1;
    }
    allocate(bt, n_chains, per_depth);
    for (uint32_t k = k0; k < k1; k++)
        run_chain(&r, bt, k, n_chains, per_depth, mutations);
    runner_close(&r);
    free(per_depth);
    return 0;
}

int mlt_render_rows(const fr_scene *s, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat, fr_error *err)
{
    if (mlt_supported(s, err) < 0)
        return -1;
    memset(rgb, 0, (size_t)s->settings.width * (y1 - y0) * 3 * sizeof *rgb);
    uint64_t n = (uint64_t)s->settings.width * s->settings.height * 16;
    n = n < MLT_BOOTSTRAP_MIN ? MLT_BOOTSTRAP_MIN : n > MLT_BOOTSTRAP ? MLT_BOOTSTRAP : n;
    mlt_boot bt;
    if (mlt_bootstrap(s, (uint32_t)n, &bt, err) < 0)
        return -1;
    int rc = mlt_chains(s, &bt, y0, y1, s->settings.height, (uint64_t)s->settings.width * s->settings.spp, splat, err);
    mlt_boot_free(&bt);
    return rc;
}
