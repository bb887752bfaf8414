/* freeze_light.c -- the light table of a scene being frozen, with pick
 * probabilities (see freeze_light.h). */

#include "compile/freeze_light.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compile/freeze_lighttree.h"
#include "fmath.h"
#include "compile/builder_instance.h"
#include "compile/builder_group.h"
#include "texture.h"

/* |a x b| in double: edges of coordinates up to 1e18 (jsonval.h) have
 * cross products whose squared length overflows a float. */
static double cross_len(vec3 a, vec3 b)
{
    double x = (double)a.y * b.z - (double)a.z * b.y, y = (double)a.z * b.x - (double)a.x * b.z,
           z = (double)a.x * b.y - (double)a.y * b.x;
    return sqrt(x * x + y * y + z * z);
}

static double prim_area(const fr_builder *b, const fr_prim *p)
{
    if (p->kind == FR_PRIM_SPHERE) {
        double r = ((const fr_sphere *)b->spheres.data)[p->index].radius;
        return 4.0 * FM_PI * r * r;
    }
    if (p->kind == FR_PRIM_RECT) {
        const fr_rect *q = &((const fr_rect *)b->rects.data)[p->index];
        return cross_len(q->edge_u, q->edge_v);
    }
    const fr_triangle *t = &((const fr_triangle *)b->triangles.data)[p->index];
    const vec3 *pos = b->positions.data;
    return 0.5 * cross_len(v3_sub(pos[t->v[1]], pos[t->v[0]]), v3_sub(pos[t->v[2]], pos[t->v[0]]));
}

/* The bounding sphere of everything bounded, and of the planes' points. */
static void bounds(fr_builder *b)
{
    vec3 lo = v3s(INFINITY), hi = v3s(-INFINITY);
    const fr_prim *prims = b->prims.data;
    for (uint32_t i = 0; i < b->prims.count; i++) {
        const fr_prim *p = &prims[i];
        if (p->kind == FR_PRIM_INSTANCE) {
            vec3 l, h;
            bld_instance_bounds(b, p->index, &l, &h);
            lo = v3_vmin(lo, l);
            hi = v3_vmax(hi, h);
        } else if (p->kind == FR_PRIM_SPHERE) {
            const fr_sphere *s = (const fr_sphere *)b->spheres.data + p->index;
            lo = v3_vmin(lo, v3_sub(s->center, v3s(s->radius)));
            hi = v3_vmax(hi, v3_add(s->center, v3s(s->radius)));
        } else if (p->kind == FR_PRIM_RECT) {
            const fr_rect *q = (const fr_rect *)b->rects.data + p->index;
            vec3 c[4] = {q->origin, v3_add(q->origin, q->edge_u), v3_add(q->origin, q->edge_v),
                         v3_add(v3_add(q->origin, q->edge_u), q->edge_v)};
            for (int k = 0; k < 4; k++) {
                lo = v3_vmin(lo, c[k]);
                hi = v3_vmax(hi, c[k]);
            }
        } else {
            const fr_triangle *t = (const fr_triangle *)b->triangles.data + p->index;
            for (int k = 0; k < 3; k++) {
                lo = v3_vmin(lo, ((const vec3 *)b->positions.data)[t->v[k]]);
                hi = v3_vmax(hi, ((const vec3 *)b->positions.data)[t->v[k]]);
            }
        }
    }
    for (uint32_t i = 0; i < b->planes.count; i++) {
        lo = v3_vmin(lo, ((const fr_plane *)b->planes.data)[i].point);
        hi = v3_vmax(hi, ((const fr_plane *)b->planes.data)[i].point);
    }
    if (!(lo.x <= hi.x)) {
        lo = v3s(0.0f);
        hi = v3s(0.0f);
    }
    b->world.center = v3_scale(v3_add(lo, hi), 0.5f);
    b->world.radius = 0.5f * v3_len(v3_sub(hi, lo));
    /* A point-sized scene still has a disk for distant light to cross. */
    if (!(b->world.radius > 1e-6f))
        b->world.radius = 1.0f;
}

/* The value of texel (i, j) of texture t (row j from the top; i wraps
 * around, j is clamped, as env lookups do), grey as luminance of
 * colour x texel, clamped at 0. */
