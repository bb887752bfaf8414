/* texture.c -- texture lookups, and textures, bump and normal maps applied at
 * a hit (see texture.h). */

#include "texture.h"

#include "bsdf.h"
#include "fmath.h"
#include "simd4.h"

#include <string.h>

float tex_srgb_to_linear(float v)
{
    if (!(v > 0.0f))
        return 0.0f;
    if (v >= 1.0f)
        return 1.0f;
    return v <= 0.04045f ? v * (1.0f / 12.92f) : fm_powf((v + 0.055f) * (1.0f / 1.055f), 2.4f);
}

/* a + (b - a) t: exact when a == b, so a constant image filters to exactly
 * its constant and a flat height map has exactly zero slope. */
static float lerp(float a, float b, float t) { return a + (b - a) * t; }

/* Texel column or row for integer i under the wrap mode, n texels. */
static uint32_t wrap_index(long i, uint32_t n, uint32_t wrap)
{
    if (wrap == FR_WRAP_CLAMP)
        return i < 0 ? 0 : i >= (long)n ? n - 1 : (uint32_t)i;
    long m = i % (long)n;
    return (uint32_t)(m < 0 ? m + (long)n : m);
}

/* Map one texture coordinate into the range the wrap mode allows: its
 * fraction for repeat (so huge plane coordinates stay precise), [0, 1] for
 * clamp.  NaN (from coordinates that overflow) becomes 0, so pixel
 * indices are always in range. */
static float wrap_coord(float x, uint32_t wrap)
{
    if (wrap == FR_WRAP_CLAMP)
        return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f;
    float f = x - floorf(x);
    return f < 1.0f ? f : 0.0f;   /* x = -tiny rounds to 1.0 */
}

/* sRGB-encoded bytes decoded: srgb8[k] = tex_srgb_to_linear(k / 255.0f),
 * bit for bit (test_texture checks every entry). */
static const float srgb8[256] = {
#include "texture_srgb8.inc"
};

/* The bits of half h as a float: the exponent rebased from 15 to 127 (to
 * 255 for infinities and NaNs, whose payload moves with the mantissa);
 * subnormals (exponent 0) as m 2^-24, exactly.  Selects, no branches. */
static inline float half_to_float(uint16_t h)
{
    uint32_t em = h & 0x7fffu;
    uint32_t bits = (em << 13) + (112u << 23) + (em >= 0x7c00u ? 112u << 23 : 0u);
    float v, sub = (float)em * 0x1p-24f;
    memcpy(&v, &bits, sizeof v);
    v = em < 0x0400u ? sub : v;
    memcpy(&bits, &v, sizeof bits);
    bits |= (uint32_t)(h >> 15) << 31;
    memcpy(&v, &bits, sizeof v);
    return v;
}

float tex_half_to_float(uint16_t h) { return half_to_float(h); }

typedef uint32_t u4 __attribute__((vector_size(16)));

/* half_to_float of four halves (zero-extended in h) at once: the same
 * operations lane by lane, so the same bits. */
static inline f4 half_to_float4(u4 h)
{
    u4 em = h & 0x7fffu;
    u4 bits = (em << 13) + (112u << 23) + ((u4)(em >= 0x7c00u) & (112u << 23));
    f4 sub = __builtin_convertvector((i4)em, f4) * 0x1p-24f;   /* em < 2^15: signed is exact */
    u4 small = (u4)(em < 0x0400u);
    u4 r = (small & (u4)sub) | (~small & bits);
    return (f4)(r | (h >> 15) << 31);
}

/* The four three-channel half texels i[0..3] of a level starting at byte
 * lv, decoded twelve values as three vectors of four. */
static inline void quad_half3(const unsigned char *lv, const size_t i[4], float out[4][3])
{
    uint16_t h[12];
    for (int k = 0; k < 4; k++)
        memcpy(h + 3 * k, lv + i[k] * 6, 6);
    float v[12];
    for (int q = 0; q < 3; q++) {
        u4 x = {h[4 * q], h[4 * q + 1], h[4 * q + 2], h[4 * q + 3]};
        f4 f = half_to_float4(x);
        memcpy(v + 4 * q, &f, sizeof f);
    }
    memcpy(out, v, sizeof v);
}

