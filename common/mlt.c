/* mlt.c -- the primary-sample-space Metropolis chain: lazy large and small
 * steps with backup and restore (see mlt.h). */

#include "mlt.h"

#include <stdlib.h>

#include "fmath.h"

/* Bounds of a small step's distance (Kelemen et al.'s s1; s2 four times
 * theirs, mlt.h). */
#define S1 (1.0f / 1024.0f)
#define S2 (1.0f / 16.0f)

static void rewind_streams(mlt_chain *c)
{
    for (uint32_t i = 0; i < MLT_MAX_STREAMS; i++)
        c->pos[i] = 0;
}

int mlt_init(mlt_chain *c, uint32_t cap, uint32_t n_streams, uint64_t seed, float p_large)
{
    c->x = calloc(cap ? cap : 1, sizeof *c->x);
    if (!c->x)
        return -1;
    c->cap = cap;
    c->n_streams = n_streams < 1 ? 1 : n_streams > MLT_MAX_STREAMS ? MLT_MAX_STREAMS : n_streams;
    c->p_large = p_large;
    mlt_restart(c, seed);
    return 0;
}

void mlt_free(mlt_chain *c)
{
    free(c->x);
    c->x = NULL;
}

void mlt_restart(mlt_chain *c, uint64_t seed)
{
    c->used = 0;
    c->iter = 0;
    c->last_large = 0;
    c->large = 1;
    mlt_reseed(c, seed);
    rewind_streams(c);
}

void mlt_reseed(mlt_chain *c, uint64_t seed) { c->rng = seed * 0xd1342543de82ef95ull + 0x2545f4914f6cdd1dull; }

/* A counter stepped by an odd constant and mixed (Steele, Lea and Flood's
 * SplitMix64): the top 24 bits of the mix make the float. */
float mlt_uniform(mlt_chain *c)
{
    uint64_t z = (c->rng += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (float)((z ^ (z >> 31)) >> 40) * (1.0f / 16777216.0f);
}

void mlt_step(mlt_chain *c, int force_large)
{
    c->iter++;
    c->large = force_large || mlt_uniform(c) < c->p_large;
    rewind_streams(c);
}

float mlt_perturb(float u, float a, float b)
{
    /* Distance s2 * (s1/s2)^a = s2 * exp(-ln(s2/s1) a): density ~ 1/d on
     * [s1, s2]; ln(s2/s1) = ln 64. */
    float d = S2 * fm_expf(-4.15888308f * a);
    float v = b < 0.5f ? u + d : u - d;
    if (v >= 1.0f)
        v -= 1.0f;
    if (v < 0.0f)
        v += 1.0f;
    /* u - d + 1 rounding up to 1 (u tiny): wrap to 0. */
    return v < 1.0f ? v : 0.0f;
}

/* Dimensions up to idx given numbers, as if drawn by the last accepted
 * large step. */
static void extend(mlt_chain *c, uint64_t idx)
{
    for (uint32_t i = c->used; i <= idx; i++) {
        c->x[i].value = mlt_uniform(c);
        c->x[i].set = c->last_large;
    }
    if (idx >= c->used)
        c->used = (uint32_t)idx + 1;
}

float mlt_next(mlt_chain *c, uint32_t stream)
{
    uint64_t idx = (uint64_t)c->pos[stream]++ * c->n_streams + stream;
    if (idx >= c->cap)
        return mlt_uniform(c);
    mlt_dim *d = &c->x[idx];
    extend(c, idx);
    if (d->set == c->iter)
        return d->value;       /* already this iteration's */
    /* Bring it up to the last accepted large step, then back it up. */
    if (d->set < c->last_large) {
        d->value = mlt_uniform(c);
        d->set = c->last_large;
    }
    d->backup = d->value;
    d->backup_set = d->set;
    if (c->large) {
        d->value = mlt_uniform(c);
    } else {
        uint64_t n = c->iter - d->set;
        if (n > MLT_LAZY_MAX)
            n = MLT_LAZY_MAX;
        for (uint64_t k = 0; k < n; k++) {
            float a = mlt_uniform(c), b = mlt_uniform(c);
            d->value = mlt_perturb(d->value, a, b);
        }
    }
    d->set = c->iter;
    return d->value;
}

void mlt_accept(mlt_chain *c)
{
    if (c->large)
        c->last_large = c->iter;
}

void mlt_reject(mlt_chain *c)
{
    for (uint32_t i = 0; i < c->used; i++)
        if (c->x[i].set == c->iter) {
            c->x[i].value = c->x[i].backup;
            c->x[i].set = c->x[i].backup_set;
        }
}