static double texel_luma(const fr_builder *b, const fr_texture *t, vec3 color, int64_t i, int64_t j)
{
    int64_t w = t->width, h = t->height;
    i %= w;
    if (i < 0)
        i += w;
    j = j < 0 ? 0 : j >= h ? h - 1 : j;
    float p[3];
    tex_texel(b->texels.data, t, 0, (uint32_t)i, (uint32_t)j, p);
    vec3 c = t->channels == 3 ? v3(p[0], p[1], p[2]) : v3s(p[0]);
    double y = v3_luma(v3_mul(color, c));
    return y > 0.0 ? y : 0.0;
}

/* The environment map's sampling tables (scene.h, fr_world): each texel
 * weighs its row's sin(theta) times the mean over the texel of the map as
 * looked up (the texel itself when nearest, the bilinear reconstruction's
 * mean over the texel otherwise, which is never 0 where a lookup is not).
 * *integral receives the integral of the luminance over the sphere. */
static int env_tables(fr_builder *b, double *integral, fr_error *err)
{
    const fr_texture *t = (const fr_texture *)b->textures.data + b->world.env_texture;
    uint32_t w = t->width, h = t->height;
    size_t n = (size_t)w * h, total = n + h + 1 + (size_t)h * (w + 1);
    if (b->distrib.count + total >= FR_NONE / 2)
        return fr_fail(err, "environment: tables too large");
    double *f = malloc(n * sizeof *f), *row = malloc(h * sizeof *row);
    if (!f || !row) {
        free(f);
        free(row);
        return fr_fail(err, "environment: out of memory for its tables");
    }
    static const double k[3] = {0.125, 0.75, 0.125};
    int nearest = t->filter == FR_FILTER_NEAREST;
    double sum = 0.0, power = 0.0;
    for (uint32_t j = 0; j < h; j++) {
        double s = fm_sinf(FM_PI * ((float)j + 0.5f) / (float)h);
        row[j] = 0.0;
        for (uint32_t i = 0; i < w; i++) {
            double v = 0.0;
            if (nearest) {
                v = texel_luma(b, t, b->world.env_color, i, j);
            } else {
                for (int dj = -1; dj <= 1; dj++)
                    for (int di = -1; di <= 1; di++)
                        v += k[dj + 1] * k[di + 1] * texel_luma(b, t, b->world.env_color, (int64_t)i + di, (int64_t)j + dj);
            }
            power += texel_luma(b, t, b->world.env_color, i, j) * s;
            f[(size_t)j * w + i] = v * s;
            row[j] += v * s;
        }
        sum += row[j];
    }
    *integral = power * 2.0 * FM_PI * FM_PI / (double)n;
    int rc = 0;
    if (!(sum > 0.0)) {
        rc = fr_fail(err, "environment: the map is black (it would give no light)");
    } else if (bld_pad(&b->distrib, b->distrib.count + (uint32_t)total) < 0) {
        rc = fr_fail(err, "environment: out of memory for its tables");
    } else {
        b->world.dist_first = b->distrib.count - (uint32_t)total;
        float *pdf = (float *)b->distrib.data + b->world.dist_first, *marg = pdf + n, *cond = marg + h + 1;
        double acc = 0.0;
        for (uint32_t j = 0; j < h; j++) {
            marg[j] = (float)(acc / sum);
            acc += row[j];
            float *c = cond + (size_t)j * (w + 1);
            double ra = 0.0;
            for (uint32_t i = 0; i < w; i++) {
                double v = f[(size_t)j * w + i];
                pdf[(size_t)j * w + i] = (float)(v * (double)n / sum);
                c[i] = row[j] > 0.0 ? (float)(ra / row[j]) : (float)i / (float)w;
                ra += v;
            }
            c[w] = 1.0f;
        }
        marg[h] = 1.0f;
    }
    free(f);
    free(row);
    return rc;
}

/* What the weights of textured emitters share: a view of the builder's
 * textures for lookups, and each texture's mean value (computed once). */
typedef struct {
    fr_scene view;
    vec3 *mean;                /* per texture; x < 0 until computed */
} emit_ctx;

/* A textured emitter's weight is at least this fraction of its colour
 * times its texture's mean over all its texels: never 0 where the texture
 * is not black everywhere, whatever the estimate over the primitive says
 * (its points may miss a lit texel), so next-event estimation stays
 * unbiased; small enough that a black part of a screen takes next to
 * nothing from the lit part. */
#define EMIT_FLOOR 1e-3

