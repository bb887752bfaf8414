/* test_medium.c -- participating media against transmittance and scattering
 * integrals.
 *
 * Participating media: transmittance e^(-sigma_t d) through slabs, the
 * sampling routines against their densities, single scattering from a
 * point light and from a rect or quad area light against the numerically
 * integrated analytic integral (with and without equiangular sampling, and
 * the variance each gives), and
 * white furnaces filled with albedo-1 media. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "medium.h"
#include "pathtrace.h"
#include "scenes.h"

/* ---- building blocks ------------------------------------------------------ */

static void transmittance_and_phase(void)
{
    fr_medium m = {v3(0.5f, 1.0f, 2.0f), v3(0.25f, 0.0f, 1.0f), 0.0f, 0};
    const float ds[] = {0.0f, 0.01f, 0.7f, 3.0f, 20.0f};
    for (int i = 0; i < 5; i++) {
        vec3 t = med_transmittance(&m, ds[i]);
        double e[3] = {exp(-0.75 * ds[i]), exp(-1.0 * ds[i]), exp(-3.0 * ds[i])};
        CHECK(fabs(t.x - e[0]) <= 1e-6 * e[0] + 1e-30 && fabs(t.y - e[1]) <= 1e-6 * e[1] + 1e-30 &&
                  fabs(t.z - e[2]) <= 1e-6 * e[2] + 1e-30,
              "Tr(%g) = %g %g %g, expected %g %g %g", ds[i], t.x, t.y, t.z, e[0], e[1], e[2]);
    }
    vec3 t = med_transmittance(&m, INFINITY);
    CHECK(t.x == 0.0f && t.y == 0.0f && t.z == 0.0f, "Tr(inf) is not 0");
    /* The phase function integrates to 1 and has mean cosine g; sampling
     * follows it (mean cosine and a histogram in cos theta). */
    const float gs[] = {0.0f, 0.6f, -0.3f, 0.9f};
    for (int k = 0; k < 4; k++) {
        float g = gs[k];
        double integral = 0, mean = 0;
        int n = 20000;
        for (int i = 0; i < n; i++) {
            double mu = -1.0 + (i + 0.5) * 2.0 / n;
            double p = med_phase(g, (float)mu) * 2.0 * M_PI * 2.0 / n;
            integral += p;
            mean += p * mu;
        }
        CHECK(fabs(integral - 1.0) < 1e-3, "HG g=%g integrates to %g", g, integral);
        CHECK(fabs(mean - g) < 1e-3, "HG g=%g has mean cosine %g", g, mean);
        vec3 d = v3_norm(v3(0.3f, -0.5f, 0.8f));
        enum { BINS = 10, N = 40000 };
        int hist[BINS] = {0};
        double smean = 0;
        for (int i = 0; i < N; i++) {
            vec3 w = med_sample_phase(g, d, (i + 0.5f) / N, fmodf(i * 0.6180339887f, 1.0f));
            float mu = v3_dot(w, d);
            smean += mu;
            int b = (int)((mu + 1.0f) * 0.5f * BINS);
            hist[b < 0 ? 0 : b >= BINS ? BINS - 1 : b]++;
        }
        CHECK(fabs(smean / N - g) < 2e-3, "HG g=%g sampled mean cosine %g", g, smean / N);
        double worst = 0;
        for (int b = 0; b < BINS; b++) {
            double lo = -1.0 + 2.0 * b / BINS, hi = lo + 2.0 / BINS, pb = 0;
            for (int j = 0; j < 200; j++) {
                double mu = lo + (j + 0.5) * (hi - lo) / 200;
                pb += med_phase(g, (float)mu) * 2.0 * M_PI * (hi - lo) / 200;
            }
            worst = fmax(worst, fabs(hist[b] / (double)N - pb));
        }
        CHECK(worst < 2e-3, "HG g=%g: sampled histogram off by %g", g, worst);
    }
}

