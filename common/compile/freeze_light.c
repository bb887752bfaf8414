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

/* Luminance of material m's emission at texture coordinates uv. */
static double emission_at(const fr_scene *view, const fr_material *m, vec2 uv)
{
    return v3_luma(tex_emission(view, m, uv));
}

/* Mean luminance of the emission of primitive p (material m) for its
 * power: the emission colour, times its texture's mean over a few points
 * of the primitive (the corners, edge midpoints and centre of a triangle,
 * a 3 x 3 grid on a rectangle), blended with a tenth of the texture's
 * mean over its whole square so that no textured light gets no power. */
static double emission_luma(const fr_builder *b, const fr_prim *p, const fr_material *m)
{
    if (m->tex_emission == FR_NONE)
        return v3_luma(m->emission);
    fr_scene view;
    memset(&view, 0, sizeof view);
    view.textures = b->textures.data;
    view.n_textures = b->textures.count;
    view.texels = b->texels.data;
    view.n_texels = b->texels.count;
    double global = 0.0, local = 0.0;
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++)
            global += emission_at(&view, m, (vec2){((float)i + 0.5f) / 8.0f, ((float)j + 0.5f) / 8.0f}) / 64.0;
    if (p->kind == FR_PRIM_TRIANGLE) {
        /* Barycentric points (b1, b2); uv as trace_surface computes it. */
        static const float pts[7][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5f, 0}, {0, 0.5f}, {0.5f, 0.5f}, {1.0f / 3, 1.0f / 3}};
        const fr_triangle *t = (const fr_triangle *)b->triangles.data + p->index;
        const vec2 *uvs = b->uvs.data;
        for (int k = 0; k < 7; k++) {
            float b1 = pts[k][0], b2 = pts[k][1], b0 = 1.0f - b1 - b2;
            vec2 uv = {b1, b2};
            if (t->flags & FR_TRI_UVS)
                uv = (vec2){b0 * uvs[t->v[0]].u + b1 * uvs[t->v[1]].u + b2 * uvs[t->v[2]].u,
                            b0 * uvs[t->v[0]].v + b1 * uvs[t->v[1]].v + b2 * uvs[t->v[2]].v};
            local += emission_at(&view, m, uv) / 7.0;
        }
    } else if (p->kind == FR_PRIM_RECT) {
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 3; i++)
                local += emission_at(&view, m, (vec2){((float)i + 0.5f) / 3.0f, ((float)j + 0.5f) / 3.0f}) / 9.0;
    } else {
        local = global;
    }
    return 0.9 * local + 0.1 * global;
}

/* Power (W, as the light's units make it) that frz_lights gives light l
 * for its pick probability, for lights other than the environment.  An
 * area light with an emission texture counts the texture's mean over a
 * few points of its primitive (nine tenths) and over the whole texture
 * (one tenth), so every emitter keeps some chance of being picked. */
static double frz_light_power(const fr_builder *b, const fr_light *l)
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
        return FM_PI * emission_luma(b, p, m) * l->area * (m->two_sided ? 2.0 : 1.0);
    }
    default:
        return 0.0;
    }
}

/* Rank of a light kind in the table: distant lights first. */
static int rank(uint32_t kind) { return kind == FR_LIGHT_ENV ? 0 : kind == FR_LIGHT_SUN ? 1 : 2; }

int frz_lights(fr_builder *b, const uint32_t *placed, fr_error *err)
{
    bounds(b);
    /* Order what the readers added (stable), then append the area lights. */
    fr_array given = b->lights;
    b->lights = (fr_array){NULL, 0, 0, sizeof(fr_light)};
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
            if (at == FR_NONE)
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
        if (li == FR_NONE)
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
    for (uint32_t i = 0; i < b->lights.count; i++) {
        power[i] = lights[i].kind == FR_LIGHT_ENV ? env_power : frz_light_power(b, &lights[i]);
        total += power[i];
    }
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
