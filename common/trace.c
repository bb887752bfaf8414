#include "trace.h"

#include "bvh.h"
#include "fmath.h"

float trace_prim(const fr_scene *s, uint32_t i, const fr_ray *r, float tmax, float *a, float *b)
{
    const fr_prim *p = &s->prims[i];
    if (p->kind == FR_PRIM_TRIANGLE) {
        const fr_triangle *t = &s->triangles[p->index];
        return geo_triangle(s->positions[t->v[0]], s->positions[t->v[1]], s->positions[t->v[2]], r, tmax, a, b);
    }
    if (p->kind == FR_PRIM_SPHERE) {
        *a = *b = 0.0f;
        return geo_sphere(&s->spheres[p->index], r, tmax);
    }
    return geo_rect(&s->rects[p->index], r, tmax, a, b);
}

/* Slab test against a node's box with precomputed reciprocal direction;
 * returns the entry distance or -1 if missed within (0, tmax). */
static float box_entry(const fr_bvh_node *n, vec3 o, vec3 inv, float tmax)
{
    float tx0 = (n->lo.x - o.x) * inv.x, tx1 = (n->hi.x - o.x) * inv.x;
    float ty0 = (n->lo.y - o.y) * inv.y, ty1 = (n->hi.y - o.y) * inv.y;
    float tz0 = (n->lo.z - o.z) * inv.z, tz1 = (n->hi.z - o.z) * inv.z;
    float tmin = fmaxf(fmaxf(fminf(tx0, tx1), fminf(ty0, ty1)), fmaxf(fminf(tz0, tz1), 0.0f));
    float tfar = fminf(fminf(fmaxf(tx0, tx1), fmaxf(ty0, ty1)), fminf(fmaxf(tz0, tz1), tmax));
    /* Widen the far bound by a few ulps so rounding never drops a box that
     * the exact ray touches (robust traversal, Ize 2013). */
    return tmin <= tfar * 1.00000024f ? tmin : -1.0f;
}

/* Walk the BVH; with `any` set, return at the first hit. */
static int walk(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit, int any, uint32_t skip)
{
    int found = 0;
    for (uint32_t i = 0; i < s->n_planes; i++) {
        float t = geo_plane(&s->planes[i], r, tmax);
        if (t > 0.0f) {
            if (any) return 1;
            tmax = t;
            hit->t = t; hit->prim = FR_NONE; hit->plane = i; hit->a = hit->b = 0.0f;
            found = 1;
        }
    }
    if (s->n_nodes == 0)
        return found;
    vec3 inv = v3(1.0f / r->d.x, 1.0f / r->d.y, 1.0f / r->d.z);
    int neg[3] = {r->d.x < 0.0f, r->d.y < 0.0f, r->d.z < 0.0f};
    uint32_t stack[BVH_MAX_DEPTH * 2];
    int sp = 0;
    uint32_t node = 0;
    if (box_entry(&s->nodes[0], r->o, inv, tmax) < 0.0f)
        return found;
    for (;;) {
        const fr_bvh_node *n = &s->nodes[node];
        uint32_t count = n->count & 0xffffffu;
        if (count) {
            for (uint32_t i = n->offset; i < n->offset + count; i++) {
                float a, b;
                if (i == skip)
                    continue;
                float t = trace_prim(s, i, r, tmax, &a, &b);
                if (t > 0.0f) {
                    if (any) return 1;
                    tmax = t;
                    hit->t = t; hit->prim = i; hit->plane = FR_NONE; hit->a = a; hit->b = b;
                    found = 1;
                }
            }
        } else {
            /* Visit the near child first (by the split axis and ray sign). */
            uint32_t first = node + 1, second = n->offset;
            if (neg[n->count >> 24]) { uint32_t t = first; first = second; second = t; }
            float t1 = box_entry(&s->nodes[first], r->o, inv, tmax);
            float t2 = box_entry(&s->nodes[second], r->o, inv, tmax);
            if (t1 >= 0.0f && t2 >= 0.0f) {
                if (sp < (int)(sizeof stack / sizeof stack[0])) stack[sp++] = second;
                node = first;
                continue;
            }
            if (t1 >= 0.0f) { node = first; continue; }
            if (t2 >= 0.0f) { node = second; continue; }
        }
        if (sp == 0)
            return found;
        node = stack[--sp];
    }
}

int trace_closest(const fr_scene *s, const fr_ray *r, float tmax, fr_hit *hit)
{
    return walk(s, r, tmax, hit, 0, FR_NONE);
}

int trace_occluded(const fr_scene *s, const fr_ray *r, float tmax, uint32_t skip)
{
    fr_hit h;
    return walk(s, r, tmax, &h, 1, skip);
}