static inline uint32_t format_bytes(uint32_t format)
{
    switch (format) {
    case FR_TEXEL_U8_SRGB: case FR_TEXEL_U8: return 1;
    case FR_TEXEL_U16: case FR_TEXEL_U16_SRGB: case FR_TEXEL_F16: return 2;
    default: return 4;
    }
}

uint32_t tex_format_bytes(uint32_t format) { return format_bytes(format); }

void tex_level_size(const fr_texture *t, uint32_t level, uint32_t *w, uint32_t *h)
{
    uint32_t a = level < 32 ? t->width >> level : 0, b = level < 32 ? t->height >> level : 0;
    *w = a ? a : 1;
    *h = b ? b : 1;
}

/* Value c of the texel starting at byte p. */
static inline float decode(uint32_t format, const unsigned char *p, uint32_t c)
{
    uint16_t h;
    float f;
    switch (format) {
    case FR_TEXEL_U8_SRGB:
        return srgb8[p[c]];
    case FR_TEXEL_U8:
        return (float)p[c] / 255.0f;
    case FR_TEXEL_U16:
        memcpy(&h, p + 2 * c, 2);
        return (float)h / 65535.0f;
    case FR_TEXEL_U16_SRGB:
        memcpy(&h, p + 2 * c, 2);
        return tex_srgb_to_linear((float)h / 65535.0f);
    case FR_TEXEL_F16:
        memcpy(&h, p + 2 * c, 2);
        return half_to_float(h);
    default:
        memcpy(&f, p + 4 * c, 4);
        return f;
    }
}

/* Texel i (row-major) of a level starting at byte lv: channels into out. */
static inline __attribute__((always_inline)) void fetch(const unsigned char *lv, uint32_t format, uint32_t n,
                                                        size_t i, float out[3])
{
    const unsigned char *p = lv + i * n * format_bytes(format);
    switch (format) {
    case FR_TEXEL_U8_SRGB:
        for (uint32_t c = 0; c < n; c++)
            out[c] = srgb8[p[c]];
        break;
    case FR_TEXEL_U8:
        for (uint32_t c = 0; c < n; c++)
            out[c] = (float)p[c] / 255.0f;
        break;
    default:
        for (uint32_t c = 0; c < n; c++)
            out[c] = decode(format, p, c);
    }
}

void tex_texel(const uint32_t *texels, const fr_texture *t, uint32_t level, uint32_t x, uint32_t y, float out[3])
{
    uint32_t w, h;
    tex_level_size(t, level, &w, &h);
    fetch((const unsigned char *)(texels + t->first[level]), t->format, t->channels, (size_t)y * w + x, out);
}

/* The four texels i[0..3] of a level starting at byte lv, fetched with the
 * format (and, for three channels, the count) known to the compiler, so
 * that decode's choices are made once, not per value. */
static inline __attribute__((always_inline)) void fetch4(const unsigned char *lv, uint32_t format, uint32_t n,
                                                         const size_t i[4], float out[4][3])
{
    for (int k = 0; k < 4; k++)
        fetch(lv, format, n, i[k], out[k]);
}

#define FETCH4_CASE(f) \
    case f: \
        if (n == 3) \
            fetch4(lv, f, 3, i, out); \
        else \
            fetch4(lv, f, n, i, out); \
        break

static void quad(const unsigned char *lv, uint32_t format, uint32_t n, const size_t i[4], float out[4][3])
{
    switch (format) {
    FETCH4_CASE(FR_TEXEL_U8_SRGB);
    FETCH4_CASE(FR_TEXEL_U8);
    FETCH4_CASE(FR_TEXEL_U16);
    FETCH4_CASE(FR_TEXEL_U16_SRGB);
    case FR_TEXEL_F16:
        if (n == 3)
            quad_half3(lv, i, out);
        else
            fetch4(lv, FR_TEXEL_F16, n, i, out);
        break;
    default:
        fetch4(lv, FR_TEXEL_F32, n, i, out);
    }
}

void tex_texels4(const uint32_t *texels, const fr_texture *t, uint32_t level, const size_t i[4], float out[4][3])
{
    quad((const unsigned char *)(texels + t->first[level]), t->format, t->channels, i, out);
}

/* Image lookup of level `level` at texture-space (u, v), channels into
 * out[0..channels). */
