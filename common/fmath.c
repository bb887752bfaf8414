/* fmath.c -- sin, cos, exp, log, pow, atan2, acos ... from + - * / and sqrt.
 *
 * Every function widens its float argument to double, evaluates there and
 * rounds once at the end.  The double work (range reduction, a minimax
 * polynomial with an error of 2^-40 or less relative to the true value)
 * leaves about 2^-16 of a float ulp of error, so the final rounding is what
 * dominates: results are the correctly rounded float except for inputs whose
 * true value lies that close to a rounding boundary, and never 2 ulp off.
 *
 * Determinism rests on three things: only IEEE 754 operations that are
 * exactly rounded (+ - * / sqrt, conversions), no contraction into fused
 * multiply-adds (-ffp-contract=off), and integer work done on unsigned types
 * so no step depends on implementation-defined behaviour.
 *
 * The polynomial coefficients were fitted with the Remez exchange algorithm
 * in 60-digit arithmetic and rounded to double; the comment above each set
 * gives the interval and the fit's maximum relative error. */
#include "fmath.h"

#include <math.h>   /* sqrt, fabs, signbit, INFINITY: exact, no libm call */
#include <stdint.h>
#include <string.h>

static inline uint32_t f2u(float x) { uint32_t u; memcpy(&u, &x, sizeof u); return u; }
static inline float u2f(uint32_t u) { float x; memcpy(&x, &u, sizeof x); return x; }
static inline uint64_t d2u(double x) { uint64_t u; memcpy(&u, &x, sizeof u); return u; }
static inline double u2d(uint64_t u) { double x; memcpy(&x, &u, sizeof x); return x; }

/* Adding then subtracting 1.5 * 2^52 rounds a double of magnitude below 2^51
 * to the nearest integer (ties to even) with two exact-rounding additions. */
#define ROUND_MAGIC 0x1.8p52

#define PI_D   0x1.921fb54442d18p+1
#define PIO2_D 0x1.921fb54442d18p+0
#define PIO4_D 0x1.921fb54442d18p-1

/* ---- sin, cos, tan ------------------------------------------------------ */

/* pi/2 in three parts for Cody-Waite reduction: the first two have 33
 * significant bits, so k * part is exact for |k| < 2^20. */
#define INV_PIO2 0x1.45f306dc9c883p-1
#define PIO2_1   0x1.921fb544p+0
#define PIO2_2   0x1.0b4611a6p-34
#define PIO2_3   0x1.3198a2e037073p-69

/* Bits of 2/pi, 32 to a word, after one word of zeros standing for the
 * integer part; enough for the largest float exponent. */
static const uint32_t TWO_OVER_PI[9] = {
    0x00000000, 0xa2f9836e, 0x4e441529, 0xfc2757d1, 0xf534ddc0,
    0xdb629599, 0x3c439041, 0xfe5163ab, 0xdebbc561,
};

/* 32 bits of TWO_OVER_PI starting s bits into word i (0 <= s < 32). */
static inline uint32_t two_over_pi_bits(int i, int s)
{
    uint64_t w = ((uint64_t)TWO_OVER_PI[i] << 32) | TWO_OVER_PI[i + 1];
    return (uint32_t)(w >> (32 - s));
}

/* Payne-Hanek reduction for |x| >= 2^20 (and inf/NaN): x = m * 2^e with m a
 * 24-bit integer, so x * 2/pi mod 4 needs only a 96-bit window of 2/pi
 * starting two bits above weight 2^-e; bits before it contribute multiples
 * of 4.  The product m * window, kept mod 2^96, is that value as a fixed
 * point number with 94 fraction bits. */