/* Texture ti's mean value, each channel clamped at 0 as tex_emission
 * clamps it: over its level-0 texels, or a checker's two colours. */
static vec3 texture_mean(emit_ctx *c, uint32_t ti)
{
    if (c->mean[ti].x >= 0.0f)
        return c->mean[ti];
    const fr_texture *t = &c->view.textures[ti];
    double sum[3] = {0.0, 0.0, 0.0};
    if (t->kind == FR_TEX_CHECKER) {
        vec3 a = v3_vmax(t->color0, v3s(0.0f)), b = v3_vmax(t->color1, v3s(0.0f));
        sum[0] = 0.5 * ((double)a.x + b.x), sum[1] = 0.5 * ((double)a.y + b.y), sum[2] = 0.5 * ((double)a.z + b.z);
    } else {
        for (uint32_t y = 0; y < t->height; y++)
            for (uint32_t x = 0; x < t->width; x++) {
                float p[3];
                tex_texel(c->view.texels, t, 0, x, y, p);
                for (uint32_t k = 0; k < 3; k++) {
                    float v = p[t->channels == 3 ? k : 0];
                    sum[k] += v > 0.0f ? v : 0.0;
                }
            }
        double n = (double)t->width * t->height;
        for (int k = 0; k < 3; k++)
            sum[k] /= n;
    }
    c->mean[ti] = v3((float)sum[0], (float)sum[1], (float)sum[2]);
    return c->mean[ti];
}

/* Length in level-0 texels of a step d in uv across texture t (a checker
 * counts two texels a square). */
static double texels_along(const fr_texture *t, vec2 d)
{
    double w = t->kind == FR_TEX_IMAGE ? t->width : 2.0, h = t->kind == FR_TEX_IMAGE ? t->height : 2.0;
    double x = (double)d.u * t->scale.u * w, y = (double)d.v * t->scale.v * h;
    return sqrt(x * x + y * y);
}

/* How a primitive whose longest uv edge spans e level-0 texels of t is
 * integrated: from the first mip level on which that edge spans at most 16
 * texels (the last level if none), on a k-by-k grid with about two points
 * a texel of that level along the edge (k from 4 to 32). */
static int grid_for(const fr_texture *t, double e, uint32_t *level)
{
    uint32_t l = 0, levels = t->kind == FR_TEX_IMAGE ? t->levels : 1;
    while (e > 16.0 && l + 1 < levels) {
        e *= 0.5;
        l++;
    }
    *level = l;
    double k = ceil(2.0 * e);
    return !(k > 4.0) ? 4 : k > 32.0 ? 32 : (int)k;
}

/* Luminance of material m's emission at uv, read from mip level `level`. */
static double emission_at(const emit_ctx *c, const fr_material *m, vec2 uv, uint32_t level)
{
    vec3 v = v3_vmax(tex_eval_level(&c->view, m->tex_emission, uv, level), v3s(0.0f));
    return v3_luma(v3_mul(m->emission, v));
}

/* Mean luminance of the emission of primitive p (material m), for its
 * power: the emission colour times its texture's mean over the primitive,
 * integrated on a grid fine enough for the mip level read (grid_for): a
 * triangle cut into k x k equal triangles, read at their centroids; a
 * rectangle's k x k cells; a sphere's (u, v) square, 2k x k cells weighted
 * by sin(pi v), its area there.  Never below EMIT_FLOOR of the texture's
 * mean over all its texels. */
