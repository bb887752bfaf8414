/* texture.c -- texture lookups, and textures, bump and normal maps applied at
 * a hit (see texture.h). */

#include "texture.h"

#include "bsdf.h"
#include "fmath.h"

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

static const float *texel(const fr_scene *s, const fr_texture *t, uint32_t x, uint32_t y)
{
    return s->texels + t->first + ((size_t)y * t->width + x) * t->channels;
}

/* Image lookup at texture-space (u, v), channels into out[0..channels). */
static void image_eval(const fr_scene *s, const fr_texture *t, float u, float v, float out[3])
{
    uint32_t n = t->channels;
    /* Pixel space: x right, y down from the top row; texel centres at +0.5. */
    float x = wrap_coord(u, t->wrap) * (float)t->width;
    float y = (1.0f - wrap_coord(v, t->wrap)) * (float)t->height;
    if (t->filter == FR_FILTER_NEAREST) {
        const float *p = texel(s, t, wrap_index((long)floorf(x), t->width, FR_WRAP_CLAMP),
                               wrap_index((long)floorf(y), t->height, FR_WRAP_CLAMP));
        for (uint32_t c = 0; c < n; c++)
            out[c] = p[c];
        return;
    }
    x -= 0.5f;
    y -= 0.5f;
    float x0f = floorf(x), y0f = floorf(y), fx = x - x0f, fy = y - y0f;
    long x0 = (long)x0f, y0 = (long)y0f;
    uint32_t xa = wrap_index(x0, t->width, t->wrap), xb = wrap_index(x0 + 1, t->width, t->wrap);
    uint32_t ya = wrap_index(y0, t->height, t->wrap), yb = wrap_index(y0 + 1, t->height, t->wrap);
    const float *p00 = texel(s, t, xa, ya), *p10 = texel(s, t, xb, ya);
    const float *p01 = texel(s, t, xa, yb), *p11 = texel(s, t, xb, yb);
    for (uint32_t c = 0; c < n; c++)
        out[c] = lerp(lerp(p00[c], p10[c], fx), lerp(p01[c], p11[c], fx), fy);
}

/* 1 if floor(x) is odd.  f - 2 floor(f/2) is exact for every float; above
 * 2^24 every float is even. */
static int odd(float x)
{
    float f = floorf(x);
    return f - 2.0f * floorf(0.5f * f) != 0.0f;
}

static vec3 eval_at(const fr_scene *s, const fr_texture *t, float u, float v, int *grey)
{
    if (t->kind == FR_TEX_CHECKER) {
        *grey = 0;
        return odd(u) != odd(v) ? t->color1 : t->color0;
    }
    float c[3];
    image_eval(s, t, u, v, c);
    *grey = t->channels == 1;
    return t->channels == 1 ? v3s(c[0]) : v3(c[0], c[1], c[2]);
}

static void to_texture_space(const fr_texture *t, vec2 uv, float *u, float *v)
{
    *u = uv.u * t->scale.u + t->offset.u;
    *v = uv.v * t->scale.v + t->offset.v;
}

vec3 tex_eval(const fr_scene *s, uint32_t ti, vec2 uv)
{
    const fr_texture *t = &s->textures[ti];
    float u, v;
    int grey;
    to_texture_space(t, uv, &u, &v);
    return eval_at(s, t, u, v, &grey);
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
    float hu = eval_at(s, t, u + du, v, &grey).x - eval_at(s, t, u - du, v, &grey).x;
    float hv = eval_at(s, t, u, v + dv, &grey).x - eval_at(s, t, u, v - dv, &grey).x;
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
    if (m->tex_diffuse != FR_NONE)
        tmp->diffuse = v3_mul(m->diffuse, clamp01(tex_eval(s, m->tex_diffuse, sf->uv))), lobes = 1;
    if (m->tex_glossy != FR_NONE)
        tmp->glossy = v3_mul(m->glossy, clamp01(tex_eval(s, m->tex_glossy, sf->uv))), lobes = 1;
    if (m->tex_specular != FR_NONE)
        tmp->specular = v3_mul(m->specular, clamp01(tex_eval(s, m->tex_specular, sf->uv))), lobes = 1;
    if (m->tex_transmit != FR_NONE)
        tmp->transmit = v3_mul(m->transmit, clamp01(tex_eval(s, m->tex_transmit, sf->uv))), lobes = 1;
    if (m->tex_emission != FR_NONE)
        tmp->emission = tex_emission(s, m, sf->uv);
    /* glTF's metallicRoughness texture: roughness in G, metallic in B (a
     * grey texture has the same value in every channel). */
    if (m->tex_roughness != FR_NONE)
        tmp->roughness = m->roughness * clamp01(tex_eval(s, m->tex_roughness, sf->uv)).y;
    if (m->tex_metallic != FR_NONE)
        tmp->metallic = m->metallic * clamp01(tex_eval(s, m->tex_metallic, sf->uv)).z;
    /* glTF's transmissionTexture: the share in R. */
    if (m->tex_transmission != FR_NONE)
        tmp->transmission = m->transmission * clamp01(tex_eval(s, m->tex_transmission, sf->uv)).x;
    if (lobes)
        bsdf_lobe_probs(tmp);
    if (m->tex_bump != FR_NONE)
        bump(s, m, sf);
    if (m->tex_normal != FR_NONE)
        normal_map(s, m, sf);
    return tmp;
}