static int reduce_large(float x, double *r)
{
    uint32_t ix = f2u(x);
    if ((ix & 0x7f800000u) == 0x7f800000u) {
        *r = (double)(x - x);                    /* inf or NaN: NaN */
        return 0;
    }
    uint32_t m = (ix & 0x7fffffu) | 0x800000u;
    int g = (int)((ix >> 23) & 0xffu) - 150 + 30; /* e + 30: first window bit */
    int w = g >> 5, s = g & 31;
    uint64_t p2 = (uint64_t)m * two_over_pi_bits(w + 2, s);
    uint64_t p1 = (uint64_t)m * two_over_pi_bits(w + 1, s) + (p2 >> 32);
    uint32_t p0 = (uint32_t)((uint64_t)m * two_over_pi_bits(w, s) + (p1 >> 32));
    uint64_t v = ((uint64_t)p0 << 32) | (uint32_t)p1;   /* (x*2/pi mod 4) * 2^62 */
    uint64_t q = (v + ((uint64_t)1 << 61)) >> 62;      /* nearest quadrant */
    uint64_t f = v - (q << 62);                         /* two's complement fraction */
    double fd = (f >> 63) ? -(double)(~f + 1) : (double)f;
    fd = (fd + (double)(uint32_t)p2 * 0x1p-32) * 0x1p-62;
    int k = (int)(q & 3);
    if (ix >> 31) {
        fd = -fd;
        k = (4 - k) & 3;
    }
    *r = fd * PIO2_D;
    return k;
}