static double emission_luma(emit_ctx *c, const fr_builder *b, const fr_prim *p, const fr_material *m)
{
    if (m->tex_emission == FR_NONE)
        return v3_luma(m->emission);
    const fr_texture *t = (const fr_texture *)b->textures.data + m->tex_emission;
    double floor_ = EMIT_FLOOR * v3_luma(v3_mul(m->emission, texture_mean(c, m->tex_emission)));
    double sum = 0.0, weight = 0.0;
    uint32_t level;
    if (p->kind == FR_PRIM_TRIANGLE) {
        const fr_triangle *tri = (const fr_triangle *)b->triangles.data + p->index;
        vec2 uv[3] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};   /* barycentrics when it has none */
        if (tri->flags & FR_TRI_UVS)
            for (int q = 0; q < 3; q++)
                uv[q] = ((const vec2 *)b->uvs.data)[tri->v[q]];
        double e = 0.0;
        for (int q = 0; q < 3; q++) {
            double l = texels_along(t, (vec2){uv[(q + 1) % 3].u - uv[q].u, uv[(q + 1) % 3].v - uv[q].v});
            e = l > e ? l : e;
        }
        int k = grid_for(t, e, &level);
        /* Up triangles (i, j), (i + 1, j), (i, j + 1) of the lattice and
         * down ones (i + 1, j), (i, j + 1), (i + 1, j + 1): centroids at
         * (3i + 1, 3j + 1) / 3k and (3i + 2, 3j + 2) / 3k. */
        for (int i = 0; i < k; i++)
            for (int j = 0; i + j < k; j++)
                for (int d = 1; d <= 2; d++) {
                    if (d == 2 && i + j + 2 > k)
                        continue;
                    float b1 = (float)(3 * i + d) / (float)(3 * k), b2 = (float)(3 * j + d) / (float)(3 * k);
                    float b0 = 1.0f - b1 - b2;
                    vec2 at = {b0 * uv[0].u + b1 * uv[1].u + b2 * uv[2].u, b0 * uv[0].v + b1 * uv[1].v + b2 * uv[2].v};
                    sum += emission_at(c, m, at, level);
                    weight += 1.0;
                }
    } else if (p->kind == FR_PRIM_RECT || p->kind == FR_PRIM_SPHERE) {
        int sphere = p->kind == FR_PRIM_SPHERE;
        double eu = texels_along(t, (vec2){1.0f, 0.0f}), ev = texels_along(t, (vec2){0.0f, 1.0f});
        int k = grid_for(t, eu > ev ? eu : ev, &level), ku = sphere ? 2 * k : k;
        for (int j = 0; j < k; j++) {
            float v = ((float)j + 0.5f) / (float)k;
            double w = sphere ? fm_sinf(FM_PI * v) : 1.0;
            for (int i = 0; i < ku; i++) {
                sum += w * emission_at(c, m, (vec2){((float)i + 0.5f) / (float)ku, v}, level);
                weight += w;
            }
        }
    }
    double mean = weight > 0.0 ? sum / weight : 0.0;
    return mean > floor_ ? mean : floor_;
}

/* Power (W, as the light's units make it) that frz_lights gives light l
 * for its pick probability, for lights other than the environment.  An
 * area light with an emission texture counts the texture's mean over its
 * primitive (emission_luma), with a floor that keeps every emitter some
 * chance of being picked. */
static double frz_light_power(emit_ctx *c, const fr_builder *b, const fr_light *l)
{
    double r2 = (double)b->world.radius * b->world.radius, y = v3_luma(l->intensity);
    switch (l->kind) {
    case FR_LIGHT_POINT:
        return 4.0 * FM_PI * y;
    case FR_LIGHT_SPOT: {
        /* 2 pi times the falloff integrated over cos theta: 1 inside the
         * inner cone, ((c - co) / d)^2 between the cones. */
        double co = l->cone_cos, ci = l->cone_aux, d = ci - co > 0.001 ? ci - co : 0.001;
        return 2.0 * FM_PI * y * ((1.0 - ci) + (ci - co) * (ci - co) * (ci - co) / (3.0 * d * d));
    }
    case FR_LIGHT_SUN:
        return FM_PI * r2 * y;
    case FR_LIGHT_PRIM: {
        const fr_prim *p = (const fr_prim *)b->prims.data + l->prim;
        const fr_material *m = (const fr_material *)b->materials.data + p->material;
        /* In double: emission and area may each be near the float limit. */
        return FM_PI * emission_luma(c, b, p, m) * l->area * (m->two_sided ? 2.0 : 1.0);
    }
    default:
        return 0.0;
    }
}

/* The next light of the table's group (builder_group.h), when the scene
 * names groups: given, the light as the readers added it, or FR_NONE for
 * an area light of `material`.  FR_NONE when memory runs out. */
static uint32_t group(fr_builder *b, uint32_t given, uint32_t material)
{
    if (!b->group_names.count)
        return 0;
    uint32_t g = bld_group_of(b, given, material);
    return bld_push(&b->light_groups, &g);
}

/* Rank of a light kind in the table: distant lights first. */
static int rank(uint32_t kind) { return kind == FR_LIGHT_ENV ? 0 : kind == FR_LIGHT_SUN ? 1 : 2; }

