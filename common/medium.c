/* medium.c -- homogeneous media: transmittance, phase function, distance and
 * equiangular sampling (see medium.h). */

#include "medium.h"

#include "fmath.h"

/* A path crosses at most this many media boundaries between two scattering
 * events; beyond (never in a sane scene) it is treated as blocked. */
enum { MAX_CROSSINGS = 64 };

static float channel(vec3 v, int c) { return c == 0 ? v.x : c == 1 ? v.y : v.z; }

static float tr1(float sigma_t, float d)
{
    if (sigma_t == 0.0f)
        return 1.0f;
    return d == INFINITY ? 0.0f : fm_expf(-sigma_t * d);
}

vec3 med_transmittance(const fr_medium *m, float d)
{
    vec3 st = v3_add(m->sigma_a, m->sigma_s);
    return v3(tr1(st.x, d), tr1(st.y, d), tr1(st.z, d));
}

float med_phase(float g, float cos_theta)
{
    float denom = 1.0f + g * g - 2.0f * g * cos_theta;
    return (1.0f / (4.0f * FM_PI)) * (1.0f - g * g) / (denom * sqrtf(denom));
}

vec3 med_sample_phase(float g, vec3 d, float u1, float u2)
{
    float cos_t;
    if (fabsf(g) < 1e-3f) {
        cos_t = 1.0f - 2.0f * u1;
    } else {
        /* Inverse of the HG cumulative distribution in cos(theta). */
        float sq = (1.0f - g * g) / (1.0f - g + 2.0f * g * u1);
        cos_t = (1.0f + g * g - sq * sq) / (2.0f * g);
        cos_t = cos_t < -1.0f ? -1.0f : cos_t > 1.0f ? 1.0f : cos_t;
    }
    float sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t)), sn, cs;
    fm_sincosf(2.0f * FM_PI * u2, &sn, &cs);
    vec3 t, b;
    v3_basis(d, &t, &b);
    return v3_norm(v3_from_local(v3(sin_t * cs, sin_t * sn, cos_t), t, b, d));
}

/* Channel selection probabilities: proportional to the throughput. */
static vec3 channel_probs(vec3 beta)
{
    vec3 b = v3_vmax(beta, v3s(0.0f));
    float sum = b.x + b.y + b.z;
    if (!(sum > 0.0f) || !isfinite(sum))
        return v3s(1.0f / 3.0f);
    return v3_scale(b, 1.0f / sum);
}

float med_distance_pdf(const fr_medium *m, vec3 beta, float t)
{
    vec3 st = v3_add(m->sigma_a, m->sigma_s), w = channel_probs(beta);
    float p = 0.0f;
    for (int c = 0; c < 3; c++)
        p += channel(w, c) * channel(st, c) * tr1(channel(st, c), t);
    return p;
}

int med_sample_distance(const fr_medium *m, float tmax, vec3 beta, float uch, float u, float *t, vec3 *weight)
{
    vec3 st = v3_add(m->sigma_a, m->sigma_s);
    if (v3_is_zero(m->sigma_s)) {
        *t = tmax;
        *weight = med_transmittance(m, tmax);
        return 0;
    }
    vec3 w = channel_probs(beta);
    int c = uch < w.x ? 0 : uch < w.x + w.y ? 1 : 2;
    float sc = channel(st, c);
    float d = sc > 0.0f ? -fm_logf(1.0f - u) / sc : INFINITY;
    if (d < tmax) {
        *t = d;
        float pdf = med_distance_pdf(m, beta, d);
        *weight = v3_scale(v3_mul(med_transmittance(m, d), m->sigma_s), 1.0f / pdf);
        return 1;
    }
    /* Reaching the end: the mixture of the channels' Tr(tmax). */
    vec3 tr = med_transmittance(m, tmax);
    float p = v3_dot(w, tr);
    *t = tmax;
    *weight = p > 0.0f ? v3_scale(tr, 1.0f / p) : v3s(0.0f);
    return 0;
}

/* The ray's closest approach to c: its parameter delta and distance h. */
static int closest_approach(vec3 o, vec3 d, vec3 c, float *delta, float *h)
{
    vec3 oc = v3_sub(c, o);
    *delta = v3_dot(oc, d);
    float h2 = v3_len2(oc) - *delta * *delta;
    *h = sqrtf(fmaxf(0.0f, h2));
    /* Too close to the line: the density degenerates to a spike. */
    return *h > 1e-6f * (fabsf(*delta) + sqrtf(v3_len2(oc))) && *h > 0.0f;
}

/* Angles, seen from c, of the segment's ends: theta = atan((t - delta) / h). */
static void end_angles(float delta, float h, float tmax, float *a, float *b)
{
    *a = fm_atan2f(-delta, h);
    *b = tmax == INFINITY ? 0.5f * FM_PI : fm_atan2f(tmax - delta, h);
}

int med_equiangular(vec3 o, vec3 d, float tmax, vec3 c, float u, float *t, float *pdf)
{
    float delta, h, a, b;
    if (!closest_approach(o, d, c, &delta, &h))
        return 0;
    end_angles(delta, h, tmax, &a, &b);
    if (!(b > a))
        return 0;
    /* Uniform in the angle subtended at c, so t - delta = h tan(theta). */
    float theta = a + u * (b - a);
    if (!(theta < 0.5f * FM_PI))
        return 0;
    float x = h * fm_tanf(theta);
    *t = delta + x;
    if (!(*t >= 0.0f && *t < tmax))
        return 0;
    *pdf = h / ((b - a) * (h * h + x * x));
    return *pdf > 0.0f && isfinite(*pdf);
}

float med_equiangular_pdf(vec3 o, vec3 d, float tmax, vec3 c, float t)
{
    float delta, h, a, b;
    if (!closest_approach(o, d, c, &delta, &h) || !(t >= 0.0f && t < tmax))
        return 0.0f;
    end_angles(delta, h, tmax, &a, &b);
    if (!(b > a))
        return 0.0f;
    float x = t - delta;
    return h / ((b - a) * (h * h + x * x));
}

uint32_t med_after(const fr_scene *s, uint32_t current, const fr_material *m, vec3 ng, vec3 dir)
{
    if (!m->medium)
        return current;
    return v3_dot(dir, ng) < 0.0f ? m->medium : s->volume.fog;
}

vec3 med_shadow(const fr_scene *s, uint32_t medium, const fr_ray *r, float tmax, uint32_t skip)
{
    fr_ray ray = *r;
    vec3 tr = v3s(1.0f);
    for (int k = 0; k < MAX_CROSSINGS; k++) {
        fr_hit h;
        if (!trace_closest(s, &ray, tmax, &h) || (h.prim != FR_NONE && h.prim == skip)) {
            if (medium)
                tr = v3_mul(tr, med_transmittance(&s->media[medium - 1], tmax));
            return tr;
        }
        fr_surface sf;
        trace_surface(s, &ray, &h, &sf);
        const fr_material *m = &s->materials[sf.material];
        if (!m->interface)
            return v3s(0.0f);
        if (medium)
            tr = v3_mul(tr, med_transmittance(&s->media[medium - 1], h.t));
        medium = med_after(s, medium, m, sf.ng, ray.d);
        vec3 o = geo_offset(sf.p, sf.perr, sf.ng, ray.d);
        tmax -= v3_dot(v3_sub(o, ray.o), ray.d);
        ray.o = o;
        if (!(tmax > 0.0f))
            return tr;
    }
    return v3s(0.0f);
}