/* Free-flight sampling: the expected weight of scattering in [0, tmax) is
 * sigma_s / sigma_t (1 - Tr(tmax)) per channel, of reaching the end Tr(tmax). */
static void distance_sampling(void)
{
    fr_medium m = {v3(0.1f, 0.3f, 0.0f), v3(0.4f, 0.2f, 0.6f), 0.0f, 0};
    const float tmaxes[] = {0.5f, 3.0f, INFINITY};
    for (int k = 0; k < 3; k++) {
        float tmax = tmaxes[k];
        double sc[3] = {0, 0, 0}, re[3] = {0, 0, 0};
        enum { N = 3 * 20000 };
        for (int i = 0; i < N; i++) {
            float t;
            vec3 w;
            float uch = (i + 0.5f) / N, u = fmodf(i * 0.6180339887f, 1.0f);
            double *acc = med_sample_distance(&m, tmax, v3(0.2f, 0.5f, 0.3f), uch, u, &t, &w) ? sc : re;
            acc[0] += w.x, acc[1] += w.y, acc[2] += w.z;
        }
        vec3 st = v3_add(m.sigma_a, m.sigma_s), tr = med_transmittance(&m, tmax);
        float s3[3] = {m.sigma_s.x, m.sigma_s.y, m.sigma_s.z}, t3[3] = {st.x, st.y, st.z}, r3[3] = {tr.x, tr.y, tr.z};
        for (int c = 0; c < 3; c++) {
            double esc = s3[c] / t3[c] * (1.0 - r3[c]);
            CHECK(fabs(sc[c] / N - esc) < 2e-3, "tmax %g channel %d: scattering weight %g, expected %g", tmax, c,
                  sc[c] / N, esc);
            CHECK(fabs(re[c] / N - r3[c]) < 2e-3, "tmax %g channel %d: reaching weight %g, expected %g", tmax, c,
                  re[c] / N, r3[c]);
        }
    }
}

/* Equiangular sampling: its pdf integrates to 1 over the segment, and the
 * samples follow it. */
static void equiangular_sampling(void)
{
    vec3 o = v3(0, 0, 0), d = v3(0, 0, -1), c = v3(0.3f, 0.2f, -2.0f);
    const float tmaxes[] = {1.0f, 5.0f, INFINITY};
    for (int k = 0; k < 3; k++) {
        float tmax = tmaxes[k];
        /* Integral by the substitution t = delta + h tan(theta). */
        double integral = 0, hi = tmax == INFINITY ? 1e6 : tmax;
        int n = 200000;
        for (int i = 0; i < n; i++) {
            double t = hi * pow((i + 0.5) / n, 3.0), dt = hi * 3.0 * pow((i + 0.5) / n, 2.0) / n;
            integral += med_equiangular_pdf(o, d, tmax, c, (float)t) * dt;
        }
        CHECK(fabs(integral - 1.0) < 2e-3, "equiangular pdf over [0, %g) integrates to %g", tmax, integral);
        int inside = 0, ok = 1;
        double below = 0;
        enum { N = 10000 };
        for (int i = 0; i < N; i++) {
            float t, pdf;
            if (!med_equiangular(o, d, tmax, c, (i + 0.5f) / N, &t, &pdf))
                continue;
            inside++;
            ok &= fabsf(pdf - med_equiangular_pdf(o, d, tmax, c, t)) <= 1e-4f * pdf;
            below += t < 2.0f;
        }
        double p2 = 0;
        for (int i = 0; i < 20000; i++) {
            double t = (i + 0.5) * fmin(2.0, hi) / 20000;
            p2 += med_equiangular_pdf(o, d, tmax, c, (float)t) * fmin(2.0, hi) / 20000;
        }
        CHECK(inside == N && ok, "equiangular tmax %g: %d of %d samples, pdfs consistent %d", tmax, inside, N, ok);
        CHECK(fabs(below / N - p2) < 2e-3, "equiangular tmax %g: P(t < 2) sampled %g, integrated %g", tmax, below / N, p2);
    }
}

