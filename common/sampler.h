/** @file sampler.h
 * The random numbers of a pixel sample.
 *
 * Counter-based: every number is a pure function of (pixel x, pixel y,
 * sample index, dimension, scene seed), so a slab of rows renders the same
 * bits whatever process, host or split renders it (invariant 1).
 *
 * The numbers are stratified: each pair of dimensions is the 2D Sobol
 * (0,2)-sequence, Owen-scrambled per pixel and per dimension pair, with the
 * sample order shuffled per dimension pair so that pairs do not correlate
 * ("padding"; Burley 2020, "Practical hash-based Owen scrambling").  Any
 * prefix of a pixel's samples is well stratified, whatever the sample
 * count.
 */
#ifndef FRANJA_SAMPLER_H
#define FRANJA_SAMPLER_H

#include <stdint.h>

/** The scrambling seeds of one pixel's dimension pairs, which do not
 * depend on the sample index: a pixel's samples can share them (see
 * smp_start_shared).  Filled as the pairs are first drawn; valid bit d
 * says that pair d holds its seeds. */
#define SMP_SHARED_PAIRS 64
typedef struct {
    uint64_t pixel;            /**< the pixel hash the entries belong to (fr_sampler.pixel) */
    uint32_t x, y, seed;       /**< the pixel and scene seed that `pixel` hashes */
    uint32_t keyed;            /**< 1: x, y, seed and pixel are set (a zeroed block holds no pixel) */
    uint64_t valid;            /**< bit d: pair d is filled */
    struct {
        uint64_t h;            /**< index shuffle (low half) and first coordinate (high half) seeds */
        uint32_t sv;           /**< second coordinate seed */
        uint32_t pad;
    } pair[SMP_SHARED_PAIRS];
} smp_shared;

/** Where a pixel sample is in its sequence of random numbers. */
typedef struct {
    uint64_t pixel;            /**< hash of pixel and seed, in the high half */
    uint32_t index;            /**< sample index within the pixel */
    uint32_t rindex;           /**< the index, bit-reversed */
    uint32_t dim;              /**< next dimension pair */
    smp_shared *shared;        /**< seeds shared with the pixel's other samples, or NULL */
} fr_sampler;

/** Start sample `index` of pixel (x, y). */
void smp_start(fr_sampler *s, uint32_t x, uint32_t y, uint32_t index, uint32_t seed);
/** smp_start, keeping the pixel's hash and scrambling seeds in *shared
 * (caller-owned, alive while s is used) so that the pixel's next samples
 * reuse them instead of hashing them again; the numbers are the same bits
 * as smp_start's.  *shared may hold another pixel's seeds (or be zeroed):
 * it is then started over for this pixel. */
void smp_start_shared(fr_sampler *s, smp_shared *shared, uint32_t x, uint32_t y, uint32_t index, uint32_t seed);
/** Next two numbers in [0, 1), from one stratified 2D pattern. */
void smp_2d(fr_sampler *s, float *u, float *v);
/** Next number in [0, 1), not stratified: for decisions that gain nothing
 * from stratification (Russian roulette); cheaper than a stratified number. */
float smp_random(fr_sampler *s);
/** Pass over the next dimension pair without computing it: for a pair
 * that this sample does not use (the lens of a pinhole camera), so that
 * the pairs after it keep their numbers. */
static inline void smp_skip(fr_sampler *s) { s->dim++; }

/** A 32-bit integer hash with good avalanche (used for seeds). */
uint32_t smp_hash(uint32_t x);

#endif
