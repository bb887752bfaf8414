/* bench_rays.h -- the rays the BVH benchmarks trace (bvhbench, bvhtrees).
 *
 * make_rays(s, w, h, &np, &nb) returns (malloc'd, the caller frees it; NULL
 * when out of memory) np primary rays, one through the centre of each
 * pixel of a w x h grid of the scene's camera, followed by nb diffuse
 * bounce rays: for each primary ray that hits, a cosine-distributed
 * direction about the geometric normal on the side the ray came from,
 * leaving the surface as the renderer's rays do (geo_offset).  The
 * directions come from a fixed counter-based sequence, so every program
 * and every run gets the same rays for the same scene. */
#ifndef FRANJA_BENCH_RAYS_H
#define FRANJA_BENCH_RAYS_H

#include <math.h>
#include <stdlib.h>

#include "geom.h"
#include "pathtrace.h"
#include "trace.h"

/* A small counter-based generator for the bounce directions. */
static inline float bench_rnd(uint32_t *state)
{
    uint32_t h = (*state += 0x9E3779B9u);
    h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}

static inline fr_ray *make_rays(const fr_scene *s, uint32_t w, uint32_t h, uint32_t *n_primary, uint32_t *n_bounce)
{
    fr_ray *r = malloc((size_t)w * h * 2 * sizeof *r);
    if (!r)
        return NULL;
    fr_scene cam = *s;
    cam.settings.width = w;
    cam.settings.height = h;
    uint32_t n = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            r[n++] = pt_camera_ray(&cam, x, y, 0.5f, 0.5f, 0.5f, 0.5f);
    *n_primary = n;
    uint32_t state = 12345;
    for (uint32_t i = 0; i < *n_primary; i++) {
        fr_hit hit;
        if (!trace_closest(s, &r[i], INFINITY, &hit))
            continue;
        fr_surface sf;
        trace_surface(s, &r[i], &hit, &sf);
        vec3 ng = v3_dot(sf.ng, r[i].d) < 0.0f ? sf.ng : v3_neg(sf.ng), t, b;
        v3_basis(ng, &t, &b);
        float u1 = bench_rnd(&state), u2 = bench_rnd(&state), rr = sqrtf(u1), phi = 2.0f * 3.14159265f * u2;
        vec3 d = v3_from_local(v3(rr * cosf(phi), rr * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u1))), t, b, ng);
        r[n].o = geo_offset(sf.p, sf.perr, ng, d);
        r[n].d = v3_norm(d);
        n++;
    }
    *n_bounce = n - *n_primary;
    return r;
}

#endif
