/* test_vertex.c -- the shared path-vertex pieces one by one against closed
 * forms.
 *
 * The path-vertex pieces the integrators share (vertex.h), one by one:
 * finding the next vertex with and without media (and how many sampler
 * dimensions that takes), next-event estimation at a surface against the
 * closed form of a point light over a Lambert plane, a blocked shadow ray,
 * the MIS weights of an area-light sample, and scattering onward from a
 * surface and from a medium. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "fmath.h"
#include "medium.h"
#include "scenes.h"
#include "vertex.h"

#define CAMERA "\"camera\": {\"position\": [0, 1, -3], \"target\": [0, 0, 0], \"fov\": 40}, "
#define IMAGE "\"image\": {\"width\": 8, \"height\": 8, \"spp\": 1}, "

static const char point_scene[] =
    "{" IMAGE CAMERA
    "\"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
    "\"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"}],"
    "\"lights\": [{\"type\": \"point\", \"position\": [0, 2, 0], \"intensity\": [4, 4, 4]}]}";

/* The same with a small ball in the way of the light from (0.5, 0, 0). */
static const char blocked_scene[] =
    "{" IMAGE CAMERA
    "\"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
    "\"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "             {\"type\": \"sphere\", \"center\": [0.25, 1, 0], \"radius\": 0.1, \"material\": \"floor\"}],"
    "\"lights\": [{\"type\": \"point\", \"position\": [0, 2, 0], \"intensity\": [4, 4, 4]}]}";

/* A downward-facing panel light over the floor. */
static const char area_scene[] =
    "{" IMAGE CAMERA
    "\"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},"
    "                \"panel\": {\"type\": \"emitter\", \"emission\": [3, 3, 3]}},"
    "\"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "             {\"type\": \"rect\", \"origin\": [-0.5, 2, -0.5], \"edge_u\": [1, 0, 0], \"edge_v\": [0, 0, 1],"
    "              \"material\": \"panel\"}]}";

/* Fog everywhere, a floor and a point light. */
static const char fog_scene[] =
    "{" IMAGE CAMERA
    "\"media\": {\"fog\": {\"sigma_a\": 0.1, \"sigma_s\": 0.4, \"g\": 0.3}}, \"medium\": \"fog\","
    "\"materials\": {\"floor\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
    "\"shapes\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"}],"
    "\"lights\": [{\"type\": \"point\", \"position\": [0, 2, 0], \"intensity\": [4, 4, 4]}]}";

static int close_rel(float a, float b, float tol) { return fabsf(a - b) <= tol * fabsf(b); }

/* The surface vertex straight below (0.5, 1, 0). */
static int floor_vertex(const fr_scene *s, fr_sampler *smp, vtx_vertex *v)
{
    fr_ray ray = {v3(0.5f, 1.0f, 0.0f), v3(0.0f, -1.0f, 0.0f), 0.0f};
    uint32_t medium = 0;
    vec3 beta = v3s(1.0f);
    smp_start(smp, 3, 4, 0, 0);
    return vtx_next(s, smp, &ray, &medium, &beta, (vtx_mis){1, 1}, NULL, v);
}

static void power_heuristic(void)
{
    CHECK(vtx_power_heuristic(1.0f, 0.0f) == 1.0f, "w(1, 0) = %g", (double)vtx_power_heuristic(1.0f, 0.0f));
    CHECK(vtx_power_heuristic(0.0f, 0.0f) == 0.0f, "w(0, 0) = %g", (double)vtx_power_heuristic(0.0f, 0.0f));
    CHECK(vtx_power_heuristic(2.0f, 2.0f) == 0.5f, "w(2, 2) = %g", (double)vtx_power_heuristic(2.0f, 2.0f));
    CHECK(close_rel(vtx_power_heuristic(1.0f, 3.0f) + vtx_power_heuristic(3.0f, 1.0f), 1.0f, 1e-6f),
          "weights of two techniques sum to 1");
}