void trace_surface(const fr_scene *s, const fr_ray *r, const fr_hit *hit, fr_surface *out)
{
    out->p = v3_madd(r->o, r->d, hit->t);
    if (hit->prim == FR_NONE) {
        const fr_plane *pl = &s->planes[hit->plane];
        out->ng = out->ns = pl->normal;
        vec3 t, b;
        v3_basis(pl->normal, &t, &b);
        vec3 rel = v3_sub(out->p, pl->point);
        out->uv = (vec2){v3_dot(rel, t), v3_dot(rel, b)};
        out->dpdu = t;
        out->dpdv = b;
        out->material = pl->material;
        out->light = FR_NONE;
        return;
    }
    const fr_prim *p = &s->prims[hit->prim];
    out->material = p->material;
    out->light = p->light;
    if (p->kind == FR_PRIM_SPHERE) {
        const fr_sphere *sp = &s->spheres[p->index];
        vec3 n = v3_scale(v3_sub(out->p, sp->center), 1.0f / sp->radius);
        out->ng = out->ns = v3_norm(n);
        /* Re-project onto the surface: removes most of the hit point's error. */
        out->p = v3_madd(sp->center, out->ng, sp->radius);
        /* Longitude and latitude, seen from outside as an image is seen:
         * u grows eastward (+x toward -z), v from 0 at the -y pole to 1 at
         * +y, so cross(dpdu, dpdv) faces out and an image is not mirrored. */
        float phi = fm_atan2f(-out->ng.z, out->ng.x);
        out->uv = (vec2){(phi + FM_PI) * FM_INV_2PI, 1.0f - fm_acosf(out->ng.y) * FM_INV_PI};
        vec3 rel = v3_sub(out->p, sp->center);
        float rxz = sqrtf(rel.x * rel.x + rel.z * rel.z);
        out->dpdu = v3(2.0f * FM_PI * rel.z, 0.0f, -2.0f * FM_PI * rel.x);
        out->dpdv = rxz > 0.0f ? v3_scale(v3(rel.x * rel.y / rxz, -rxz, rel.z * rel.y / rxz), -FM_PI)
                               : v3(0.0f, 0.0f, 0.0f);
    } else if (p->kind == FR_PRIM_RECT) {
        const fr_rect *q = &s->rects[p->index];
        out->ng = out->ns = v3_norm(v3_cross(q->edge_u, q->edge_v));
        out->p = v3_add(q->origin, v3_add(v3_scale(q->edge_u, hit->a), v3_scale(q->edge_v, hit->b)));
        out->uv = (vec2){hit->a, hit->b};
        out->dpdu = q->edge_u;
        out->dpdv = q->edge_v;
    } else {
        const fr_triangle *t = &s->triangles[p->index];
        vec3 p0 = s->positions[t->v[0]], p1 = s->positions[t->v[1]], p2 = s->positions[t->v[2]];
        float b0 = 1.0f - hit->a - hit->b;
        out->p = v3_add(v3_add(v3_scale(p0, b0), v3_scale(p1, hit->a)), v3_scale(p2, hit->b));
        out->ng = v3_norm(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
        out->ns = out->ng;
        if (t->flags & FR_TRI_NORMALS) {
            vec3 n = v3_add(v3_add(v3_scale(s->normals[t->v[0]], b0), v3_scale(s->normals[t->v[1]], hit->a)),
                            v3_scale(s->normals[t->v[2]], hit->b));
            if (v3_len2(n) > 0.0f) {
                n = v3_norm(n);
                out->ns = v3_dot(n, out->ng) < 0.0f ? v3_neg(n) : n;
            }
        }
        if (t->flags & FR_TRI_UVS) {
            vec2 u0 = s->uvs[t->v[0]], u1 = s->uvs[t->v[1]], u2 = s->uvs[t->v[2]];
            out->uv = (vec2){b0 * u0.u + hit->a * u1.u + hit->b * u2.u, b0 * u0.v + hit->a * u1.v + hit->b * u2.v};
            /* Solve [dp1 dp2] = [dpdu dpdv] [duv1 duv2] for the tangents. */
            float du1 = u1.u - u0.u, dv1 = u1.v - u0.v, du2 = u2.u - u0.u, dv2 = u2.v - u0.v;
            float det = du1 * dv2 - dv1 * du2;
            vec3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
            if (fabsf(det) > 1e-20f) {
                float inv = 1.0f / det;
                out->dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), inv);
                out->dpdv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), inv);
            } else {
                v3_basis(out->ng, &out->dpdu, &out->dpdv);
            }
        } else {
            out->uv = (vec2){hit->a, hit->b};
            out->dpdu = v3_sub(p1, p0);
            out->dpdv = v3_sub(p2, p0);
        }
    }
}
