/* passes.c -- render passes: their names and channels, and what one sample
 * of the path integrator brings to them (see passes.h). */

#include "passes.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bsdf.h"
#include "fmath.h"

static const pass_info passes[PASS_COUNT] = {
    [PASS_ALBEDO] = {"albedo", "Denoising Albedo", "RGB"},
    [PASS_NORMAL] = {"normal", "Denoising Normal", "XYZ"},
    [PASS_DEPTH] = {"depth", "Depth", "Z"},
    [PASS_POSITION] = {"position", "Position", "XYZ"},
    [PASS_EMISSION] = {"emission", "Emit", "RGB"},
    [PASS_DIFFUSE_DIRECT] = {"diffuse_direct", "DiffDir", "RGB"},
    [PASS_DIFFUSE_INDIRECT] = {"diffuse_indirect", "DiffInd", "RGB"},
    [PASS_GLOSSY_DIRECT] = {"glossy_direct", "GlossDir", "RGB"},
    [PASS_GLOSSY_INDIRECT] = {"glossy_indirect", "GlossInd", "RGB"},
    [PASS_TRANSMISSION_DIRECT] = {"transmission_direct", "TransDir", "RGB"},
    [PASS_TRANSMISSION_INDIRECT] = {"transmission_indirect", "TransInd", "RGB"},
    [PASS_MATERIAL_ID] = {"material_id", "IndexMA", "X"},
    [PASS_CRYPTO_MATERIAL] = {"crypto_material", "CryptoMaterial", "RGBARGBARGBA"},
    [PASS_VARIANCE] = {"variance", "Variance", "RGB"},
    [PASS_OBJECT_ID] = {"object_id", "IndexOB", "X"},
    [PASS_CRYPTO_OBJECT] = {"crypto_object", "CryptoObject", "RGBARGBARGBA"},
    [PASS_LIGHTGROUP] = {"light_groups", "Combined_", "RGBRGBRGBRGBRGBRGBRGBRGB"},
    [PASS_SHADOW] = {"shadow", "Shadow", "RGB"},
};

const pass_info *pass_get(int i) { return &passes[i]; }

uint32_t pass_channels(uint32_t mask)
{
    uint32_t n = 0;
    for (int i = 0; i < PASS_COUNT; i++)
        if (mask >> i & 1u)
            n += (uint32_t)strlen(passes[i].channels);
    return n;
}

/* The light passes: emission and the six of the first scattering. */
#define PASS_LIGHT (((1u << (PASS_TRANSMISSION_INDIRECT + 1)) - 1u) & ~((1u << PASS_EMISSION) - 1u))

int pass_parse(const char *list, uint32_t *mask, fr_error *err)
{
    uint32_t m = 0;
    const char *p = list;
    if (!*p)
        return fr_fail(err, "empty list of passes (expected names separated by commas, or all, none)");
    for (;;) {
        size_t k = strcspn(p, ",");
        int found = 0;
        for (int i = 0; i < PASS_COUNT; i++)
            if (strlen(passes[i].name) == k && !strncmp(p, passes[i].name, k)) {
                m |= 1u << i;
                found = 1;
            }
        if (k == 3 && !strncmp(p, "all", 3))
            m = PASS_ALL, found = 1;
        else if (k == 4 && !strncmp(p, "none", 4))
            found = 1;
        else if (k == 5 && !strncmp(p, "light", 5))
            m |= PASS_LIGHT, found = 1;
        else if (k == 7 && !strncmp(p, "denoise", 7))
            m |= 1u << PASS_ALBEDO | 1u << PASS_NORMAL, found = 1;
        if (!found) {
            char names[400];
            pass_format(PASS_ALL, names, sizeof names);
            return fr_fail(err, "unknown pass '%.*s' (expected %s, or all, light, denoise, none)", (int)(k < 64 ? k : 64),
                           p, names);
        }
        if (!p[k])
            break;
        p += k + 1;
    }
    *mask = m;
    return 0;
}

void pass_format(uint32_t mask, char *out, size_t cap)
{
    size_t n = 0;
    out[0] = 0;
    for (int i = 0; i < PASS_COUNT && n < cap; i++)
        if (mask >> i & 1u)
            n += (size_t)snprintf(out + n, cap - n, "%s%s", n ? "," : "", passes[i].name);
    if (!mask)
        snprintf(out, cap, "none");
}

void pass_start(pass_sample *p)
{
    memset(p, 0, sizeof *p);
    p->albedo_beta = v3s(1.0f);
    p->depth = PASS_DEPTH_NONE;
    p->kind = -1;
}

void pass_first_hit(pass_sample *p, vec3 at, uint32_t material, uint32_t object, vec3 from)
{
    p->depth = v3_len(v3_sub(at, from));
    p->position = at;
    p->material = material == FR_NONE ? 0 : material + 1;
    p->object = object;
}