static void point_light(void)
{
    fr_scene s;
    test_scene(point_scene, &s);
    fr_sampler smp;
    vtx_vertex v;
    int kind = floor_vertex(&s, &smp, &v);
    CHECK(kind == VTX_SURFACE && v.kind == VTX_SURFACE, "floor below: kind %d", kind);
    CHECK(fabsf(v.sf.p.x - 0.5f) < 1e-6f && fabsf(v.sf.p.y) < 1e-6f, "hit at (%g, %g)", (double)v.sf.p.x,
          (double)v.sf.p.y);
    CHECK(smp.dim == 0, "no media: no sampler dimension drawn (%u)", smp.dim);

    /* L = beta * (albedo / pi) * I cos / d^2, pdf 1 (the only light: light
     * 0, picked with probability 1, as lgt_choose picks it). */
    vtx_direct d;
    vtx_mis mis = {1, 1};
    vec3 beta = v3(1.0f, 0.5f, 0.25f);
    const fr_material *m = &s.materials[v.sf.material];
    vtx_origin org = vtx_origin_at(&v.sf, v3(0, 1, 0));
    int got = vtx_direct_surface(&s, m, &v.sf, v3(0, 1, 0), 0, beta, mis, 0, 1.0f, 0.6f, 0.2f, &org, &d);
    float d2 = 0.25f + 4.0f, cosv = 2.0f / sqrtf(d2), want = 0.5f / FM_PI * 4.0f / d2 * cosv;
    CHECK(got == 1, "point light sampled");
    CHECK(d.ls.delta && d.weight == 1.0f, "a point light sample is not weighted (%g)", (double)d.weight);
    CHECK(close_rel(d.L.x, want, 1e-5f) && close_rel(d.L.y, 0.5f * want, 1e-5f) && close_rel(d.L.z, 0.25f * want, 1e-5f),
          "L = (%g %g %g), closed form %g times beta", (double)d.L.x, (double)d.L.y, (double)d.L.z, (double)want);
    CHECK(close_rel(d.scatter_pdf, cosv / FM_PI, 1e-5f), "Lambert pdf toward the light %g, want %g",
          (double)d.scatter_pdf, (double)(cosv / FM_PI));
    /* Seen from below the floor the Lambert lobe faces away: no light. */
    org = vtx_origin_at(&v.sf, v3(0, -1, 0));
    CHECK(vtx_direct_surface(&s, m, &v.sf, v3(0, -1, 0), 0, beta, mis, 0, 1.0f, 0.6f, 0.2f, &org, &d) == 0,
          "no light through the back of the floor");
    scn_free(&s);

    test_scene(blocked_scene, &s);
    kind = floor_vertex(&s, &smp, &v);
    CHECK(kind == VTX_SURFACE, "blocked scene: floor below");
    m = &s.materials[v.sf.material];
    org = vtx_origin_at(&v.sf, v3(0, 1, 0));
    CHECK(vtx_direct_surface(&s, m, &v.sf, v3(0, 1, 0), 0, beta, mis, 0, 1.0f, 0.6f, 0.2f, &org, &d) == 0,
          "a ball between the floor and the light blocks it");
    fr_ray up = {v3(0.5f, 1.0f, 0.0f), v3(0.0f, 1.0f, 0.0f), 0.0f};
    uint32_t medium = 0;
    CHECK(vtx_next(&s, &smp, &up, &medium, &beta, (vtx_mis){1, 1}, NULL, &v) == VTX_ESCAPED, "a ray into the sky escapes");
    scn_free(&s);
}