/* x = k*pi/2 + r, |r| <= pi/4 (to rounding); returns k mod 4. */
static inline int reduce_pio2(float x, double *r)
{
    if (fabsf(x) < 0x1p20f) {
        double xd = x;
        double k = (xd * INV_PIO2 + ROUND_MAGIC) - ROUND_MAGIC;
        /* xd - k*PIO2_1 is exact; the later steps round only at the size of
         * the (possibly small) result. */
        *r = ((xd - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
        return (int)((uint32_t)(int32_t)k & 3u);
    }
    return reduce_large(x, r);
}

/* sin(r) = r * (1 + z*P(z)), z = r^2, |r| <= pi/4: relative error 2^-47.5.
 * The product form keeps the sign of a zero r. */
static inline double sin_kernel(double r)
{
    double z = r * r, z2 = z * z;
    double p = (-0x1.5555555552239p-3 + z * 0x1.1111110c87333p-7)
             + z2 * ((-0x1.a019f93968bb1p-13 + z * 0x1.71d76d1671617p-19)
             + z2 * -0x1.a961a17d2d4cdp-26);
    return r * (1.0 + z * p);
}

/* cos(r) = 1 + z*Q(z), z = r^2, |r| <= pi/4: relative error 2^-43.6. */
static inline double cos_kernel(double r)
{
    double z = r * r, z2 = z * z;
    double p = (-0x1.ffffffffe98afp-2 + z * 0x1.55555545c514dp-5)
             + z2 * ((-0x1.6c16b348bc348p-10 + z * 0x1.a00eb9af45605p-16)
             + z2 * -0x1.23c97e63f6f01p-22);
    return 1.0 + z * p;
}

/* sin_kernel(r) in lane 0 and cos_kernel(r) in lane 1, their operations
 * two at a time in the same order (lane-wise arithmetic rounds as the
 * scalar does): for the functions that need both. */
typedef double d2 __attribute__((vector_size(16)));
static inline d2 sincos_kernels(double r)
{
    double z = r * r, z2 = z * z;
    d2 zv = {z, z}, z2v = {z2, z2};
    d2 p = ((d2){-0x1.5555555552239p-3, -0x1.ffffffffe98afp-2} + zv * (d2){0x1.1111110c87333p-7, 0x1.55555545c514dp-5})
         + z2v * (((d2){-0x1.a019f93968bb1p-13, -0x1.6c16b348bc348p-10}
                   + zv * (d2){0x1.71d76d1671617p-19, 0x1.a00eb9af45605p-16})
                  + z2v * (d2){-0x1.a961a17d2d4cdp-26, -0x1.23c97e63f6f01p-22});
    d2 q = (d2){1.0, 1.0} + zv * p;
    return (d2){r * q[0], q[1]};
}

/* c ? a : b without a branch: quadrants and octants of random directions
 * are unpredictable, and a mispredicted branch costs more than both sides. */
static inline double pick(int c, double a, double b)
{
    uint64_t m = (uint64_t)0 - (uint64_t)(c != 0);
    return u2d((d2u(a) & m) | (d2u(b) & ~m));
}

/* sin(k*pi/2 + r) from s = sin(r), c = cos(r): the sign flip is a bit flip,
 * which negates zeros too. */
static inline float quadrant(double s, double c, int k)
{
    return (float)u2d(d2u(pick(k & 1, c, s)) ^ ((uint64_t)(k & 2) << 62));
}

float fm_sinf(float x)
{
    double r;
    int k = reduce_pio2(x, &r);
    return quadrant(sin_kernel(r), cos_kernel(r), k);
}

float fm_cosf(float x)
{
    double r;
    int k = reduce_pio2(x, &r);
    return quadrant(sin_kernel(r), cos_kernel(r), k + 1);
}

/* Inlined where it is called (always_inline): a sampled direction's sine
 * and cosine come back in registers, not through the two pointers. */
__attribute__((always_inline)) inline void fm_sincosf(float x, float *sp, float *cp)
{
    double r;
    int k = reduce_pio2(x, &r);
    d2 sc = sincos_kernels(r);
    *sp = quadrant(sc[0], sc[1], k);
    *cp = quadrant(sc[0], sc[1], k + 1);
}

float fm_tanf(float x)
{
    double r;
    int k = reduce_pio2(x, &r);
    double s = sin_kernel(r), c = cos_kernel(r);
    return (float)(pick(k & 1, -c, s) / pick(k & 1, s, c));
}

/* ---- exp, log, pow ------------------------------------------------------ */

/* exp(t) = 2^(k/32) * exp(r), r = t - k*ln2/32, |r| <= ln2/64.  ln2/32 is
 * split so that k * LN2_32_HI is exact for |k| < 2^13. */
#define INV_LN2_32 0x1.71547652b82fep+5
#define LN2_32_HI  0x1.62e42fefa2p-6
#define LN2_32_LO  0x1.9ef35793c7673p-46
#define LN2        0x1.62e42fefa39efp-1

/* 2^(j/32), j = 0..31, correctly rounded. */
static const double EXP2_32[32] = {
    0x1.0000000000000p+0, 0x1.059b0d3158574p+0, 0x1.0b5586cf9890fp+0, 0x1.11301d0125b51p+0,
    0x1.172b83c7d517bp+0, 0x1.1d4873168b9aap+0, 0x1.2387a6e756238p+0, 0x1.29e9df51fdee1p+0,
    0x1.306fe0a31b715p+0, 0x1.371a7373aa9cbp+0, 0x1.3dea64c123422p+0, 0x1.44e086061892dp+0,
    0x1.4bfdad5362a27p+0, 0x1.5342b569d4f82p+0, 0x1.5ab07dd485429p+0, 0x1.6247eb03a5585p+0,
    0x1.6a09e667f3bcdp+0, 0x1.71f75e8ec5f74p+0, 0x1.7a11473eb0187p+0, 0x1.82589994cce13p+0,
    0x1.8ace5422aa0dbp+0, 0x1.93737b0cdc5e5p+0, 0x1.9c49182a3f090p+0, 0x1.a5503b23e255dp+0,
    0x1.ae89f995ad3adp+0, 0x1.b7f76f2fb5e47p+0, 0x1.c199bdd85529cp+0, 0x1.cb720dcef9069p+0,
    0x1.d5818dcfba487p+0, 0x1.dfc97337b9b5fp+0, 0x1.ea4afa2a490dap+0, 0x1.f50765b6e4540p+0,
};

/* exp(t) for -160 <= t <= 100 (callers clamp), relative error about 2^-43:
 * the minimax polynomial on |r| <= ln2/64 is good to 2^-43.6. */
static inline double exp_core(double t)
{
    double k = (t * INV_LN2_32 + ROUND_MAGIC) - ROUND_MAGIC;
    double r = (t - k * LN2_32_HI) - k * LN2_32_LO;
    double r2 = r * r;
    double p = (0x1.ffffffffffffap-1 + r * 0x1.ffffffffb135dp-1)
             + r2 * ((0x1.000000005bec5p-1 + r * 0x1.5555f953ab88ap-3)
             + r2 * 0x1.5554e800fa83fp-5);
    uint32_t ku = (uint32_t)((int32_t)k + 32768);        /* k + 2^15 >= 0 */
    uint64_t e = (uint64_t)((ku >> 5) - 1024 + 1023);     /* biased exponent of 2^(k div 32) */
    double scale = u2d(d2u(EXP2_32[ku & 31]) - ((uint64_t)1023 << 52) + (e << 52));
    return scale * p;
}

/* log(x) for a positive normal float given by its bits, plus eoff to add to
 * its exponent.  x = 2^e * m with m in [sqrt(1/2), sqrt(2)); log m =
 * 2 atanh(f), f = (m-1)/(m+1), |f| <= 0.1716, as f * (2 + s*P(s)), s = f^2:
 * relative error 2^-44.9, so pow can scale it by up to ~150. */
static inline double log_core(uint32_t ix, int eoff)
{
    /* adding 1.0 - sqrt(1/2) carries into the exponent exactly when
     * m >= sqrt(2) */
    int e = (int)((ix + (0x3f800000u - 0x3f3504f3u)) >> 23) - 127;
    uint32_t iz = ix + (127u << 23) - ((uint32_t)(e + 127) << 23);
    double m = (double)u2f(iz);
    double f = (m - 1.0) / (m + 1.0);
    double s = f * f, s2 = s * s;
    double p = (0x1.555555561d7d5p-1 + s * 0x1.999996ab52f83p-2)
             + s2 * ((0x1.2494111937610p-2 + s * 0x1.c62b594e353c9p-3)
             + s2 * 0x1.9111be6a02274p-3);
    double lm = f * (2.0 + s * p);
    return (double)(e + eoff) * LN2 + lm;
}

/* log_core for any positive finite float (subnormals are scaled up first). */
static inline double log_pos(float x)
{
    uint32_t ix = f2u(x);
    if (ix < 0x00800000u)
        return log_core(f2u(x * 0x1p23f), -23);
    return log_core(ix, 0);
}

float fm_expf(float x)
{
    if (x != x)
        return x + x;
    if (x > 89.0f)              /* exp(88.73) already exceeds FLT_MAX */
        return INFINITY;
    if (x < -104.0f)            /* below half the smallest subnormal */
        return 0.0f;
    return (float)exp_core((double)x);
}

float fm_logf(float x)
{
    uint32_t ix = f2u(x);
    if (ix - 0x00800000u >= 0x7f800000u - 0x00800000u) {
        /* zero, subnormal, negative, inf or NaN */
        if ((ix << 1) == 0)
            return -INFINITY;
        if ((ix << 1) > 0xff000000u)
            return x + x;                        /* NaN */
        if (ix >> 31)
            return (x - x) / (x - x);            /* negative: NaN */
        if (ix == 0x7f800000u)
            return x;                            /* +inf */
    }
    return (float)log_pos(x);
}

/* 0: y is not an integer, 1: odd integer, 2: even integer (all floats of
 * magnitude 2^24 and above, and the infinities). */
static int int_kind(uint32_t iy)
{
    int be = (int)((iy >> 23) & 0xffu);
    if (be >= 151)
        return 2;
    if (be < 127)
        return 0;                                /* 0 < |y| < 1 (y = 0 done) */
    uint32_t m = (iy & 0x7fffffu) | 0x800000u;
    int frac = 150 - be;                         /* fraction bits in m */
    if (m & ((1u << frac) - 1u))
        return 0;
    return ((m >> frac) & 1u) ? 1 : 2;
}

float fm_powf(float x, float y)
{
    uint32_t ix = f2u(x), iy = f2u(y);
    if ((iy << 1) == 0 || ix == 0x3f800000u)
        return 1.0f;                             /* pow(x, 0) = pow(1, y) = 1 */
    if ((ix << 1) > 0xff000000u || (iy << 1) > 0xff000000u)
        return x + y;                            /* NaN */
    int neg = 0;
    if (ix >> 31) {
        int kind = int_kind(iy);
        if (kind == 0 && (ix << 1) != 0 && (ix << 1) != 0xff000000u)
            return (x - x) / (x - x);            /* negative ** non-integer */
        neg = kind == 1;
        x = -x;
        ix &= 0x7fffffffu;
    }
    float mag;
    if (ix == 0x3f800000u)
        mag = 1.0f;                              /* (-1) ** (integer or inf) */
    else if (ix == 0)
        mag = (iy >> 31) ? INFINITY : 0.0f;
    else if (ix == 0x7f800000u)
        mag = (iy >> 31) ? 0.0f : INFINITY;
    else {
        double t = (double)y * log_pos(x);
        /* beyond these the float result is 0 or inf anyway; this also
         * maps y = +-inf to the right limit */
        t = t < -160.0 ? -160.0 : t > 100.0 ? 100.0 : t;
        mag = (float)exp_core(t);
    }
    return neg ? -mag : mag;
}

/* ---- atan2, asin, acos -------------------------------------------------- */

/* atan2 in double for non-NaN arguments, with C's signed-zero and infinity
 * cases: the angle of (x, y) in [-pi, pi].  With a = min(|x|,|y|), b = max,
 * atan(a/b) is in [0, pi/4]; above tan(pi/8) it is taken as pi/4 +
 * atan((a-b)/(a+b)) so the polynomial argument u stays within tan(pi/8):
 * atan(u) = u * (1 + z*P(z)), z = u^2, relative error 2^-40.2. */
static double atan2_core(double y, double x)
{
    double ax = fabs(x), ay = fabs(y);
    int swap = ay > ax;
    double a = pick(swap, ax, ay), b = pick(swap, ay, ax);
    double ang;
    if (b == 0.0 || a == INFINITY) {
        ang = b == 0.0 ? 0.0 : PIO4_D;           /* both zero, both infinite */
    } else {
        int big = a > b * 0x1.a827999fcef32p-2;
        double u = pick(big, a - b, a) / pick(big, a + b, b);
        double z = u * u, z2 = z * z, z4 = z2 * z2;
        double p = ((-0x1.5555554edf7ddp-2 + z * 0x1.999991fc4b529p-3)
                 + z2 * (-0x1.2490c30c4924ep-3 + z * 0x1.c6d1ec96fc507p-4))
                 + z4 * ((-0x1.7082c0ec0d6fap-4 + z * 0x1.1e5c769d40c56p-4)
                 + z2 * -0x1.36adf351d73c8p-5);
        ang = pick(big, PIO4_D, 0.0) + u * (1.0 + z * p);
    }
    ang = pick(swap, PIO2_D - ang, ang);
    ang = pick(signbit(x), PI_D - ang, ang);
    return u2d(d2u(ang) | (d2u(y) & ((uint64_t)1 << 63)));   /* ang >= 0 */
}

float fm_atan2f(float y, float x)
{
    if (x != x || y != y)
        return x + y;
    return (float)atan2_core(y, x);
}

/* asin(w) for |w| <= 1/2: w * (1 + z*P(z)), z = w^2, relative error
 * 2^-43.9.  Beyond 1/2, asin(w) = pi/2 - 2 asin(sqrt((1-w)/2)) brings the
 * argument back, with (1-w)/2 exact for a float w. */
static inline double asin_kernel(double w)
{
    double z = w * w, z2 = z * z, z4 = z2 * z2;
    double p = ((0x1.555555565a9bdp-3 + z * 0x1.333331f267ad2p-4)
             + z2 * (0x1.6db762b5088a4p-5 + z * 0x1.f1ab4339193bbp-6))
             + z4 * (((0x1.7027ec1aff965p-6 + z * 0x1.0e11622a1ad57p-6)
             + z2 * (0x1.30da3dcc249cbp-6 + z * -0x1.6ff281390acbcp-9))
             + z4 * 0x1.056f908d69f34p-5);
    return w * (1.0 + z * p);
}

float fm_asinf(float x)
{
    if (x != x)
        return x + x;
    double ax = fabs((double)x);
    ax = ax > 1.0 ? 1.0 : ax;
    int big = ax > 0.5;
    double a = asin_kernel(pick(big, sqrt((1.0 - ax) * 0.5), ax));
    double r = pick(big, PIO2_D - 2.0 * a, a);
    return (float)u2d(d2u(r) | (d2u((double)x) & ((uint64_t)1 << 63)));   /* r >= 0 */
}

/* acos(x) = pi/2 - asin(x) for |x| <= 1/2, else 2 asin(sqrt((1-|x|)/2)),
 * taken from pi for negative x. */
float fm_acosf(float x)
{
    if (x != x)
        return x + x;
    double d = x > 1.0f ? 1.0 : x < -1.0f ? -1.0 : (double)x;
    int big = fabs(d) > 0.5;
    double a = asin_kernel(pick(big, sqrt((1.0 - fabs(d)) * 0.5), d));
    double far = pick(signbit(d), PI_D - 2.0 * a, 2.0 * a);
    return (float)pick(big, far, PIO2_D - a);
}