/* ---- slabs ----------------------------------------------------------------- */

#define HEAD(w, h, spp, depth)                                                                  \
    "{\"image\": {\"width\": " #w ", \"height\": " #h ", \"spp\": " #spp ", \"max_depth\": " #depth "},"

/* An emitter seen through two absorbing slabs (boxes bounded by interfaces)
 * of thickness 0.5 and 1.25: every pixel is Le e^(-sigma_t d) exactly, per
 * channel; shadow rays through the same slabs carry the same factor. */
static void slabs(void)
{
    const char *json = HEAD(4, 4, 4, 0)
        " \"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"fov\": 0.01},"
        " \"media\": {\"ink\": {\"sigma_a\": [0.4, 1.0, 2.5]}, \"tea\": {\"sigma_a\": [0.1, 0.3, 0.7]}},"
        " \"materials\": {\"ink\": {\"type\": \"interface\", \"medium\": \"ink\"},"
        "   \"tea\": {\"type\": \"interface\", \"medium\": \"tea\"},"
        "   \"lamp\": {\"type\": \"emitter\", \"emission\": [3, 2, 1]}, \"wall\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}},"
        " \"shapes\": [{\"type\": \"box\", \"min\": [-5, -5, 2], \"max\": [5, 5, 2.5], \"material\": \"ink\"},"
        "   {\"type\": \"box\", \"min\": [-5, -5, -1], \"max\": [5, 5, 0.25], \"material\": \"tea\"},"
        "   {\"type\": \"rect\", \"origin\": [-5, -5, -3], \"edge_u\": [10, 0, 0], \"edge_v\": [0, 10, 0], \"material\": \"lamp\"},"
        "   {\"type\": \"rect\", \"origin\": [-5, -5, -8], \"edge_u\": [0, 10, 0], \"edge_v\": [10, 0, 0], \"material\": \"wall\"}]}";
    fr_scene s;
    test_scene(json, &s);
    CHECK(s.n_media == 2 && s.volume.camera_medium == 0 && s.volume.fog == 0, "slab scene: %u media, camera in %u",
          s.n_media, s.volume.camera_medium);
    float rgb[4 * 4 * 3];
    pt_render_rows(&s, PT_MIS, 0, 4, rgb);
    double e[3] = {3 * exp(-0.4 * 0.5 - 0.1 * 1.25), 2 * exp(-1.0 * 0.5 - 0.3 * 1.25), 1 * exp(-2.5 * 0.5 - 0.7 * 1.25)};
    double worst = 0;
    for (int i = 0; i < 16; i++)
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(rgb[i * 3 + c] - e[c]) / e[c]);
    CHECK(worst < 5e-4, "emitter through slabs: off by %g (relative) from Le e^(-sigma_t d)", worst);
    /* A shadow ray from z = 4 to z = -2.5 crosses both slabs. */
    fr_ray r = {v3(0.1f, 0.2f, 4.0f), v3(0, 0, -1), 0.0f};
    vec3 tr = med_shadow(&s, 0, &r, 6.5f, FR_NONE);
    /* (Each boundary crossing moves the ray by the surface offset, ~1e-4.) */
    CHECK(fabs(tr.x * 3 - e[0]) < 5e-4 * e[0] && fabs(tr.y * 2 - e[1]) < 5e-4 * e[1] && fabs(tr.z - e[2]) < 5e-4 * e[2],
          "shadow transmittance %g %g %g", tr.x, tr.y, tr.z);
    /* Past the emitter, the shadow ray is blocked. */
    tr = med_shadow(&s, 0, &r, 9.0f, FR_NONE);
    CHECK(v3_is_zero(tr), "a shadow ray through an opaque surface has transmittance %g", tr.x);
    scn_free(&s);
}

/* ---- single scattering ----------------------------------------------------- */

/* A camera at the origin looks down -z through a thin chromatic fog lit by
 * a point light; one pixel, a tiny field of view; max_depth 1 keeps single
 * scattering only.  A black sphere far behind the camera is the scene's
 * only surface. */
