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

/* Seeds of the generators: chain k's mutations and its start, apart. */
#define SEED_CHAIN 2ull
#define SEED_START 3ull

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
    mlt_counts *counts;        /* per depth, or NULL */
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
    r->counts = NULL;
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

int mlt_bootstrap(const fr_scene *s, uint32_t n, mlt_boot *bt, fr_error *err)
{
    memset(bt, 0, sizeof *bt);
    bt->nd = s->settings.max_depth + 1;
    bt->bd = calloc(bt->nd, sizeof *bt->bd);
    /* b_d: each depth's mean luminance by bidirectional path tracing over
     * the image, all strategies MIS-weighted and the pixels stratified. */
    if (!bt->bd || bd_depth_means(s, n, bt->bd) < 0) {
        mlt_boot_free(bt);
        return fr_fail(err, "out of memory for the Metropolis normalisation");
    }
    /* In float, as the coordinator hands it to the workers (--mlt-norm): a
     * worker that computes it gives the same bits. */
    for (uint32_t d = 0; d < bt->nd; d++)
        bt->b += bt->bd[d] = (float)bt->bd[d];
    return 0;
}

uint32_t mlt_norm_samples(const fr_scene *s)
{
    uint64_t n = (uint64_t)s->settings.width * s->settings.height * s->settings.spp / MLT_NORM_SHARE;
    return n < MLT_NORM_MIN ? MLT_NORM_MIN : n > MLT_NORM_MAX ? MLT_NORM_MAX : (uint32_t)n;
}

int mlt_boot_set(mlt_boot *bt, const float *bd, uint32_t nd, fr_error *err)
{
    memset(bt, 0, sizeof *bt);
    bt->nd = nd;
    if (!(bt->bd = calloc(nd ? nd : 1, sizeof *bt->bd)))
        return fr_fail(err, "out of memory for the Metropolis normalisation");
    for (uint32_t d = 0; d < nd; d++)
        bt->b += bt->bd[d] = bd[d];
    return 0;
}

