/* envmap.c -- the environment light: radiance from a direction, its sampling
 * and pdf (see envmap.h). */

#include "envmap.h"

#include "fmath.h"
#include "texture.h"

/* 2 pi^2: the area of the unit square of (u, v) maps to the sphere with
 * density 2 pi^2 sin(theta). */
#define TWO_PI2 19.7392088021787172f

/* dir turned by the world's rotation about +y, as the lookup sees it. */
static vec3 turn(const fr_world *w, vec3 d)
{
    return v3(w->rot_cos * d.x + w->rot_sin * d.z, d.y, w->rot_cos * d.z - w->rot_sin * d.x);
}

vec2 env_uv(const fr_scene *s, vec3 dir)
{
    vec3 d = turn(&s->world, dir);
    float u = 0.5f + fm_atan2f(d.z, d.x) * FM_INV_2PI;
    float v = 1.0f - fm_acosf(d.y) * FM_INV_PI;
    /* Clamped, NaN (from a NaN direction) to 0, so texel indices stay in range. */
    vec2 r = {u >= 0.0f ? (u <= 1.0f ? u : 1.0f) : 0.0f, v >= 0.0f ? (v <= 1.0f ? v : 1.0f) : 0.0f};
    return r;
}

/* Column i wrapped into [0, w) (i within one width of it: the lookup's
 * columns are -1 to w), row j clamped into [0, h). */
static int64_t wrap_column(int64_t i, int64_t w)
{
    i = i < 0 ? i + w : i;
    return i >= w ? i - w : i;
}

static int64_t clamp_row(int64_t j, int64_t h) { return j < 0 ? 0 : j >= h ? h - 1 : j; }

static vec3 rgb(const fr_texture *t, const float p[3])
{
    return t->channels == 3 ? v3(p[0], p[1], p[2]) : v3s(p[0]);
}

/* The map's value at (u, v) in [0, 1]^2, v = 1 on the top row. */
static vec3 lookup(const fr_scene *s, vec2 uv)
{
    const fr_texture *t = &s->textures[s->world.env_texture];
    int64_t w = t->width, h = t->height;
    float x = uv.u * (float)t->width, y = (1.0f - uv.v) * (float)t->height;
    vec3 c;
    float p[4][3];
    if (t->filter == FR_FILTER_NEAREST) {
        int64_t i = wrap_column((int64_t)floorf(x), w), j = clamp_row((int64_t)floorf(y), h);
        tex_texel(s->texels, t, 0, (uint32_t)i, (uint32_t)j, p[0]);
        c = rgb(t, p[0]);
    } else {
        x -= 0.5f;
        y -= 0.5f;
        float fx = floorf(x), fy = floorf(y), ax = x - fx, ay = y - fy;
        int64_t i = (int64_t)fx, j = (int64_t)fy;
        int64_t i0 = wrap_column(i, w), i1 = wrap_column(i + 1, w);
        int64_t j0 = clamp_row(j, h) * w, j1 = clamp_row(j + 1, h) * w;
        size_t at[4] = {(size_t)(j0 + i0), (size_t)(j0 + i1), (size_t)(j1 + i0), (size_t)(j1 + i1)};
        tex_texels4(s->texels, t, 0, at, p);
        vec3 top = v3_add(v3_scale(rgb(t, p[0]), 1.0f - ax), v3_scale(rgb(t, p[1]), ax));
        vec3 bot = v3_add(v3_scale(rgb(t, p[2]), 1.0f - ax), v3_scale(rgb(t, p[3]), ax));
        c = v3_add(v3_scale(top, 1.0f - ay), v3_scale(bot, ay));
    }
    return v3_vmax(c, v3s(0.0f));
}

/* The sampling tables of a w x h map. */
typedef struct { const float *pdf, *marg, *cond; uint32_t w, h; } tables;

static tables get_tables(const fr_scene *s)
{
    const fr_texture *t = &s->textures[s->world.env_texture];
    tables tb;
    tb.w = t->width;
    tb.h = t->height;
    tb.pdf = s->distrib + s->world.dist_first;
    tb.marg = tb.pdf + (size_t)tb.w * tb.h;
    tb.cond = tb.marg + tb.h + 1;
    return tb;
}

