/* json_microfacet.c -- the JSON scene's conductor, principled and rough glass
 * materials (see json_microfacet.h). */

#include "compile/json_microfacet.h"

#include <stdio.h>
#include <string.h>

#include "compile/jsonval.h"

const char *const json_microfacet_fields[SCN_MICROFACET_NFIELDS + 1] = {"roughness", "anisotropy", "masking",  "compensate",
                                             "fresnel",   "eta",        "k",        "base_color",
                                             "metallic",  "transmission", "coupling", NULL};

/* Members a type may have beyond the shared ones ("type", "emission",
 * "two_sided", "bump", "normal_map", "medium"). */
static const char *const shared[] = {"type", "emission", "two_sided", "bump", "normal_map", "medium", NULL};
static const char *const conductor_own[] = {"reflectance", "roughness", "anisotropy", "masking", "compensate",
                                            "fresnel", "eta", "k", NULL};
static const char *const principled_own[] = {"base_color", "metallic", "roughness", "anisotropy", "transmission",
                                             "ior", "masking", "compensate", "coupling", NULL};
static const char *const glass_micro[] = {"roughness", "anisotropy", "masking", "compensate", "fresnel", NULL};

static int listed(const char *const *names, const char *s)
{
    for (; *names; names++)
        if (!strcmp(*names, s))
            return 1;
    return 0;
}

/* Every member of o is shared or in `own`. */
static int only(const cJSON *o, const char *where, const char *type, const char *const *own, fr_error *err)
{
    for (const cJSON *c = o->child; c; c = c->next)
        if (!listed(shared, c->string) && !listed(own, c->string))
            return fr_fail(err, "%s.%s: not a member of a %s material", where, c->string, type);
    return 0;
}

static int boolean(const cJSON *o, const char *key, const char *where, int *out, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v)
        return 0;
    if (!cJSON_IsBool(v))
        return fr_fail(err, "%s.%s: expected true or false", where, key);
    *out = cJSON_IsTrue(v);
    return 0;
}

/* roughness (number or texture), anisotropy, masking, compensate. */
static int surface(json_appear *a, const cJSON *o, const char *where, float def_rough, fr_material *m, fr_error *err)
{
    static const char *const maskings[] = {"correlated", "separable", NULL};
    int masking = 0, comp = 0;
    if (json_scalar(a, o, "roughness", where, def_rough, 0.0f, 1.0f, &m->roughness, &m->tex_roughness, err) < 0 ||
        jv_number(o, "anisotropy", where, 0, 0.0f, &m->anisotropy, err) < 0 ||
        jv_choice(o, "masking", where, maskings, 0, &masking, err) < 0 || boolean(o, "compensate", where, &comp, err) < 0)
        return -1;
    if (!(m->anisotropy >= -1.0f && m->anisotropy <= 1.0f))
        return fr_fail(err, "%s.anisotropy: expected a number in [-1, 1]", where);
    m->mf_flags = (masking ? FR_MF_SEPARABLE : 0u) | (comp ? FR_MF_COMPENSATE : 0u);
    return 0;
}

static int conductor(json_appear *a, const cJSON *o, const char *where, fr_material *m, fr_error *err)
{
    static const char *const modes[] = {"schlick", "exact", "none", NULL};
    int has_eta = cJSON_GetObjectItemCaseSensitive(o, "eta") != NULL;
    int has_k = cJSON_GetObjectItemCaseSensitive(o, "k") != NULL;
    int mode;
    if (only(o, where, "conductor", conductor_own, err) < 0 || surface(a, o, where, 0.0f, m, err) < 0 ||
        jv_choice(o, "fresnel", where, modes, has_eta || has_k ? FR_FRESNEL_EXACT : FR_FRESNEL_SCHLICK, &mode, err) < 0)
        return -1;
    m->model = FR_MAT_CONDUCTOR;
    m->fresnel = (uint32_t)mode;
    if (mode == FR_FRESNEL_EXACT) {
        if (jv_vec3(o, "eta", where, 1, v3s(1.0f), &m->eta, err) < 0 || jv_vec3(o, "k", where, 1, v3s(0.0f), &m->k, err) < 0)
            return -1;
        if (!(v3_min(m->eta) > 0.0f))
            return fr_fail(err, "%s.eta: expected indices > 0", where);
        if (!(v3_min(m->k) >= 0.0f))
            return fr_fail(err, "%s.k: expected extinction coefficients >= 0", where);
    } else if (has_eta || has_k) {
        return fr_fail(err, "%s.%s: a complex index needs \"fresnel\": \"exact\"", where, has_eta ? "eta" : "k");
    }
    /* The reflectance is F0 (schlick), the colour (none) or a tint (exact). */
    return json_colour(a, o, "reflectance", where, mode != FR_FRESNEL_EXACT, v3s(1.0f), &m->specular, &m->tex_specular,
                      err);
}