static void area_light(void)
{
    fr_scene s;
    test_scene(area_scene, &s);
    fr_sampler smp;
    vtx_vertex v;
    CHECK(floor_vertex(&s, &smp, &v) == VTX_SURFACE, "area scene: floor below");
    const fr_material *m = &s.materials[v.sf.material];
    vtx_direct a, b;
    vtx_mis mis = {1, 1}, off = {0, 1};
    vec3 beta = v3s(1.0f);
    vtx_origin org = vtx_origin_at(&v.sf, v3(0, 1, 0));
    int ga = vtx_direct_surface(&s, m, &v.sf, v3(0, 1, 0), 0, beta, mis, 0, 1.0f, 0.3f, 0.7f, &org, &a);
    int gb = vtx_direct_surface(&s, m, &v.sf, v3(0, 1, 0), 0, beta, off, 0, 1.0f, 0.3f, 0.7f, &org, &b);
    CHECK(ga && gb && !a.ls.delta, "panel sampled");
    CHECK(b.weight == 1.0f, "not weighed: weight %g", (double)b.weight);
    CHECK(a.weight == vtx_power_heuristic(a.ls.pdf, a.scatter_pdf) && a.weight > 0.0f && a.weight < 1.0f,
          "MIS weight %g from pdfs %g, %g", (double)a.weight, (double)a.ls.pdf, (double)a.scatter_pdf);
    float cosv = a.ls.wi.y;
    CHECK(close_rel(a.scatter_pdf, cosv / FM_PI, 1e-5f), "Lambert pdf %g, want %g", (double)a.scatter_pdf,
          (double)(cosv / FM_PI));
    /* Same sample, so the weighted contribution is the unweighted one times w. */
    CHECK(close_rel(a.L.y, b.L.y * a.weight, 1e-5f), "L %g = %g * %g", (double)a.L.y, (double)b.L.y,
          (double)a.weight);
    float want = 0.5f / FM_PI * 3.0f * cosv / b.ls.pdf;
    CHECK(close_rel(b.L.y, want, 1e-5f), "L %g, want f Le cos / pdf = %g", (double)b.L.y, (double)want);

    /* Scattering onward leaves the floor upward, in the sampled direction. */
    fr_bsdf_sample bs;
    fr_ray next;
    uint32_t medium = 0;
    CHECK(vtx_scatter_surface(&s, m, &v.sf, v3(0, 1, 0), 0.5f, 0.3f, 0.6f, &org, &bs, &next, &medium) == 1,
          "Lambert scatters");
    CHECK(next.d.x == bs.wi.x && next.d.y == bs.wi.y && next.d.z == bs.wi.z && next.d.y > 0.0f && next.o.y > 0.0f &&
              medium == 0,
          "next ray leaves above the floor along wi");
    vec3 o = geo_offset(v.sf.p, v.sf.perr, v.sf.ng, bs.wi), ob = geo_offset(v.sf.p, v.sf.perr, v.sf.ng, v3(0, -1, 0));
    CHECK(org.below == 0 && memcmp(&next.o, &o, sizeof o) == 0 && memcmp(&org.o, &o, sizeof o) == 0,
          "the origin is geo_offset's, made for the upper side");
    CHECK(ob.y < 0.0f && ob.y < o.y, "geo_offset pushes a downward ray's origin below the floor (%g)", (double)ob.y);
    vtx_origin below = vtx_origin_at(&v.sf, v3(0, -1, 0));
    CHECK(below.below == 1 && memcmp(&below.o, &ob, sizeof ob) == 0, "the origin below the floor is geo_offset's");
    /* The vertex's origin is taken as it is for rays on its side, and not
     * for rays on the other side. */
    vtx_origin planted = {v3(1, 2, 3), 0};
    CHECK(vtx_scatter_surface(&s, m, &v.sf, v3(0, 1, 0), 0.5f, 0.3f, 0.6f, &planted, &bs, &next, &medium) == 1 &&
              next.o.x == 1.0f && next.o.y == 2.0f && next.o.z == 3.0f,
          "the origin made for the upper side is reused");
    planted.below = 1;
    CHECK(vtx_scatter_surface(&s, m, &v.sf, v3(0, 1, 0), 0.5f, 0.3f, 0.6f, &planted, &bs, &next, &medium) == 1 &&
              memcmp(&next.o, &o, sizeof o) == 0,
          "the lower side's origin is not taken for the upper side");
    scn_free(&s);
}