static const float SIG_S[3] = {0.05f, 0.08f, 0.03f}, SIG_A[3] = {0.02f, 0.01f, 0.05f}, G = 0.3f, INTENSITY = 10.0f;
static const double LIGHT[3] = {0.4, 1.0, -3.0};

static void fog_scene(fr_scene *s)
{
    char json[2048];
    snprintf(json, sizeof json,
             HEAD(1, 1, 1, 1)
             " \"camera\": {\"position\": [0, 0, 0], \"target\": [0, 0, -1], \"fov\": 0.001},"
             " \"media\": {\"fog\": {\"sigma_a\": [%g, %g, %g], \"sigma_s\": [%g, %g, %g], \"g\": %g}},"
             " \"medium\": \"fog\","
             " \"materials\": {\"black\": {\"type\": \"lambert\", \"albedo\": [0, 0, 0]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 1000], \"radius\": 1, \"material\": \"black\"}],"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, %g, %g]}]}",
             SIG_A[0], SIG_A[1], SIG_A[2], SIG_S[0], SIG_S[1], SIG_S[2], G, LIGHT[0], LIGHT[1], LIGHT[2], INTENSITY,
             INTENSITY, INTENSITY);
    test_scene(json, s);
}

/* The analytic integral along the ray x(t) = -t z:
 *   L = int_0^inf e^(-st t) ss p(cos) I e^(-st r) / r^2 dt,
 * integrated over theta with t = delta + h tan(theta), dt / r^2 = dtheta / h. */
static double single_scattering(int c)
{
    double delta = -LIGHT[2], h = sqrt(LIGHT[0] * LIGHT[0] + LIGHT[1] * LIGHT[1]), st = SIG_S[c] + SIG_A[c];
    double a = atan2(-delta, h), b = M_PI / 2, sum = 0;
    int n = 200000;
    for (int i = 0; i < n; i++) {
        double th = a + (b - a) * (i + 0.5) / n, t = delta + h * tan(th), r = h / cos(th);
        /* cos between the propagation direction -z and the direction to
         * the light, (c - x(t)) / r */
        double mu = -(LIGHT[2] + t) / r;
        double p = (1 - G * G) / (4 * M_PI * pow(1 + G * G - 2 * G * mu, 1.5));
        sum += exp(-st * (t + r)) * SIG_S[c] * p * INTENSITY / h * (b - a) / n;
    }
    return sum;
}

/* Mean and variance of n samples of the single pixel. */
static void estimate(const fr_scene *s, pt_strategy st, uint32_t n, double mean[3], double var[3])
{
    double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; i++) {
        vec3 v = pt_sample(s, st, 0, 0, i);
        double c[3] = {v.x, v.y, v.z};
        for (int k = 0; k < 3; k++)
            sum[k] += c[k], sq[k] += c[k] * c[k];
    }
    for (int k = 0; k < 3; k++) {
        mean[k] = sum[k] / n;
        var[k] = sq[k] / n - mean[k] * mean[k];
    }
}

