/* gltf_anim.c -- glTF animations evaluated at one time (gltf_anim.h). */
#include "compile/gltf_anim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmath.h"

enum { INTERP_LINEAR, INTERP_STEP, INTERP_CUBIC };

/* One sampler, checked: its key times and values.  A value is one
 * element of `comps` components, or (morph weights) `group` consecutive
 * scalar elements. */
typedef struct {
    gdoc_acc in, out;
    int interp;
    uint32_t keys;
    uint32_t comps, group;
} sampler;

double ganim_frame_time(double frame, double fps)
{
    return (double)(float)(frame / fps);
}

double ganim_hooks_time(const scene_hooks *h, double frame)
{
    return ganim_frame_time(frame, h->fps > 0.0 ? h->fps : GANIM_FPS);
}

int ganim_present(const gltf_doc *d)
{
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(d->root, "animations");
    return cJSON_IsArray(an) && cJSON_GetArraySize(an) > 0;
}

void ganim_free(ganim_pose *p)
{
    for (uint32_t i = 0; p->node && i < p->n; i++)
        free(p->node[i].w);
    free(p->node);
    memset(p, 0, sizeof *p);
}

/* Sampler `si` of animation `ai` (object `so`), for a property of `comps`
 * components (0: morph weights, a group of scalars per key): its
 * accessors and interpolation, every time and value checked. */
static int sampler_read(gltf_doc *d, uint32_t ai, uint32_t si, const cJSON *so, uint32_t comps, sampler *s,
                        fr_error *err)
{
    char ptr[96];
    snprintf(ptr, sizeof ptr, "/animations/%u/samplers/%u", ai, si);
    if (!cJSON_IsObject(so))
        return gdoc_fail(d, err, ptr, "expected an object");
    uint32_t iin, iout;
    if (gdoc_index(d, so, ptr, "input", 1, d->accessors.n, "accessors", &iin, err) < 0 ||
        gdoc_index(d, so, ptr, "output", 1, d->accessors.n, "accessors", &iout, err) < 0)
        return -1;
    const cJSON *ip = cJSON_GetObjectItemCaseSensitive(so, "interpolation");
    s->interp = INTERP_LINEAR;
    if (ip) {
        if (!cJSON_IsString(ip))
            return gdoc_fail(d, err, ptr, "interpolation: expected LINEAR, STEP or CUBICSPLINE");
        if (!strcmp(ip->valuestring, "STEP"))
            s->interp = INTERP_STEP;
        else if (!strcmp(ip->valuestring, "CUBICSPLINE"))
            s->interp = INTERP_CUBIC;
        else if (strcmp(ip->valuestring, "LINEAR") != 0)
            return gdoc_fail(d, err, ptr, "interpolation: '%s' is not LINEAR, STEP or CUBICSPLINE", ip->valuestring);
    }
    static const uint32_t floats[] = {GDOC_F32, 0};
    static const uint32_t int_types[] = {GDOC_F32, GDOC_I8, GDOC_U8, GDOC_I16, GDOC_U16, 0};
    char pin[112], pout[112];
    snprintf(pin, sizeof pin, "%s/input", ptr);
    snprintf(pout, sizeof pout, "%s/output", ptr);
    int weights = comps == 0;
    if (gdoc_accessor(d, iin, pin, 1, floats, &s->in, err) < 0 ||
        gdoc_accessor(d, iout, pout, weights ? 1 : comps, comps == 4 || weights ? int_types : floats, &s->out,
                      err) < 0)
        return -1;
    if (s->out.ctype != GDOC_F32 && !s->out.normalized)
        return gdoc_fail(d, err, pout, "accessor %u: integer %s must be normalized", iout,
                         weights ? "weights" : "rotations");
    s->keys = s->in.count;
    uint32_t per = s->interp == INTERP_CUBIC ? 3 : 1;
    s->comps = weights ? 1 : comps;
    s->group = 1;
    if (weights) {
        /* As many weights per key as the mesh has targets (checked by the
         * scene's reader): the elements divide evenly among the keys. */
        uint64_t n = s->out.count / ((uint64_t)per * s->keys);
        if (n == 0 || n * per * s->keys != s->out.count || n > GANIM_MAX_WEIGHTS)
            return gdoc_fail(d, err, pout, "accessor %u has %u elements: not %u key times of 1 to %d weights%s",
                             iout, s->out.count, s->keys, GANIM_MAX_WEIGHTS,
                             per == 3 ? " (in-tangents, values, out-tangents per key)" : "");
        s->group = (uint32_t)n;
    }
    if (!weights && (uint64_t)s->out.count != (uint64_t)per * s->keys)
        return gdoc_fail(d, err, pout, "accessor %u has %u elements; %u key times need %llu%s", iout, s->out.count,
                         s->keys, (unsigned long long)per * s->keys,
                         per == 3 ? " (in-tangent, value, out-tangent per key)" : "");
    double prev = 0.0;
    for (uint32_t k = 0; k < s->keys; k++) {
        double t = gdoc_get(&s->in, k, 0);
        if (!isfinite(t))
            return gdoc_fail(d, err, pin, "accessor %u: time %u is not finite", iin, k);
        if (k > 0 && !(t > prev))
            return gdoc_fail(d, err, pin, "accessor %u: time %u (%g) is not after time %u (%g): times must "
                             "increase", iin, k, t, k - 1, prev);
        prev = t;
    }
    for (uint32_t k = 0; k < s->out.count; k++)
        for (uint32_t c = 0; c < s->comps; c++)
            if (!isfinite(gdoc_get(&s->out, k, c)) || fabs(gdoc_get(&s->out, k, c)) > 1e30)
                return gdoc_fail(d, err, pout, "accessor %u: element %u is not a finite number", iout, k);
    return 0;
}