static void level_eval(const fr_scene *s, const fr_texture *t, uint32_t level, float u, float v, float out[3])
{
    uint32_t n = t->channels, w, h, f = t->format;
    tex_level_size(t, level, &w, &h);
    const unsigned char *lv = (const unsigned char *)(s->texels + t->first[level]);
    /* Pixel space: x right, y down from the top row; texel centres at +0.5. */
    float x = wrap_coord(u, t->wrap) * (float)w;
    float y = (1.0f - wrap_coord(v, t->wrap)) * (float)h;
    if (t->filter == FR_FILTER_NEAREST) {
        fetch(lv, f, n, (size_t)wrap_index((long)floorf(y), h, FR_WRAP_CLAMP) * w +
                            wrap_index((long)floorf(x), w, FR_WRAP_CLAMP), out);
        return;
    }
    x -= 0.5f;
    y -= 0.5f;
    float x0f = floorf(x), y0f = floorf(y), fx = x - x0f, fy = y - y0f;
    long x0 = (long)x0f, y0 = (long)y0f;
    size_t xa = wrap_index(x0, w, t->wrap), xb = wrap_index(x0 + 1, w, t->wrap);
    size_t ya = (size_t)wrap_index(y0, h, t->wrap) * w, yb = (size_t)wrap_index(y0 + 1, h, t->wrap) * w;
    size_t at[4] = {ya + xa, ya + xb, yb + xa, yb + xb};
    float p[4][3];
    quad(lv, f, n, at, p);
    for (uint32_t c = 0; c < n; c++)
        out[c] = lerp(lerp(p[0][c], p[1][c], fx), lerp(p[2][c], p[3][c], fx), fy);
}

/* Image lookup at texture-space (u, v) and level of detail lod (0: level
 * 0; between levels, trilinear), channels into out[0..channels). */
static void image_eval(const fr_scene *s, const fr_texture *t, float u, float v, float lod, float out[3])
{
    if (!(lod > 0.0f) || t->levels < 2 || t->filter == FR_FILTER_NEAREST) {
        level_eval(s, t, 0, u, v, out);
        return;
    }
    float top = (float)(t->levels - 1);
    if (lod >= top) {
        level_eval(s, t, t->levels - 1, u, v, out);
        return;
    }
    float lf = floorf(lod), frac = lod - lf;
    uint32_t l = (uint32_t)lf;
    float a[3], b[3];
    level_eval(s, t, l, u, v, a);
    if (frac == 0.0f) {
        for (uint32_t c = 0; c < t->channels; c++)
            out[c] = a[c];
        return;
    }
    level_eval(s, t, l + 1, u, v, b);
    for (uint32_t c = 0; c < t->channels; c++)
        out[c] = lerp(a[c], b[c], frac);
}

/* 1 if floor(x) is odd.  f - 2 floor(f/2) is exact for every float; above
 * 2^24 every float is even. */
static int odd(float x)
{
    float f = floorf(x);
    return f - 2.0f * floorf(0.5f * f) != 0.0f;
}

static vec3 eval_at(const fr_scene *s, const fr_texture *t, float u, float v, float lod, int *grey)
{
    if (t->kind == FR_TEX_CHECKER) {
        *grey = 0;
        return odd(u) != odd(v) ? t->color1 : t->color0;
    }
    float c[3] = {0.0f, 0.0f, 0.0f};
    image_eval(s, t, u, v, lod, c);
    *grey = t->channels == 1;
    return t->channels == 1 ? v3s(c[0]) : v3(c[0], c[1], c[2]);
}

static void to_texture_space(const fr_texture *t, vec2 uv, float *u, float *v)
{
    *u = uv.u * t->scale.u + t->offset.u;
    *v = uv.v * t->scale.v + t->offset.v;
}

/* As tex_eval at level of detail lod (0: level 0; fractions blend two
 * levels; past the last level, the last). */
static vec3 tex_eval_lod(const fr_scene *s, uint32_t ti, vec2 uv, float lod)
{
    const fr_texture *t = &s->textures[ti];
    float u, v;
    int grey;
    to_texture_space(t, uv, &u, &v);
    return eval_at(s, t, u, v, lod, &grey);
}

vec3 tex_eval(const fr_scene *s, uint32_t ti, vec2 uv)
{
    return tex_eval_lod(s, ti, uv, 0.0f);
}