static void point_light_in_fog(void)
{
    fr_scene s;
    fog_scene(&s);
    enum { N = 1 << 16 };
    double ref[3], m_mis[3], v_mis[3], m_dist[3], v_dist[3];
    for (int c = 0; c < 3; c++)
        ref[c] = single_scattering(c);
    estimate(&s, PT_MIS, N, m_mis, v_mis);
    estimate(&s, PT_MIS_DISTANCE, N, m_dist, v_dist);
    for (int c = 0; c < 3; c++) {
        double se_mis = sqrt(v_mis[c] / N), se_dist = sqrt(v_dist[c] / N);
        CHECK(fabs(m_mis[c] - ref[c]) < 4 * se_mis + 1e-3 * ref[c] && fabs(m_mis[c] - ref[c]) < 0.01 * ref[c],
              "channel %d: equiangular+MIS %g +- %g, analytic %g", c, m_mis[c], se_mis, ref[c]);
        CHECK(fabs(m_dist[c] - ref[c]) < 4 * se_dist + 1e-3 * ref[c] && fabs(m_dist[c] - ref[c]) < 0.03 * ref[c],
              "channel %d: distance sampling %g +- %g, analytic %g", c, m_dist[c], se_dist, ref[c]);
    }
    /* Same scene, same sample count: equiangular + MIS against distance
     * sampling alone (the figure is printed for the record). */
    double ratio = (v_dist[0] + v_dist[1] + v_dist[2]) / (v_mis[0] + v_mis[1] + v_mis[2]);
    printf("# single scattering, %d spp: variance distance-only / equiangular+MIS = %.1f\n", N, ratio);
    CHECK(ratio > 4.0, "equiangular + MIS reduces the variance only %.2fx", ratio);
    scn_free(&s);
}

/* The same fog and camera lit by a square area light (side 0.5, one unit
 * above the ray, facing down, radiance LE; a triangle pair or a rect):
 * equiangular sampling toward a point chosen on the light first, weighed
 * against the vertex's light sample and its phase sample, must give the
 * analytic single scattering, as each technique alone does. */
static const double AREA_Z = -3.0, AREA_SIDE = 0.5, LE = 6.0;

static void area_fog_scene(fr_scene *s, int triangles)
{
    char json[2048], shape[512];
    double x0 = -AREA_SIDE / 2, x1 = AREA_SIDE / 2, z0 = AREA_Z - AREA_SIDE / 2, z1 = AREA_Z + AREA_SIDE / 2;
    if (triangles) /* a quad: two triangles, front side down like the rect's */
        snprintf(shape, sizeof shape,
                 "{\"type\": \"quad\", \"vertices\": [[%g, 1, %g], [%g, 1, %g], [%g, 1, %g], [%g, 1, %g]],"
                 " \"material\": \"lamp\"}",
                 x0, z0, x1, z0, x1, z1, x0, z1);
    else
        snprintf(shape, sizeof shape,
                 "{\"type\": \"rect\", \"origin\": [%g, 1, %g], \"edge_u\": [%g, 0, 0], \"edge_v\": [0, 0, %g],"
                 " \"material\": \"lamp\"}",
                 x0, z0, AREA_SIDE, AREA_SIDE);
    snprintf(json, sizeof json,
             HEAD(1, 1, 1, 1)
             " \"camera\": {\"position\": [0, 0, 0], \"target\": [0, 0, -1], \"fov\": 0.001},"
             " \"media\": {\"fog\": {\"sigma_a\": [%g, %g, %g], \"sigma_s\": [%g, %g, %g], \"g\": %g}},"
             " \"medium\": \"fog\","
             " \"materials\": {\"black\": {\"type\": \"lambert\", \"albedo\": [0, 0, 0]},"
             "   \"lamp\": {\"type\": \"emitter\", \"emission\": [%g, %g, %g]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 1000], \"radius\": 1, \"material\": \"black\"}, %s]}",
             SIG_A[0], SIG_A[1], SIG_A[2], SIG_S[0], SIG_S[1], SIG_S[2], G, LE, LE, LE, shape);
    test_scene(json, s);
}

/* L = int_0^inf e^(-st t) ss int_A p(cos) Le e^(-st r) cos_l / r^2 dA dt
 * along x(t) = -t z: the light's square by the midpoint rule, t for each
 * of its points by the angle seen from it (t = delta + h tan(theta),
 * dt / r^2 = dtheta / h); cos_l = 1 / r (the light is one unit above). */