/* Value e of the output: its comps components, or its group of weights. */
static void value(const sampler *s, uint32_t e, double *v)
{
    if (s->group > 1 || s->comps == 1) {
        for (uint32_t i = 0; i < s->group; i++)
            v[i] = gdoc_get(&s->out, e * s->group + i, 0);
        return;
    }
    for (uint32_t c = 0; c < s->comps; c++)
        v[c] = gdoc_get(&s->out, e, c);
}

static void normalise(double *q)
{
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (l > 0.0 && isfinite(l))
        for (int c = 0; c < 4; c++)
            q[c] /= l;
}

/* sin and cos of x in [0, pi] in double, by their series (+ - * / only:
 * the reader is linked into the worker, which calls no libm
 * transcendental, and a pose must be the same bits on every host); the
 * terms left out are below 1e-15 there. */
static double series_sin(double x)
{
    double x2 = x * x, term = x, sum = x;
    for (int n = 1; n <= 14; n++) {
        term *= -x2 / ((2.0 * n) * (2.0 * n + 1.0));
        sum += term;
    }
    return sum;
}

static double series_cos(double x)
{
    double x2 = x * x, term = 1.0, sum = 1.0;
    for (int n = 1; n <= 14; n++) {
        term *= -x2 / ((2.0 * n - 1.0) * (2.0 * n));
        sum += term;
    }
    return sum;
}

/* acos(d) for d in [0, 0.9999999]: fmath's single-precision angle, then
 * Newton's steps on cos(theta) = d in double. */
static double angle_of(double d)
{
    double th = (double)fm_acosf((float)d);
    for (int i = 0; i < 3; i++)
        th += (series_cos(th) - d) / series_sin(th);
    return th;
}