vec3 tex_eval_level(const fr_scene *s, uint32_t ti, vec2 uv, uint32_t level)
{
    const fr_texture *t = &s->textures[ti];
    if (t->kind != FR_TEX_IMAGE || (level == 0 && t->filter == FR_FILTER_BILINEAR))
        return tex_eval(s, ti, uv);
    fr_texture b = *t;
    b.filter = FR_FILTER_BILINEAR;
    float u, v, c[3] = {0.0f, 0.0f, 0.0f};
    to_texture_space(t, uv, &u, &v);
    level_eval(s, &b, level < t->levels ? level : t->levels - 1, u, v, c);
    return t->channels == 1 ? v3s(c[0]) : v3(c[0], c[1], c[2]);
}

float tex_lod(const fr_scene *s, uint32_t ti, const fr_surface *sf)
{
    const fr_texture *t = &s->textures[ti];
    if (!(sf->footprint > 0.0f) || t->kind != FR_TEX_IMAGE || t->levels < 2)
        return 0.0f;
    /* Texels per unit of texture space, over scene area per unit of uv:
     * the squared number of level-0 texels one scene unit spans. */
    float area = v3_len(v3_cross(sf->dpdu, sf->dpdv));
    float density = (float)t->width * (float)t->height * fabsf(t->scale.u * t->scale.v);
    float f2 = sf->footprint * sf->footprint * density / area;
    if (!(f2 > 1.0f) || !(f2 < 1e30f))
        return 0.0f;                  /* under a texel (or a degenerate uv map): level 0 */
    return 0.5f * fm_logf(f2) * 1.44269504088896341f;
}

int tex_material_textured(const fr_material *m)
{
    return (m->tex_diffuse & m->tex_glossy & m->tex_specular & m->tex_transmit & m->tex_emission & m->tex_bump &
            m->tex_normal & m->tex_roughness & m->tex_metallic & m->tex_transmission) != FR_NONE;
}

static vec3 clamp01(vec3 c)
{
    return v3_vmin(v3_vmax(c, v3s(0.0f)), v3s(1.0f));
}

vec3 tex_emission(const fr_scene *s, const fr_material *m, vec2 uv)
{
    if (m->tex_emission == FR_NONE)
        return m->emission;
    return v3_mul(m->emission, v3_vmax(tex_eval(s, m->tex_emission, uv), v3s(0.0f)));
}

/* Keep a tilted shading normal n in the hemisphere of the geometric normal
 * ng (at least ~0.06 degrees above the surface), so a shading normal can
 * never face away from the side the path is on. */
static vec3 keep_above(vec3 n, vec3 ng)
{
    const float min_cos = 1e-3f;
    float c = v3_dot(n, ng);
    if (c < min_cos)
        n = v3_madd(n, ng, min_cos - c);
    return v3_norm(n);
}

/* Bump mapping (Blinn 1978) in surface-gradient form (Mikkelsen 2020):
 * the height h = strength * H(u, v) displaces the surface along ns; the
 * tilted normal is ns minus the surface gradient of h, which the dual basis
 * of (dpdu, dpdv) in the tangent plane gives from dh/du and dh/dv.  Slopes
 * come from central differences one texel apart (texture space). */
static void bump(const fr_scene *s, const fr_material *m, fr_surface *sf)
{
    const fr_texture *t = &s->textures[m->tex_bump];
    float u, v;
    int grey;
    to_texture_space(t, sf->uv, &u, &v);
    float du = t->kind == FR_TEX_IMAGE ? 1.0f / (float)t->width : 1.0f / 1024.0f;
    float dv = t->kind == FR_TEX_IMAGE ? 1.0f / (float)t->height : 1.0f / 1024.0f;
    float hu = eval_at(s, t, u + du, v, 0.0f, &grey).x - eval_at(s, t, u - du, v, 0.0f, &grey).x;
    float hv = eval_at(s, t, u, v + dv, 0.0f, &grey).x - eval_at(s, t, u, v - dv, 0.0f, &grey).x;
    if (hu == 0.0f && hv == 0.0f)
        return;                       /* flat here: the surface as it is */
    /* dh/du on the surface = dH/du' * du'/du = slope * scale. */
    float dhdu = m->bump_strength * hu / (2.0f * du) * t->scale.u;
    float dhdv = m->bump_strength * hv / (2.0f * dv) * t->scale.v;
    vec3 n = sf->ns;
    vec3 r1 = v3_cross(sf->dpdv, n), r2 = v3_cross(n, sf->dpdu);
    float det = v3_dot(sf->dpdu, r1);
    if (!(fabsf(det) > 1e-20f))
        return;                       /* degenerate parametrization (a pole) */
    vec3 grad = v3_scale(v3_add(v3_scale(r1, dhdu), v3_scale(r2, dhdv)), 1.0f / det);
    vec3 np = v3_sub(n, grad);
    if (v3_len2(np) > 0.0f && isfinite(np.x + np.y + np.z))
        sf->ns = keep_above(v3_norm(np), sf->ng);
}