/* The density of a map's sampling at dir, whose coordinates are uv. */
static float density(const fr_scene *s, vec3 dir, vec2 uv)
{
    tables tb = get_tables(s);
    vec3 d = turn(&s->world, dir);
    float sin_t = sqrtf(d.x * d.x + d.z * d.z);
    if (!(sin_t > 0.0f))
        return 0.0f;
    uint32_t i = (uint32_t)(uv.u * (float)tb.w), j = (uint32_t)((1.0f - uv.v) * (float)tb.h);
    i = i < tb.w ? i : tb.w - 1;
    j = j < tb.h ? j : tb.h - 1;
    return tb.pdf[(size_t)j * tb.w + i] / (TWO_PI2 * sin_t);
}

vec3 env_radiance(const fr_scene *s, vec3 dir)
{
    const fr_world *w = &s->world;
    if (w->env != FR_ENV_MAP)
        return w->env_color;
    return v3_mul(w->env_color, lookup(s, env_uv(s, dir)));
}

float env_pdf(const fr_scene *s, vec3 dir)
{
    if (s->world.env != FR_ENV_MAP)
        return 1.0f / (4.0f * FM_PI);
    return density(s, dir, env_uv(s, dir));
}

vec3 env_eval(const fr_scene *s, vec3 dir, float *pdf)
{
    const fr_world *w = &s->world;
    if (w->env != FR_ENV_MAP) {
        *pdf = 1.0f / (4.0f * FM_PI);
        return w->env_color;
    }
    vec2 uv = env_uv(s, dir);
    *pdf = density(s, dir, uv);
    return v3_mul(w->env_color, lookup(s, uv));
}

/* The cell of cumulative table c (n + 1 entries, 0 to 1) that u falls in:
 * the first k with u < c[k + 1]; *frac is u's place inside it. */
static uint32_t find(const float *c, uint32_t n, float u, float *frac)
{
    /* Halving by selects, not branches (a branch on u goes either way at
     * random): b ends at the last entry of c[1..n] that is <= u, or at
     * c[1], and the cell is the one after it, n - 1 at most.  The table is
     * non-decreasing (the loader checks it) and u is a number in [0, 1),
     * so this is the cell a plain binary search finds. */
    const float *b = c + 1;
    for (uint32_t len = n; len > 1;) {
        uint32_t half = len / 2;
        b = b[half] <= u ? b + half : b;
        len -= half;
    }
    uint32_t lo = (uint32_t)(b - (c + 1)) + (b[0] <= u);
    lo = lo < n ? lo : n - 1;
    float width = c[lo + 1] - c[lo];
    float f = width > 0.0f ? (u - c[lo]) / width : 0.5f;
    *frac = f < 0.0f ? 0.0f : f < 1.0f ? f : 0.99999994f;
    return lo;
}

vec3 env_sample(const fr_scene *s, float u1, float u2, float *pdf, vec3 *radiance)
{
    const fr_world *w = &s->world;
    vec3 d;
    float density;
    if (w->env != FR_ENV_MAP) {
        /* Uniform over the sphere. */
        float z = 1.0f - 2.0f * u1, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), sn, cs;
        fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
        *pdf = 1.0f / (4.0f * FM_PI);
        *radiance = w->env_color;
        return v3(r * cs, z, r * sn);
    }
    tables tb = get_tables(s);
    float fj, fi;
    uint32_t j = find(tb.marg, tb.h, u1, &fj);
    uint32_t i = find(tb.cond + (size_t)j * (tb.w + 1), tb.w, u2, &fi);
    float u = ((float)i + fi) / (float)tb.w, t = ((float)j + fj) / (float)tb.h;
    float st, ct, sp, cp;
    fm_sincosf(FM_PI * t, &st, &ct);
    fm_sincosf(2.0f * FM_PI * (u - 0.5f), &sp, &cp);
    vec3 l = v3(st * cp, ct, st * sp);   /* in the map's frame; turn back */
    d = v3(w->rot_cos * l.x - w->rot_sin * l.z, l.y, w->rot_sin * l.x + w->rot_cos * l.z);
    density = st > 0.0f ? tb.pdf[(size_t)j * tb.w + i] / (TWO_PI2 * st) : 0.0f;
    *pdf = density;
    *radiance = env_radiance(s, d);
    return d;
}
