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

static uint32_t reverse_bits(uint32_t x)
{
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/* Owen scrambling of a 32-bit fraction: each bit is flipped by a hash of
 * the bits above it.  Working on the reversed value, "bits above" become
 * "bits below", which adding a seed and xor-ing with multiples by even
 * constants affect only upward (Laine and Karras 2011; constants from
 * Burley 2020). */
static uint32_t owen_scramble(uint32_t x, uint32_t seed)
{
    x = reverse_bits(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverse_bits(x);
}

/* The first two dimensions of the Sobol sequence as 32-bit fractions: the
 * van der Corput radical inverse, and the sequence whose direction numbers
 * follow v[k] = v[k-1] ^ (v[k-1] >> 1) (primitive polynomial x + 1). */
static void sobol2(uint32_t i, uint32_t *a, uint32_t *b)
{
    uint32_t v = 0x80000000u, y = 0;
    *a = reverse_bits(i);
    for (; i; i >>= 1) {
        if (i & 1)
            y ^= v;
        v ^= v >> 1;
    }
    *b = y;
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
    uint32_t seed = smp_hash(s->pixel ^ smp_hash(s->dim++));
    uint32_t i = owen_scramble(s->index, seed);
    uint32_t a, b;
    sobol2(i, &a, &b);
    *u = to_unit(owen_scramble(a, smp_hash(seed + 1)));
    *v = to_unit(owen_scramble(b, smp_hash(seed + 2)));
}

float smp_1d(fr_sampler *s)
{
    float u, v;
    smp_2d(s, &u, &v);
    return u;
}