/* Tangent-space normal map: RGB in [0, 1] encodes a unit vector in the
 * frame (tangent along dpdu, bitangent, ns), 0.5 meaning 0.  The bitangent
 * follows dpdv's side so mirrored UVs read the map the right way. */
static void normal_map(const fr_scene *s, const fr_material *m, fr_surface *sf)
{
    vec3 c = tex_eval(s, m->tex_normal, sf->uv);
    vec3 l = v3((2.0f * c.x - 1.0f) * m->normal_strength, (2.0f * c.y - 1.0f) * m->normal_strength, 2.0f * c.z - 1.0f);
    vec3 n = sf->ns, t, b;
    vec3 tu = v3_sub(sf->dpdu, v3_scale(n, v3_dot(n, sf->dpdu)));
    if (v3_len2(tu) > 0.0f && isfinite(tu.x + tu.y + tu.z)) {
        t = v3_norm(tu);
        b = v3_cross(n, t);
        if (v3_dot(v3_cross(sf->dpdu, sf->dpdv), n) < 0.0f)
            b = v3_neg(b);
    } else {
        v3_basis(n, &t, &b);
    }
    vec3 np = v3_from_local(l, t, b, n);
    if (v3_len2(np) > 0.0f)
        sf->ns = keep_above(v3_norm(np), sf->ng);
}

const fr_material *tex_material(const fr_scene *s, const fr_material *m, fr_surface *sf, fr_material *tmp)
{
    if (!tex_material_textured(m))
        return m;
    *tmp = *m;
    int lobes = 0;
#define LOOKUP(tex) tex_eval_lod(s, tex, sf->uv, tex_lod(s, tex, sf))
    if (m->tex_diffuse != FR_NONE)
        tmp->diffuse = v3_mul(m->diffuse, clamp01(LOOKUP(m->tex_diffuse))), lobes = 1;
    if (m->tex_glossy != FR_NONE)
        tmp->glossy = v3_mul(m->glossy, clamp01(LOOKUP(m->tex_glossy))), lobes = 1;
    if (m->tex_specular != FR_NONE)
        tmp->specular = v3_mul(m->specular, clamp01(LOOKUP(m->tex_specular))), lobes = 1;
    if (m->tex_transmit != FR_NONE)
        tmp->transmit = v3_mul(m->transmit, clamp01(LOOKUP(m->tex_transmit))), lobes = 1;
    if (m->tex_emission != FR_NONE)
        tmp->emission = tex_emission(s, m, sf->uv);  /* level 0, as light sampling sees it */
    /* glTF's metallicRoughness texture: roughness in G, metallic in B (a
     * grey texture has the same value in every channel). */
    if (m->tex_roughness != FR_NONE)
        tmp->roughness = m->roughness * clamp01(LOOKUP(m->tex_roughness)).y;
    if (m->tex_metallic != FR_NONE)
        tmp->metallic = m->metallic * clamp01(LOOKUP(m->tex_metallic)).z;
    /* glTF's transmissionTexture: the share in R. */
    if (m->tex_transmission != FR_NONE)
        tmp->transmission = m->transmission * clamp01(LOOKUP(m->tex_transmission)).x;
#undef LOOKUP
    if (lobes)
        bsdf_lobe_probs(tmp);
    if (m->tex_bump != FR_NONE)
        bump(s, m, sf);
    if (m->tex_normal != FR_NONE)
        normal_map(s, m, sf);
    return tmp;
}