uint32_t pass_object(const fr_scene *s, const fr_surface *sf)
{
    return sf->element < s->n_objects ? s->objects[sf->element] + 1 : 0;
}

void pass_light(pass_sample *p, uint32_t bounces, vec3 L)
{
    int k = bounces == 0 ? 0 : 1 + 2 * (p->kind < 0 ? 0 : p->kind) + (bounces > 1);
    p->light[k] = v3_add(p->light[k], L);
}

void pass_group(pass_sample *p, const fr_scene *s, uint32_t light, vec3 L)
{
    uint32_t g = light < s->n_light_groups ? s->light_groups[light] : 0;
    p->group[g] = v3_add(p->group[g], L);
}

/* A material's reflectance for the albedo pass (passes.h). */
static vec3 material_albedo(const fr_material *m)
{
    vec3 a;
    if (m->model == FR_MAT_CONDUCTOR)
        a = m->specular;
    else if (m->model == FR_MAT_DIELECTRIC)
        a = m->transmit;
    else if (m->model == FR_MAT_PRINCIPLED)
        a = m->diffuse;
    else
        a = v3_add(v3_add(m->diffuse, m->glossy), v3_add(m->specular, m->transmit));
    return v3_vmin(a, v3s(1.0f));
}

void pass_light_first(pass_sample *p, const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, vec3 L)
{
    if (v3_dot(wo, sf->ng) * v3_dot(wi, sf->ng) < 0.0f) {
        p->light[5] = v3_add(p->light[5], L);
        return;
    }
    if (m->model != FR_MAT_LOBES) {
        p->light[3] = v3_add(p->light[3], L);
        return;
    }
    /* The Lambert lobe's share of f toward the light, per channel. */
    float pdf;
    vec3 f = bsdf_eval(m, sf, wo, wi, &pdf), fd = v3_scale(m->diffuse, FM_INV_PI), d;
    d.x = f.x > 0.0f ? L.x * (fd.x / f.x) : 0.0f;
    d.y = f.y > 0.0f ? L.y * (fd.y / f.y) : 0.0f;
    d.z = f.z > 0.0f ? L.z * (fd.z / f.z) : 0.0f;
    d = v3_vmin(d, L);
    p->light[1] = v3_add(p->light[1], d);
    p->light[3] = v3_add(p->light[3], v3_sub(L, d));
}

void pass_first_kind(pass_sample *p, const fr_material *m, const fr_surface *sf, vec3 wo, vec3 wi, float ulobe)
{
    if (!sf)
        p->kind = 0;
    else if (v3_dot(wo, sf->ng) * v3_dot(wi, sf->ng) < 0.0f)
        p->kind = 2;
    else
        p->kind = m->model == FR_MAT_LOBES && ulobe < m->p_lobe[0] ? 0 : 1;
}

void pass_albedo_at(pass_sample *p, const fr_material *m, const fr_surface *sf, vec3 d)
{
    if (m->model == FR_MAT_LOBES && !bsdf_has_smooth(m) && !v3_is_zero(v3_add(m->specular, m->transmit)))
        return;
    p->albedo = v3_mul(p->albedo_beta, material_albedo(m));
    p->albedo = v3_vmin(p->albedo, v3s(1.0f));
    p->normal = v3_dot(sf->ns, d) <= 0.0f ? sf->ns : v3_neg(sf->ns);
    p->albedo_done = 1;
}

void pass_shadow(pass_sample *p, vec3 L, vec3 free)
{
    p->lit = v3_add(p->lit, L);
    p->unshadowed = v3_add(p->unshadowed, free);
}

void pass_albedo_through(pass_sample *p, vec3 w)
{
    p->albedo_beta = v3_mul(p->albedo_beta, w);
}

void pass_drop_light(pass_sample *p)
{
    for (int k = 0; k < 7; k++)
        p->light[k] = v3s(0.0f);
    for (int k = 0; k < PASS_LIGHT_GROUPS; k++)
        p->group[k] = v3s(0.0f);
}

/* Channels of pass i, with the pass's values in sample p (up to 3). */
static int values(const pass_sample *p, int i, float *v)
{
    vec3 c;
    switch (i) {
    case PASS_ALBEDO: c = p->albedo; break;
    case PASS_NORMAL: c = p->normal; break;
    case PASS_POSITION: c = p->position; break;
    case PASS_DEPTH: v[0] = p->depth; return 1;
    case PASS_MATERIAL_ID: v[0] = (float)p->material; return 1;
    case PASS_OBJECT_ID: v[0] = (float)p->object; return 1;
    default: c = p->light[i - PASS_EMISSION]; break;
    }
    v[0] = c.x, v[1] = c.y, v[2] = c.z;
    return 3;
}