int frz_lights(fr_builder *b, const uint32_t *placed, fr_error *err)
{
    bounds(b);
    /* Order what the readers added (stable), then append the area lights. */
    fr_array given = b->lights;
    b->lights = (fr_array){NULL, 0, 0, sizeof(fr_light)};
    b->light_groups.count = 0;
    b->world.env_light = FR_NONE;
    int rc = 0;
    for (int r = 0; r < 3 && rc == 0; r++)
        for (uint32_t i = 0; i < given.count && rc == 0; i++) {
            const fr_light *l = (const fr_light *)given.data + i;
            if (rank(l->kind) != r || l->kind == FR_LIGHT_PRIM)
                continue;
            if (rank(l->kind) < 2 && b->volume.fog)
                rc = fr_fail(err, "lights: a sun or an environment cannot light a scene filled with fog (the fog "
                             "is infinite, so no distant light reaches it); put the fog inside a shape instead "
                             "(a box whose material has \"medium\")");
            uint32_t at = rc < 0 ? 0 : bld_push(&b->lights, l);
            if (at == FR_NONE || (rc == 0 && group(b, i, 0) == FR_NONE))
                rc = fr_fail(err, "out of memory for lights");
            if (l->kind == FR_LIGHT_ENV)
                b->world.env_light = at;
        }
    free(given.data);
    if (rc < 0)
        return -1;
    const fr_material *mats = b->materials.data;
    fr_prim *prims = b->prims.data;
    for (uint32_t i = 0; i < b->prims.count; i++)
        prims[i].light = FR_NONE;
    for (uint32_t k = 0; k < b->prims.count; k++) {
        uint32_t i = placed ? placed[k] : k;
        if (prims[i].kind == FR_PRIM_INSTANCE || v3_is_zero(mats[prims[i].material].emission))
            continue;
        fr_light l;
        memset(&l, 0, sizeof l);
        l.kind = FR_LIGHT_PRIM;
        l.prim = i;
        double area = prim_area(b, &prims[i]);
        if (!(area <= FLT_MAX))
            return fr_fail(err, "primitive %u: an emitter of area %g, too large for single precision", k, area);
        l.area = (float)area;
        uint32_t li = bld_push(&b->lights, &l);
        if (li == FR_NONE || group(b, FR_NONE, prims[i].material) == FR_NONE)
            return fr_fail(err, "out of memory for lights");
        prims[i].light = li;
    }
    double env_power = 0.0;
    b->distrib.count = 0;
    if (b->world.env == FR_ENV_MAP) {
        double integral = 0.0;
        if (env_tables(b, &integral, err) < 0)
            return -1;
        env_power = FM_PI * (double)b->world.radius * b->world.radius * integral;
    } else if (b->world.env == FR_ENV_CONSTANT) {
        env_power = FM_PI * (double)b->world.radius * b->world.radius * 4.0 * FM_PI * v3_luma(b->world.env_color);
    }
    /* Pick probabilities in proportion to power, and their running sums. */
    fr_light *lights = b->lights.data;
    double total = 0.0, *power = malloc((b->lights.count + 1) * sizeof *power);
    if (!power)
        return fr_fail(err, "out of memory for lights");
    emit_ctx ec;
    memset(&ec, 0, sizeof ec);
    ec.view.textures = b->textures.data;
    ec.view.n_textures = b->textures.count;
    ec.view.texels = b->texels.data;
    ec.view.n_texels = b->texels.count;
    ec.mean = malloc((b->textures.count + 1) * sizeof *ec.mean);
    if (!ec.mean) {
        free(power);
        return fr_fail(err, "out of memory for lights");
    }
    for (uint32_t i = 0; i < b->textures.count; i++)
        ec.mean[i] = v3s(-1.0f);
    for (uint32_t i = 0; i < b->lights.count; i++) {
        power[i] = lights[i].kind == FR_LIGHT_ENV ? env_power : frz_light_power(&ec, b, &lights[i]);
        total += power[i];
    }
    free(ec.mean);
    double acc = 0.0;
    for (uint32_t i = 0; i < b->lights.count; i++) {
        double p = total > 0.0 ? power[i] / total : 1.0 / b->lights.count;
        acc += p;
        lights[i].pick = (float)p > 0.0f ? (float)p : 1e-30f;
        lights[i].cdf = i + 1 == b->lights.count ? 1.0f : (float)acc;
    }
    b->light_nodes.count = 0;
    int rc2 = b->no_light_tree ? 0 : frz_light_tree(b, power, err);
    free(power);
    return rc2;
}