static void media(void)
{
    fr_scene s;
    test_scene(fog_scene, &s);
    /* A ray in the fog draws three pairs per medium segment, whether or not
     * it adds the equiangular estimate; both walks go the same way. */
    int scattered = 0;
    for (uint32_t i = 0; i < 64; i++) {
        fr_sampler s1, s2;
        smp_start(&s1, 1, 2, i, 7);
        smp_start(&s2, 1, 2, i, 7);
        fr_ray r1 = {v3(0.0f, 1.0f, -3.0f), v3_norm(v3(0.0f, -1.0f, 3.0f)), 0.0f}, r2 = r1;
        uint32_t m1 = 1, m2 = 1;
        vec3 b1 = v3s(1.0f), b2 = v3s(1.0f), L = v3s(0.0f);
        vtx_vertex v1, v2;
        int k1 = vtx_next(&s, &s1, &r1, &m1, &b1, (vtx_mis){1, 1}, &L, &v1);
        int k2 = vtx_next(&s, &s2, &r2, &m2, &b2, (vtx_mis){1, 1}, NULL, &v2);
        CHECK(k1 == k2 && s1.dim == 3 && s2.dim == 3 && !memcmp(&b1, &b2, sizeof b1), "sample %u: kinds %d %d, dims %u %u",
              i, k1, k2, s1.dim, s2.dim);
        CHECK(k1 != VTX_ESCAPED, "sample %u: the floor or the fog stops the ray", i);
        CHECK(L.x >= 0.0f && isfinite(L.x), "sample %u: equiangular estimate %g", i, (double)L.x);
        if (k1 != VTX_MEDIUM)
            continue;
        scattered++;
        CHECK(v1.t > 0.0f && v1.t < v1.seg_tmax, "sample %u: scatters inside its segment", i);
        fr_ray next;
        float pdf;
        vtx_scatter_medium(&s, &v1, m1, 0.25f, 0.75f, &next, &pdf);
        CHECK(next.o.x == v1.p.x && next.o.y == v1.p.y && next.o.z == v1.p.z &&
                  close_rel(pdf, med_phase(0.3f, v3_dot(v1.seg.d, next.d)), 1e-6f),
              "sample %u: phase sample from the vertex, pdf %g", i, (double)pdf);
        vtx_direct d;
        vtx_mis mis = {1, 1};
        if (vtx_direct_medium(&s, &v1, m1, b1, mis, 0, 1.0f, 0.5f, 0.5f, &d)) {
            float want = vtx_power_heuristic(med_distance_pdf(&s.media[0], v1.seg_beta, v1.t),
                                             med_equiangular_pdf(v1.seg.o, v1.seg.d, v1.seg_tmax, d.ls.p, v1.t));
            CHECK(d.ls.delta && d.weight == want, "sample %u: point light weighed against equiangular (%g, %g)", i,
                  (double)d.weight, (double)want);
        }
    }
    CHECK(scattered > 0, "some of 64 paths scatter in the fog");
    /* Vacuum in a scene with media: nothing drawn. */
    fr_sampler smp;
    smp_start(&smp, 0, 0, 0, 0);
    fr_ray r = {v3(0.5f, 1.0f, 0.0f), v3(0.0f, -1.0f, 0.0f), 0.0f};
    uint32_t medium = 0;
    vec3 beta = v3s(1.0f);
    vtx_vertex v;
    CHECK(vtx_next(&s, &smp, &r, &medium, &beta, (vtx_mis){1, 1}, NULL, &v) == VTX_SURFACE && smp.dim == 0,
          "vacuum: the floor, no dimension drawn (%u)", smp.dim);
    scn_free(&s);
}

int main(void)
{
    power_heuristic();
    point_light();
    area_light();
    media();
    return check_done();
}