void mlt_boot_free(mlt_boot *bt)
{
    free(bt->bd);
    bt->bd = NULL;
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

/* The start of chain k, at depth d: the best of MLT_START_CANDIDATES
 * independent states of depth d (from generator seeds of the chain's
 * own), one picked with probability f_j / sum f (importance resampling,
 * so that the start is distributed about as f is); when all are black,
 * MLT_START_CANDIDATES more, up to MLT_START_MAX.  Leaves the chain's
 * state at the picked candidate's, in *x. */
static void start_state(runner *r, uint32_t k, int d, state *x)
{
    uint32_t seed = r->s->settings.seed, best = 0;
    uint64_t pick_rng = key(SEED_START, seed, k);
    double sum = 0.0;
    for (uint32_t j = 0; j < MLT_START_MAX && (j < MLT_START_CANDIDATES || !(sum > 0.0)); j++) {
        mlt_restart(&r->ch, key(SEED_START, seed, k) ^ (uint64_t)(j + 1) << 40);
        evaluate(r, d, x);
        if (!(x->f > 0.0f))
            continue;
        sum += x->f;
        /* Keep j with probability f_j / (sum so far): j ends up picked with
         * probability f_j / sum. */
        mlt_chain g = {.rng = pick_rng};
        float u = mlt_uniform(&g);
        pick_rng = g.rng;
        if ((double)u * sum < x->f)
            best = j;
    }
    mlt_restart(&r->ch, key(SEED_START, seed, k) ^ (uint64_t)(best + 1) << 40);
    evaluate(r, d, x);
}

/* Run chain k of n_chains: the chains of depth 0 first, then depth 1's...
 * (per_depth); each starts from start_state. */
static void run_chain(runner *r, const mlt_boot *bt, uint32_t k, uint32_t n_chains, const uint32_t *per_depth,
                      uint64_t mutations)
{
    uint32_t seed = r->s->settings.seed, d = 0, q = k;
    while (q >= per_depth[d]) {
        q -= per_depth[d];
        d++;
    }
    state x, y;
    start_state(r, k, (int)d, &x);
    /* Depth d's light over its chains' share of the mutations. */
    r->scale = bt->bd[d] * n_chains / per_depth[d];
    mlt_reseed(&r->ch, key(SEED_CHAIN, seed, k) ^ 0x5bd1e995u);
    for (uint64_t m = 0; m < mutations; m++) {
        mlt_step(&r->ch, 0);
        evaluate(r, (int)d, &y);
        float a = x.f > 0.0f ? (y.f >= x.f ? 1.0f : y.f / x.f) : 1.0f;
        splat_state(r, &y, a);
        splat_state(r, &x, 1.0f - a);
        int accept = mlt_uniform(&r->ch) < a;
        if (r->counts) {
            r->counts[d].proposed[r->ch.large]++;
            r->counts[d].accepted[r->ch.large] += (uint64_t)accept;
        }
        if (accept) {
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
    return mlt_chains_counted(s, bt, k0, k1, n_chains, mutations, splat, NULL, err);
}

int mlt_chains_counted(const fr_scene *s, const mlt_boot *bt, uint32_t k0, uint32_t k1, uint32_t n_chains,
                       uint64_t mutations, uint64_t *splat, mlt_counts *counts, fr_error *err)
{
    if (!(bt->b > 0.0))
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
    r.counts = counts;
    for (uint32_t k = k0; k < k1; k++)
        run_chain(&r, bt, k, n_chains, per_depth, mutations);
    runner_close(&r);
    free(per_depth);
    return 0;
}

/* The short paths' samples per pixel (MLT_SHORT_MUL, MLT_SHORT_DIV). */
static uint32_t short_spp(const fr_scene *s)
{
    uint64_t n = (uint64_t)s->settings.spp * MLT_SHORT_MUL / MLT_SHORT_DIV;
    return n < 1 ? 1 : n > UINT32_MAX ? UINT32_MAX : (uint32_t)n;
}

int mlt_render_rows(const fr_scene *s, const mlt_boot *given, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat,
                    fr_error *err)
{
    if (mlt_supported(s, err) < 0)
        return -1;
    mlt_boot own;
    if (!given && mlt_bootstrap(s, mlt_norm_samples(s), &own, err) < 0)
        return -1;
    if (given && given->nd != s->settings.max_depth + 1)
        return fr_fail(err, "the Metropolis normalisation has %u depths, the scene %u (max_depth + 1)", given->nd,
                       s->settings.max_depth + 1);
    const mlt_boot *bt = given ? given : &own;
    /* The short paths by bidirectional path tracing into the rows' own
     * pixels and the splats; the chains get only the longer depths. */
    int rc = bd_render_short(s, y0, y1, MLT_SHORT_DEPTH + 1, short_spp(s), rgb, splat, err);
    mlt_boot long_only = {.bd = NULL};
    if (rc == 0 && mlt_boot_long(bt, MLT_SHORT_DEPTH, &long_only, err) < 0)
        rc = -1;
    if (rc == 0)
        rc = mlt_chains(s, &long_only, y0, y1, s->settings.height, (uint64_t)s->settings.width * s->settings.spp,
                        splat, err);
    mlt_boot_free(&long_only);
    if (!given)
        mlt_boot_free(&own);
    return rc;
}

int mlt_boot_long(const mlt_boot *bt, int short_depth, mlt_boot *out, fr_error *err)
{
    memset(out, 0, sizeof *out);
    out->nd = bt->nd;
    if (!(out->bd = calloc(bt->nd ? bt->nd : 1, sizeof *out->bd)))
        return fr_fail(err, "out of memory for the Metropolis normalisation");
    for (uint32_t d = 0; d < bt->nd; d++)
        out->b += out->bd[d] = (int)d > short_depth ? bt->bd[d] : 0.0;
    return 0;
}