static double area_single_scattering(int c)
{
    const int NA = 48, NT = 4000;
    double st = SIG_S[c] + SIG_A[c], sum = 0, da = (AREA_SIDE / NA) * (AREA_SIDE / NA);
    for (int i = 0; i < NA; i++)
        for (int j = 0; j < NA; j++) {
            double lx = -AREA_SIDE / 2 + (i + 0.5) * AREA_SIDE / NA;
            double lz = AREA_Z - AREA_SIDE / 2 + (j + 0.5) * AREA_SIDE / NA;
            double delta = -lz, h = sqrt(lx * lx + 1.0), a = atan2(-delta, h), b = M_PI / 2, inner = 0;
            for (int k = 0; k < NT; k++) {
                double th = a + (b - a) * (k + 0.5) / NT, t = delta + h * tan(th), r = h / cos(th);
                double mu = -(lz + t) / r;
                double p = (1 - G * G) / (4 * M_PI * pow(1 + G * G - 2 * G * mu, 1.5));
                inner += exp(-st * (t + r)) * SIG_S[c] * p * LE * (1.0 / r) / h * (b - a) / NT;
            }
            sum += inner * da;
        }
    return sum;
}

static void area_light_in_fog(void)
{
    enum { N = 1 << 16 };
    double ref[3];
    for (int c = 0; c < 3; c++)
        ref[c] = area_single_scattering(c);
    const pt_strategy sts[] = {PT_MIS, PT_MIS_DISTANCE, PT_LIGHT_ONLY, PT_BSDF_ONLY};
    const char *names[] = {"equiangular+MIS", "distance sampling+MIS", "light sampling (equiangular, distance)",
                           "phase sampling alone"};
    for (int tri = 0; tri < 2; tri++) {
        fr_scene s;
        area_fog_scene(&s, tri);
        double mean[4][3], var[4][3];
        for (int k = 0; k < 4; k++) {
            estimate(&s, sts[k], N, mean[k], var[k]);
            for (int c = 0; c < 3; c++) {
                double se = sqrt(var[k][c] / N);
                /* Phase sampling alone rarely hits the small light: its
                 * estimate is held to its standard error, itself bounded. */
                double tol = k == 3 ? 0.15 : 0.03;
                CHECK(fabs(mean[k][c] - ref[c]) < 4 * se + 2e-3 * ref[c] && fabs(mean[k][c] - ref[c]) < tol * ref[c] &&
                          se < tol * ref[c],
                      "%s light, channel %d: %s %g +- %g, analytic %g", tri ? "quad" : "rect", c, names[k],
                      mean[k][c], se, ref[c]);
            }
        }
        double ratio = (var[1][0] + var[1][1] + var[1][2]) / (var[0][0] + var[0][1] + var[0][2]);
        printf("# area light (%s) in fog, single scattering, %d spp: variance distance+MIS / equiangular+MIS = %.1f\n",
               tri ? "quad" : "rect", N, ratio);
        CHECK(ratio > 2.0, "%s light: equiangular sampling reduces the variance only %.2fx", tri ? "quad" : "rect",
              ratio);
        scn_free(&s);
    }
}

/* ---- white furnaces -------------------------------------------------------- */

/* Inside a sphere whose wall emits Le and absorbs everything else, a medium
 * that only scatters (albedo 1) changes nothing: every pixel sees Le. */
static void furnace(const char *what, const char *media_json, const char *extra_shapes, float le)
{
    char json[2048];
    snprintf(json, sizeof json,
             HEAD(4, 4, 1, 4096)
             " \"camera\": {\"position\": [0.2, -0.3, 2.2], \"target\": [0, 0, 0], \"fov\": 70},"
             " %s,"
             " \"materials\": {\"wall\": {\"type\": \"emitter\", \"emission\": [%g, %g, %g], \"two_sided\": true},"
             "   \"ball\": {\"type\": \"interface\", \"medium\": \"cloud\"}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 3, \"material\": \"wall\"}%s]}",
             media_json, le, le, le, extra_shapes);
    fr_scene s;
    test_scene(json, &s);
    double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
    uint32_t n = 0;
    for (uint32_t y = 0; y < 4; y++)
        for (uint32_t x = 0; x < 4; x++)
            for (uint32_t i = 0; i < 4096; i++, n++) {
                vec3 v = pt_sample(&s, PT_MIS, x, y, i);
                double c[3] = {v.x, v.y, v.z};
                for (int k = 0; k < 3; k++)
                    sum[k] += c[k], sq[k] += c[k] * c[k];
            }
    /* Within 4 standard errors, and never more than 1 % off. */
    for (int c = 0; c < 3; c++) {
        double mean = sum[c] / n, se = sqrt((sq[c] / n - mean * mean) / n);
        CHECK(fabs(mean - le) < fmin(4 * se, 0.01 * le), "%s: channel %d mean %g +- %g, expected %g", what, c, mean,
              se, le);
    }
    scn_free(&s);
}

