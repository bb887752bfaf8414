/** @file mlt.h
 * The Markov chain of primary-sample-space Metropolis light transport
 * (Kelemen, Szirmay-Kalos, Antal and Csonka 2002, "A simple and robust
 * mutation strategy for the Metropolis light transport algorithm").
 *
 * A chain's state is a vector of primary samples, numbers in [0, 1) that
 * a path is built from.  Each iteration proposes a new vector: with
 * probability p_large a large step (every number drawn afresh, uniform:
 * an independent proposal), else a small step (every number moved by
 * Kelemen's exponential perturbation, a distance between s1 = 1/1024 and
 * s2 = 1/16 with density proportional to 1/distance, either way, wrapped
 * around [0, 1); Kelemen et al. take s2 = 1/64, which mixes slower: on
 * the Cornell box it left a third more RMSE at the same mutations).  Both proposals are symmetric, so a target f is
 * sampled by accepting with probability min(1, f(y) / f(x)).
 *
 * Mutations are lazy, as Kelemen et al. describe: a number is perturbed
 * only when the path asks for it (mlt_next), by as many small steps as
 * iterations passed since it was last set, but at most MLT_LAZY_MAX (a
 * fixed function of that count, so the composed step stays symmetric;
 * Kelemen et al. take one per iteration), or drawn afresh when a large
 * step was accepted since.  The value before
 * the iteration is kept, and mlt_reject puts it back.
 *
 * The numbers are split into interleaved streams (camera and light
 * subpaths: stream i's k-th number is dimension k * n_streams + i), so
 * that a subpath's numbers keep their meaning whatever the other subpath
 * used (Hachisuka, Kaplanyan and Dachsbacher 2014, sec. 4).
 *
 * Randomness: every choice of a chain (the steps' kinds, the new numbers,
 * the acceptance) comes from one 64-bit counter-based generator seeded by
 * the caller, so a chain is a pure function of its seed.  Everything is
 * float arithmetic without libm (fmath.h) and gives the same bits on
 * every machine.
 */
#ifndef FRANJA_MLT_H
#define FRANJA_MLT_H

#include <stdint.h>

#define MLT_MAX_STREAMS 4
/** Most small steps applied at once to a number left alone for longer
 * (each costs an exponential: the numbers a strategy reads only now and
 * then would otherwise take most of a mutation's time). */
#define MLT_LAZY_MAX 1

typedef struct {
    float value, backup;       /**< the number, and its value before this iteration */
    uint64_t set, backup_set;  /**< the iteration that last set it, and before this iteration */
} mlt_dim;

/** A chain; fields are read-only to callers. */
typedef struct {
    mlt_dim *x;                /**< cap dimensions (owned) */
    uint32_t cap;
    uint32_t used;             /**< dimensions [0, used) have been set */
    uint32_t n_streams;
    uint32_t pos[MLT_MAX_STREAMS];   /**< next index of each stream this iteration */
    uint64_t rng;              /**< the generator's counter */
    uint64_t iter;             /**< current iteration (0: the state before any) */
    uint64_t last_large;       /**< the iteration of the last accepted large step */
    int large;                 /**< this iteration is a large step */
    float p_large;
} mlt_chain;

/** A chain of at most cap dimensions in n_streams (1..MLT_MAX_STREAMS)
 * streams, its generator seeded by seed, large steps with probability
 * p_large in [0, 1].  Its state starts as an accepted large step: the
 * first iteration's numbers (mlt_next before any mlt_step) are uniform.
 * -1 when out of memory.  Free with mlt_free. */
int mlt_init(mlt_chain *c, uint32_t cap, uint32_t n_streams, uint64_t seed, float p_large);
void mlt_free(mlt_chain *c);

/** Forget the state: as mlt_init left it, the generator seeded by seed. */
void mlt_restart(mlt_chain *c, uint64_t seed);

/** Restart the generator from seed, keeping the state (a chain started
 * from another's state: a bootstrap sample's). */
void mlt_reseed(mlt_chain *c, uint64_t seed);

/** A uniform number in [0, 1) from the chain's generator. */
float mlt_uniform(mlt_chain *c);

/** Begin an iteration: a proposal, large with probability p_large (or
 * when force_large), whose numbers mlt_next hands out. */
void mlt_step(mlt_chain *c, int force_large);

/** The next number of stream i of this iteration's proposal.  Past cap
 * dimensions: a fresh uniform number, not kept (the caller sizes cap). */
float mlt_next(mlt_chain *c, uint32_t stream);

/** Keep the proposal / return to the state before it. */
void mlt_accept(mlt_chain *c);
void mlt_reject(mlt_chain *c);

/** One of Kelemen's small steps of u in [0, 1) by the uniform numbers a
 * (distance) and b (direction); the result is in [0, 1). */
float mlt_perturb(float u, float a, float b);

#endif