/* Spherical linear interpolation from a to b by u, along the shorter arc. */
static void slerp(const double *a, const double *b0, double u, double *out)
{
    double b[4], qa[4];
    memcpy(qa, a, sizeof qa);
    memcpy(b, b0, sizeof b);
    normalise(qa);
    normalise(b);
    double dot = qa[0] * b[0] + qa[1] * b[1] + qa[2] * b[2] + qa[3] * b[3];
    if (dot < 0.0) {
        dot = -dot;
        for (int c = 0; c < 4; c++)
            b[c] = -b[c];
    }
    double wa = 1.0 - u, wb = u;
    if (dot < 0.9999999) {
        double th = angle_of(dot), sn = series_sin(th);
        wa = series_sin((1.0 - u) * th) / sn;
        wb = series_sin(u * th) / sn;
    }
    for (int c = 0; c < 4; c++)
        out[c] = wa * qa[c] + wb * b[c];
    normalise(out);
}

/* The sampler's value at time t into v (comps components): a key's value
 * as stored (the scene's reader normalises rotations, as it does a node's
 * own), an interpolated rotation normalised. */
static void sample(const sampler *s, double t, int rotation, double *v)
{
    uint32_t comps = s->comps * s->group;
    int cubic = s->interp == INTERP_CUBIC;
    uint32_t per = cubic ? 3 : 1, mid = cubic ? 1 : 0, n = s->keys;
    double t0 = gdoc_get(&s->in, 0, 0), tn = gdoc_get(&s->in, n - 1, 0);
    uint32_t k;
    if (t <= t0 || n == 1) {
        k = 0;
    } else if (t >= tn) {
        k = n - 1;
    } else {
        uint32_t lo = 0, hi = n - 1; /* time[lo] <= t < time[hi] */
        while (hi - lo > 1) {
            uint32_t m = lo + (hi - lo) / 2;
            if (gdoc_get(&s->in, m, 0) <= t)
                lo = m;
            else
                hi = m;
        }
        double ta = gdoc_get(&s->in, lo, 0), tb = gdoc_get(&s->in, hi, 0);
        if (t > ta && s->interp != INTERP_STEP) {
            double u = (t - ta) / (tb - ta), a[GANIM_MAX_WEIGHTS], b[GANIM_MAX_WEIGHTS];
            value(s, per * lo + mid, a);
            value(s, per * hi + mid, b);
            if (s->interp == INTERP_LINEAR) {
                if (rotation) {
                    slerp(a, b, u, v);
                    return;
                }
                for (uint32_t c = 0; c < comps; c++)
                    v[c] = (1.0 - u) * a[c] + u * b[c];
                return;
            }
            /* Hermite: out-tangent of key lo, in-tangent of key hi, both
             * scaled by the interval. */
            double ma[GANIM_MAX_WEIGHTS], mb[GANIM_MAX_WEIGHTS], td = tb - ta, u2 = u * u, u3 = u2 * u;
            value(s, per * lo + 2, ma);
            value(s, per * hi, mb);
            double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
            for (uint32_t c = 0; c < comps; c++)
                v[c] = h00 * a[c] + h10 * td * ma[c] + h01 * b[c] + h11 * td * mb[c];
            if (rotation)
                normalise(v);
            return;
        }
        k = lo;
    }
    value(s, per * k + mid, v);
}

/* Channel `ci` (object `co`) of animation `ai` (object `ao`, its samplers
 * `samplers`) evaluated at t into p. */