/* Whether pass i keeps sample 0's value rather than the mean. */
static int first_only(int i)
{
    return i == PASS_DEPTH || i == PASS_POSITION || i == PASS_MATERIAL_ID || i == PASS_OBJECT_ID;
}

/* Whether pass i is a Cryptomatte ranking. */
static int is_crypto(int i) { return i == PASS_CRYPTO_MATERIAL || i == PASS_CRYPTO_OBJECT; }

/* Doubles pass_accumulate keeps for pass i. */
static int acc_width(int i)
{
    return is_crypto(i) ? 2 * PASS_CRYPTO_SLOTS : i == PASS_VARIANCE || i == PASS_SHADOW ? 6
                                                                           : (int)strlen(passes[i].channels);
}

/* The Cryptomatte slots (id + 1, samples): one more sample on material id
 * (1 + index, 0: nothing hit). */
static void crypto_count(double *slot, uint32_t id)
{
    for (int k = 0; k < PASS_CRYPTO_SLOTS; k++) {
        if (slot[2 * k + 1] > 0 && slot[2 * k] == (double)id + 1) {
            slot[2 * k + 1] += 1;
            return;
        }
        if (slot[2 * k + 1] == 0) {
            slot[2 * k] = (double)id + 1;
            slot[2 * k + 1] = 1;
            return;
        }
    }
}

/* The ranked (id, coverage) pairs of n samples from the slots. */
static void crypto_rank(const double *slot, uint32_t n, float *out)
{
    int used[PASS_CRYPTO_SLOTS] = {0};
    for (int r = 0; r < PASS_CRYPTO_RANKS; r++) {
        int best = -1;
        for (int k = 0; k < PASS_CRYPTO_SLOTS; k++) {
            if (used[k] || slot[2 * k + 1] == 0)
                continue;
            if (best < 0 || slot[2 * k + 1] > slot[2 * best + 1] ||
                (slot[2 * k + 1] == slot[2 * best + 1] && slot[2 * k] < slot[2 * best]))
                best = k;
        }
        out[2 * r] = best < 0 ? 0.0f : (float)(slot[2 * best] - 1);
        out[2 * r + 1] = best < 0 ? 0.0f : (float)(slot[2 * best + 1] / n);
        if (best >= 0)
            used[best] = 1;
    }
}

void pass_accumulate(double *acc, uint32_t mask, const pass_sample *p, uint32_t index)
{
    for (int i = 0; i < PASS_COUNT; i++) {
        if (!(mask >> i & 1u))
            continue;
        if (is_crypto(i) || i == PASS_VARIANCE) {
            if (is_crypto(i))
                crypto_count(acc, i == PASS_CRYPTO_MATERIAL ? p->material : p->object);
            else
                for (int c = 0; c < 3; c++) {
                    double v = v3_get(p->beauty, c);
                    acc[c] += v;
                    acc[3 + c] += v * v;
                }
            acc += acc_width(i);
            continue;
        }
        if (i == PASS_SHADOW) {
            for (int c = 0; c < 3; c++) {
                acc[c] += v3_get(p->lit, c);
                acc[3 + c] += v3_get(p->unshadowed, c);
            }
            acc += 6;
            continue;
        }
        if (i == PASS_LIGHTGROUP) {
            for (int k = 0; k < 3 * PASS_LIGHT_GROUPS; k++)
                acc[k] += v3_get(p->group[k / 3], k % 3);
            acc += 3 * PASS_LIGHT_GROUPS;
            continue;
        }
        float v[3];
        int n = values(p, i, v);
        for (int c = 0; c < n; c++) {
            if (!first_only(i))
                acc[c] += v[c];
            else if (index == 0)
                acc[c] = v[c];
        }
        acc += n;
    }
}

void pass_finish(const double *acc, uint32_t mask, uint32_t n, float *out)
{
    for (int i = 0; i < PASS_COUNT; i++) {
        if (!(mask >> i & 1u))
            continue;
        int k = (int)strlen(passes[i].channels);
        if (is_crypto(i))
            crypto_rank(acc, n, out);
        else if (i == PASS_VARIANCE)
            for (int c = 0; c < 3; c++) {
                double var = n > 1 ? (acc[3 + c] - acc[c] * acc[c] / n) / (n - 1) / n : 0.0;
                out[c] = var > 0.0 ? (float)var : 0.0f;
            }
        else if (i == PASS_SHADOW)
            for (int c = 0; c < 3; c++) {
                double r = acc[3 + c] > 0.0 && isfinite(acc[3 + c]) && isfinite(acc[c]) ? acc[c] / acc[3 + c] : 1.0;
                out[c] = (float)(r < 1.0 ? r : 1.0);
            }
        else
            for (int c = 0; c < k; c++)
                out[c] = first_only(i) ? (float)acc[c] : (float)(acc[c] / n);
        out += k;
        acc += acc_width(i);
    }
}
