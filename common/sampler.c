#include "sampler.h"

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
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/* Laine-Karras permutation of a bit-reversed 32-bit fraction: each bit is
 * flipped by a hash of the bits below it (the more significant bits of the
 * fraction), which adding a seed and xor-ing with multiples by even
 * constants affect only upward.  reverse(lk(reverse(x))) is Owen
 * scrambling of x (Laine and Karras 2011; constants from Burley 2020). */
static uint32_t lk_permute(uint32_t x, uint32_t seed)
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
static uint32_t sobol1_rev(uint32_t i)
{
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0f0f0f0fu;
    i ^= (i >> 8) & 0x00ff00ffu;
    i ^= (i >> 16) & 0x0000ffffu;
    return i;
}

static float to_unit(uint32_t x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

void smp_start(fr_sampler *s, uint32_t x, uint32_t y, uint32_t index, uint32_t seed)
{
    s->pixel = smp_hash(x ^ smp_hash(y ^ smp_hash(seed + 0x9e3779b9u)));
    s->index = index;
    s->dim = 0;
}

void smp_2d(fr_sampler *s, float *u, float *v)
{
    /* Owen-scramble the index to shuffle the order per dimension pair, take
     * the point of the 2D Sobol sequence, Owen-scramble both coordinates.
     * The first Sobol dimension is the bit reversal of the index, so its
     * scrambling needs one reversal, not three. */
    uint32_t seed = smp_hash(s->pixel ^ smp_hash(s->dim++));
    uint32_t i = reverse_bits(lk_permute(reverse_bits(s->index), seed));
    *u = to_unit(reverse_bits(lk_permute(i, smp_hash(seed + 1))));
    *v = to_unit(reverse_bits(lk_permute(sobol1_rev(i), smp_hash(seed + 2))));
}

float smp_random(fr_sampler *s)
{
    return to_unit(smp_hash(s->pixel ^ smp_hash(s->index ^ smp_hash(s->dim++ + 0x85ebca6bu))));
}

float smp_1d(fr_sampler *s)
{
    float u, v;
    smp_2d(s, &u, &v);
    return u;
}