static int channel(gltf_doc *d, uint32_t ai, const cJSON *samplers, uint32_t ci, const cJSON *co, double t,
                   ganim_pose *p, fr_error *err)
{
    char ptr[96], tp[112];
    snprintf(ptr, sizeof ptr, "/animations/%u/channels/%u", ai, ci);
    snprintf(tp, sizeof tp, "%s/target", ptr);
    if (!cJSON_IsObject(co))
        return gdoc_fail(d, err, ptr, "expected an object");
    const cJSON *target;
    uint32_t si, node;
    uint32_t ns = (uint32_t)cJSON_GetArraySize(samplers);
    if (gdoc_index(d, co, ptr, "sampler", 1, ns, "this animation's samplers", &si, err) < 0 ||
        gdoc_object(d, co, ptr, "target", &target, err) < 0)
        return -1;
    if (!target)
        return gdoc_fail(d, err, ptr, "target is missing");
    if (gdoc_index(d, target, tp, "node", 0, d->nodes.n, "nodes", &node, err) < 0)
        return -1;
    const cJSON *path = cJSON_GetObjectItemCaseSensitive(target, "path");
    if (!cJSON_IsString(path))
        return gdoc_fail(d, err, tp, "path: expected translation, rotation, scale or weights");
    if (node == UINT32_MAX) {
        gdoc_warn(d, "anim-nonode", "%s: a channel without a target node is ignored", tp);
        return 0;
    }
    const char *pn = path->valuestring;
    unsigned bit = !strcmp(pn, "translation") ? GANIM_T : !strcmp(pn, "rotation") ? GANIM_R
                 : !strcmp(pn, "scale") ? GANIM_S : !strcmp(pn, "weights") ? GANIM_W : 0;
    if (!bit)
        return gdoc_fail(d, err, tp, "path: '%s' is not translation, rotation, scale or weights", pn);
    sampler s;
    uint32_t comps = bit == GANIM_R ? 4 : bit == GANIM_W ? 0 : 3;
    if (sampler_read(d, ai, si, cJSON_GetArrayItem(samplers, (int)si), comps, &s, err) < 0)
        return -1;
    ganim_node *a = &p->node[node];
    if (a->set & bit) {
        char key[64];
        snprintf(key, sizeof key, "anim-twice:%u:%u", node, bit);
        gdoc_warn(d, key, "%s: node %u's %s is animated already by /animations/%u: the first channel is used", ptr,
                  node, pn, a->anim);
        return 0;
    }
    if (!a->set) {
        a->anim = ai;
        a->channel = ci;
    }
    a->set |= bit;
    if (bit == GANIM_W) {
        if ((a->w = malloc(GANIM_MAX_WEIGHTS * sizeof *a->w)) == NULL)
            return gdoc_fail(d, err, ptr, "out of memory");
        a->n_weights = s.group;
    }
    sample(&s, t, bit == GANIM_R, bit == GANIM_T ? a->t : bit == GANIM_R ? a->r : bit == GANIM_S ? a->s : a->w);
    p->channels++;
    return 0;
}

int ganim_eval(gltf_doc *d, double t, ganim_pose *p, fr_error *err)
{
    memset(p, 0, sizeof *p);
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(d->root, "animations");
    if (!an)
        return 0;
    if (!cJSON_IsArray(an))
        return gdoc_fail(d, err, "/animations", "expected an array");
    if (!isfinite(t))
        return gdoc_fail(d, err, "/animations", "the time to evaluate them at is not finite");
    if (d->nodes.n && (p->node = calloc(d->nodes.n, sizeof *p->node)) == NULL)
        return gdoc_fail(d, err, "/animations", "out of memory");
    p->n = d->nodes.n;
    uint32_t ai = 0;
    for (const cJSON *ao = an->child; ao; ao = ao->next, ai++) {
        char ptr[48];
        snprintf(ptr, sizeof ptr, "/animations/%u", ai);
        if (!cJSON_IsObject(ao))
            return gdoc_fail(d, err, ptr, "expected an object");
        const cJSON *ch = cJSON_GetObjectItemCaseSensitive(ao, "channels");
        const cJSON *sm = cJSON_GetObjectItemCaseSensitive(ao, "samplers");
        if (!cJSON_IsArray(ch) || !cJSON_IsArray(sm))
            return gdoc_fail(d, err, ptr, "expected arrays channels and samplers");
        uint32_t ci = 0;
        for (const cJSON *co = ch->child; co; co = co->next, ci++)
            if (channel(d, ai, sm, ci, co, t, p, err) < 0)
                return -1;
    }
    return 0;
}