/* Slabs of a render with media are the same bytes as the same rows of the
 * whole image (the path's random numbers depend only on pixel and sample). */
static void split_invariance(void)
{
    fr_scene s;
    test_scene(HEAD(12, 9, 4, 6)
               " \"camera\": {\"position\": [0, 0.5, 3], \"target\": [0, 0, 0], \"fov\": 50},"
               " \"media\": {\"fog\": {\"sigma_a\": 0.05, \"sigma_s\": [0.3, 0.4, 0.5], \"g\": 0.4},"
               "   \"ball\": {\"sigma_s\": 3}}, \"medium\": \"fog\","
               " \"materials\": {\"w\": {\"type\": \"lambert\", \"albedo\": [0.6, 0.6, 0.6]},"
               "   \"b\": {\"type\": \"interface\", \"medium\": \"ball\"}, \"lamp\": {\"type\": \"emitter\", \"emission\": [4, 4, 4]}},"
               " \"shapes\": [{\"type\": \"plane\", \"point\": [0, -1, 0], \"normal\": [0, 1, 0], \"material\": \"w\"},"
               "   {\"type\": \"sphere\", \"center\": [0.3, 0, 0], \"radius\": 0.7, \"material\": \"b\"},"
               "   {\"type\": \"sphere\", \"center\": [-1, 1.5, 0], \"radius\": 0.3, \"material\": \"lamp\"}],"
               " \"lights\": [{\"type\": \"point\", \"position\": [1, 1.2, 0.5], \"intensity\": [3, 3, 3]}]}",
               &s);
    float whole[12 * 9 * 3], part[12 * 9 * 3];
    pt_render_rows(&s, PT_MIS, 0, 9, whole);
    const uint32_t cuts[] = {0, 2, 3, 7, 9};
    for (int k = 0; k < 4; k++)
        pt_render_rows(&s, PT_MIS, cuts[k], cuts[k + 1], part + cuts[k] * 12 * 3);
    CHECK(!memcmp(whole, part, sizeof whole), "slabs of a render with media differ from the whole image");
    double sum = 0;
    for (int i = 0; i < 12 * 9 * 3; i++)
        sum += whole[i];
    CHECK(sum > 0 && isfinite(sum), "the media split scene renders black or non-finite (%g)", sum);
    scn_free(&s);
}

int main(void)
{
    split_invariance();
    transmittance_and_phase();
    distance_sampling();
    equiangular_sampling();
    slabs();
    point_light_in_fog();
    area_light_in_fog();
    furnace("global fog, chromatic, g = 0.5",
            "\"media\": {\"cloud\": {\"sigma_s\": [0.3, 0.7, 1.5], \"g\": 0.5}}, \"medium\": \"cloud\"", "", 1.5f);
    furnace("a cloud ball (interface) with the camera outside",
            "\"media\": {\"cloud\": {\"sigma_s\": [2, 1, 4], \"g\": -0.4}}",
            ", {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1.5, \"material\": \"ball\"}", 1.0f);
    furnace("a cloud box with the camera inside",
            "\"media\": {\"cloud\": {\"sigma_s\": 1.2}}",
            ", {\"type\": \"box\", \"min\": [-2, -2, -2], \"max\": [2, 2, 2.5], \"material\": \"ball\"}", 2.0f);
    return check_done();
}
