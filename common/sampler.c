/* sampler.c -- the pixel sample's random numbers: Owen-scrambled 2D Sobol
 * pairs (see sampler.h). */

#include "sampler.h"

#include <stddef.h>

uint32_t smp_hash(uint32_t x)
{
    /* Two multiply-xorshift rounds (Wellons' "lowbias32" constants). */
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

static inline uint32_t reverse_bits(uint32_t x)
{
    x = __builtin_bswap32(x);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu);
    x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);
    x = ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);
    return x;
}

/* Both halves of x bit-reversed and swapped: two 32-bit reversals for the
 * price of one. */
static inline uint64_t reverse_bits2(uint64_t x)
{
    x = __builtin_bswap64(x);
    x = ((x & 0x0f0f0f0f0f0f0f0full) << 4) | ((x >> 4) & 0x0f0f0f0f0f0f0f0full);
    x = ((x & 0x3333333333333333ull) << 2) | ((x >> 2) & 0x3333333333333333ull);
    x = ((x & 0x5555555555555555ull) << 1) | ((x >> 1) & 0x5555555555555555ull);
    return x;
}

/* A 64-bit bijective mix with full avalanche (the finalizer of Steele,
 * Lea and Flood's SplitMix64): 64 random bits for two multiplications. */
static inline uint64_t mix64(uint64_t z)
{
    z ^= z >> 30;
    z *= 0xbf58476d1ce4e5b9ull;
    z ^= z >> 27;
    z *= 0x94d049bb133111ebull;
    z ^= z >> 31;
    return z;
}

/* Laine-Karras permutation of a bit-reversed 32-bit fraction: each bit is
 * flipped by a hash of the bits below it (the more significant bits of the
 * fraction), which adding a seed and xor-ing with multiples by even
 * constants affect only upward.  reverse(lk(reverse(x))) is Owen
 * scrambling of x (Laine and Karras 2011; constants from Burley 2020). */
static inline uint32_t lk_permute(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* The second Sobol dimension, bit-reversed, as a function of the index.
 * Its generator matrix (primitive polynomial x + 1) is Pascal's triangle
 * mod 2: digit r of the value is the xor of the index bits k with
 * k & r == r (Lucas' theorem).  That superset sum over GF(2) takes five
 * shift-and-xor steps, one per bit of the digit position. */
static inline uint32_t sobol1_rev(uint32_t i)
{
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0f0f0f0fu;
    i ^= (i >> 8) & 0x00ff00ffu;
    i ^= (i >> 16) & 0x0000ffffu;
    return i;
}

static inline float to_unit(uint32_t x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* The odd 64-bit constant of the golden ratio: consecutive dimension
 * pairs land far apart before mixing. */
#define GOLDEN64 0x9e3779b97f4a7c15ull

static inline uint64_t pixel_hash(uint32_t x, uint32_t y, uint32_t seed)
{
    return (uint64_t)smp_hash(x ^ smp_hash(y ^ smp_hash(seed + 0x9e3779b9u))) << 32;
}

void smp_start(fr_sampler *s, uint32_t x, uint32_t y, uint32_t index, uint32_t seed)
{
    s->pixel = pixel_hash(x, y, seed);
    s->index = index;
    s->rindex = reverse_bits(index);
    s->dim = 0;
    s->shared = NULL;
}

void smp_start_shared(fr_sampler *s, smp_shared *shared, uint32_t x, uint32_t y, uint32_t index, uint32_t seed)
{
    /* The pixel's hash too is the one its previous sample made. */
    if (!(shared->keyed == 1 && shared->x == x && shared->y == y && shared->seed == seed)) {
        uint64_t pixel = pixel_hash(x, y, seed);
        if (!(shared->keyed == 1 && shared->pixel == pixel))
            shared->valid = 0;
        shared->pixel = pixel;
        shared->x = x;
        shared->y = y;
        shared->seed = seed;
        shared->keyed = 1;
    }
    s->pixel = shared->pixel;
    s->index = index;
    s->rindex = reverse_bits(index);
    s->dim = 0;
    s->shared = shared;
}

/* The seeds of dimension pair d: the pair's mix h (returned), and when sv
 * is not NULL the second coordinate's seed, a mix of h.  The key
 * pixel * 2^32 + pair * GOLDEN64 differs for every pixel and pair below
 * 2^32, and mix64 is a bijection.  Both depend on the pixel and the pair
 * only, so the pixel's samples share them where s->shared is set. */
static inline uint64_t pair_seeds(fr_sampler *s, uint32_t d, uint32_t *sv)
{
    smp_shared *c = s->shared;
    if (c && d < SMP_SHARED_PAIRS && (c->valid >> d & 1)) {
        if (sv)
            *sv = c->pair[d].sv;
        return c->pair[d].h;
    }
    uint64_t h = mix64(s->pixel + d * GOLDEN64);
    if (c && d < SMP_SHARED_PAIRS) {
        c->pair[d].h = h;
        c->pair[d].sv = (uint32_t)mix64(h ^ GOLDEN64);
        c->valid |= (uint64_t)1 << d;
        if (sv)
            *sv = c->pair[d].sv;
    } else if (sv)
        *sv = (uint32_t)mix64(h ^ GOLDEN64);
    return h;
}

/* Inlined where it is called (always_inline: the link-time optimiser
 * would keep it a call for its size): the sampler's state and the two
 * results stay in registers. */
__attribute__((always_inline)) inline void smp_2d(fr_sampler *s, float *u, float *v)
{
    /* Owen-scramble the index to shuffle the order per dimension pair, take
     * the point of the 2D Sobol sequence, Owen-scramble both coordinates
     * (the first Sobol dimension is the bit reversal of the index, so its
     * scrambling needs one reversal, not three).  The three scrambling
     * seeds come from two 64-bit mixes of (pixel, pair) (pair_seeds).  The
     * index's bit reversal is made once per sample (smp_start), and the
     * two coordinates are reversed together in one 64-bit word. */
    uint32_t sv;
    uint64_t h = pair_seeds(s, s->dim++, &sv);
    uint32_t i = reverse_bits(lk_permute(s->rindex, (uint32_t)h));
    uint64_t r = reverse_bits2((uint64_t)lk_permute(sobol1_rev(i), sv) << 32 | lk_permute(i, (uint32_t)(h >> 32)));
    *u = to_unit((uint32_t)(r >> 32));
    *v = to_unit((uint32_t)r);
}

float smp_random(fr_sampler *s)
{
    /* The pair's mix, offset by the index and mixed again: not stratified,
     * and unrelated to every smp_2d number (those are mixes of keys, not of
     * mixes plus an index). */
    uint64_t h = pair_seeds(s, s->dim++, NULL);
    return to_unit((uint32_t)(mix64(h + (uint64_t)(s->index + 1) * 0xd6e8feb86659fd93ull) >> 32));
}