static int principled(json_appear *a, const cJSON *o, const char *where, fr_material *m, fr_error *err)
{
    static const char *const couplings[] = {"albedo", "gltf", "cycles", NULL};
    int coupling;
    /* glTF's defaults: white, metallic 1, roughness 1. */
    if (only(o, where, "principled", principled_own, err) < 0 || surface(a, o, where, 1.0f, m, err) < 0 ||
        json_colour(a, o, "base_color", where, 0, v3s(1.0f), &m->diffuse, &m->tex_diffuse, err) < 0 ||
        json_scalar(a, o, "metallic", where, 1.0f, 0.0f, 1.0f, &m->metallic, &m->tex_metallic, err) < 0 ||
        json_scalar(a, o, "transmission", where, 0.0f, 0.0f, 1.0f, &m->transmission, &m->tex_transmission, err) < 0 ||
        jv_number(o, "ior", where, 0, 1.5f, &m->ior, err) < 0 ||
        jv_choice(o, "coupling", where, couplings, 0, &coupling, err) < 0)
        return -1;
    if (!(m->transmission >= 0.0f && m->transmission <= 1.0f))
        return fr_fail(err, "%s.transmission: expected a number in [0, 1]", where);
    m->model = FR_MAT_PRINCIPLED;
    if (coupling == 1)
        m->mf_flags |= FR_MF_GLTF_COUPLING;
    if (coupling == 2) {
        if (m->mf_flags & FR_MF_COMPENSATE)
            return fr_fail(err, "%s.compensate: \"coupling\": \"cycles\" has no energy compensation", where);
        m->mf_flags |= FR_MF_CYCLES_COUPLING;
    }
    return 0;
}

/* A glass is rough when its roughness is not 0 or is a texture; a smooth
 * one stays the delta glass and takes no microfacet option. */
static int glass(json_appear *a, const cJSON *o, const char *where, fr_material *m, fr_error *err)
{
    static const char *const fresnels[] = {"microfacet", "normal", NULL};
    int at;
    if (surface(a, o, where, 0.0f, m, err) < 0 || jv_choice(o, "fresnel", where, fresnels, 0, &at, err) < 0)
        return -1;
    if (m->roughness > 0.0f || m->tex_roughness != FR_NONE) {
        m->model = FR_MAT_DIELECTRIC;
        if (at)
            m->mf_flags |= FR_MF_MACRO_FRESNEL;
        return 0;
    }
    for (const char *const *k = glass_micro + 1; *k; k++)
        if (cJSON_GetObjectItemCaseSensitive(o, *k))
            return fr_fail(err, "%s.%s: only a rough glass (roughness > 0) has this option", where, *k);
    m->roughness = 0.0f;
    m->mf_flags = 0;
    return 0;
}

int json_microfacet(json_appear *a, const cJSON *o, const char *where, const char *type, fr_material *m,
                   fr_error *err)
{
    if (!strcmp(type, "conductor"))
        return conductor(a, o, where, m, err);
    if (!strcmp(type, "principled"))
        return principled(a, o, where, m, err);
    for (const cJSON *c = o->child; c; c = c->next)
        if (listed(json_microfacet_fields, c->string) && !(!strcmp(type, "glass") && listed(glass_micro, c->string)))
            return fr_fail(err, "%s.%s: not a member of a %s material", where, c->string, type);
    if (!strcmp(type, "glass"))
        return glass(a, o, where, m, err);
    return 0;
}
