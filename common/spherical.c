/* spherical.c -- uniform sampling of the solid angle of rectangles and
 * triangles (see spherical.h). */

#include "spherical.h"

#include "fmath.h"

static inline float maxf(float a, float b) { return a > b ? a : b; }

static inline float clampf(float v, float lo, float hi) { return v < lo ? lo : v > hi ? hi : v; }

/* The angle whose cosine is c (clamped to [-1, 1]). */
static inline float angle_of(float c) { return fm_acosf(clampf(c, -1.0f, 1.0f)); }

/* In the frame of the edges (x along eu, y along ev, z away from the
 * rectangle) the point is the origin and the rectangle is
 * [x0, x1] x [y0, y1] at height z0 < 0.  The planes through the point and
 * each edge have the unit normals (pointing into the pyramid's inside)
 *   n0 ~ (0, z0, -y0), n1 ~ (-z0, 0, x1), n2 ~ (0, -z0, y1), n3 ~ (z0, 0, -x0)
 * (edges y = y0, x = x1, y = y1, x = x0), and the spherical rectangle's
 * angles are g_i = acos(-n_i . n_i+1); its area is their sum less 2 pi.
 * Each dot product has a single non-zero term, written out below. */
int spherical_rect_setup(vec3 from, vec3 origin, vec3 eu, vec3 ev, spherical_rect *r)
{
    float ex = v3_len(eu), ey = v3_len(ev);
    if (!(ex > 0.0f && ey > 0.0f))
        return 0;
    vec3 x = v3_scale(eu, 1.0f / ex), y = v3_scale(ev, 1.0f / ey);
    if (!(fabsf(v3_dot(x, y)) <= 1e-5f))
        return 0;
    vec3 d = v3_sub(origin, from);
    float z0 = -fabsf(v3_dot(d, v3_cross(x, y)));
    if (!(-z0 >= SPHERICAL_MIN_HEIGHT * sqrtf(ex * ey)))
        return 0;
    float x0 = v3_dot(d, x), y0 = v3_dot(d, y), x1 = x0 + ex, y1 = y0 + ey;
    float zz = z0 * z0;
    float lx0 = sqrtf(zz + x0 * x0), lx1 = sqrtf(zz + x1 * x1);
    float ly0 = sqrtf(zz + y0 * y0), ly1 = sqrtf(zz + y1 * y1);
    float g0 = angle_of(y0 * x1 / (ly0 * lx1));
    float g1 = angle_of(-x1 * y1 / (lx1 * ly1));
    float g2 = angle_of(x0 * y1 / (ly1 * lx0));
    float g3 = angle_of(-x0 * y0 / (lx0 * ly0));
    r->x0 = x0;
    r->x1 = x1;
    r->y0 = y0;
    r->y1 = y1;
    r->z0 = z0;
    r->ex = ex;
    r->ey = ey;
    r->b0 = -y0 / ly0;
    r->b1 = y1 / ly1;
    r->k = 2.0f * FM_PI - g2 - g3;
    r->solid = g0 + g1 - r->k;
    return r->solid >= SPHERICAL_MIN_SOLID_ANGLE && r->solid < 2.0f * FM_PI;
}

/* The slice of the spherical rectangle left of the plane through the point
 * and the line x = xu has area au - k, where au is the sum of its two
 * angles at that plane; solving for the plane with au = u1 S + k gives its
 * normal's x over z as fu below, and xu from it (1 - b0^2 is
 * z0^2 / (z0^2 + y0^2), without the cancellation).  Along the line, the
 * sine of the elevation h = y / sqrt(xu^2 + z0^2 + y^2) is uniform in
 * solid angle between its ends. */
void spherical_rect_sample(const spherical_rect *r, float u1, float u2, float *s, float *t)
{
    float au = u1 * r->solid + r->k, sn, cs;
    fm_sincosf(au, &sn, &cs);
    float fu = (cs * r->b0 - r->b1) / sn;
    float zz = r->z0 * r->z0;
    float omb0 = zz / (zz + r->y0 * r->y0);
    float den = sqrtf(maxf(0.0f, fu * fu - omb0));
    float xu = (fu > 0.0f ? -r->z0 : r->z0) / den;
    xu = xu > r->x0 ? (xu < r->x1 ? xu : r->x1) : r->x0; /* a NaN (0/0) goes to x0 */
    float dd = sqrtf(xu * xu + zz);
    float h0 = r->y0 / sqrtf(dd * dd + r->y0 * r->y0), h1 = r->y1 / sqrtf(dd * dd + r->y1 * r->y1);
    float hv = h0 + u2 * (h1 - h0), omh = (1.0f - hv) * (1.0f + hv);
    float yv = omh > 1e-12f ? hv * dd / sqrtf(omh) : r->y1;
    yv = clampf(yv, r->y0, r->y1);
    *s = clampf((xu - r->x0) / r->ex, 0.0f, 1.0f);
    *t = clampf((yv - r->y0) / r->ey, 0.0f, 1.0f);
}

/* Double-precision vectors for the triangle: Arvo's construction
 * subtracts nearly equal quantities for slivers and small triangles, which
 * single precision cannot (IEEE 754 rounds + - * / and sqrt in double as
 * exactly as in float: the same bits on every host). */
typedef struct { double x, y, z; } dvec;

static inline dvec dv(vec3 a) { return (dvec){a.x, a.y, a.z}; }
static inline dvec dv_sub(dvec a, dvec b) { return (dvec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline dvec dv_add(dvec a, dvec b) { return (dvec){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline dvec dv_scale(dvec a, double k) { return (dvec){a.x * k, a.y * k, a.z * k}; }
static inline double dv_dot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline dvec dv_cross(dvec a, dvec b)
{
    return (dvec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline double dv_len(dvec a) { return sqrt(dv_dot(a, a)); }

/* The solid angle from Van Oosterom and Strackee's formula,
 * tan(omega / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a) for unit a, b, c,
 * which unlike the angles' sum less pi keeps its precision for small
 * triangles; the sine and cosine of the angle at a from the planes through
 * a and b and through a and c (no inverse trigonometry). */
int spherical_tri_setup(vec3 from, vec3 p0, vec3 p1, vec3 p2, spherical_tri *t)
{
    vec3 ng = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
    vec3 fa = v3_sub(p0, from), fb = v3_sub(p1, from), fc = v3_sub(p2, from);
    float an = v3_len(ng);     /* twice the area */
    float h = v3_dot(fa, ng) / an;
    if (!(fabsf(h) >= SPHERICAL_MIN_HEIGHT * sqrtf(0.5f * an)))
        return 0;
    dvec pa = dv(fa), pb = dv(fb), pc = dv(fc);
    dvec a = dv_scale(pa, 1.0 / dv_len(pa)), b = dv_scale(pb, 1.0 / dv_len(pb)), c = dv_scale(pc, 1.0 / dv_len(pc));
    double triple = fabs(dv_dot(a, dv_cross(b, c)));
    float solid = 2.0f * fm_atan2f((float)triple, (float)(1.0 + dv_dot(a, b) + dv_dot(b, c) + dv_dot(c, a)));
    if (!(solid >= SPHERICAL_MIN_SOLID_ANGLE && solid < 2.0f * FM_PI))
        return 0;
    dvec nab = dv_cross(a, b), nac = dv_cross(a, c);
    double lab = dv_len(nab), lac = dv_len(nac);
    dvec cp = dv_sub(c, dv_scale(a, dv_dot(c, a)));
    double lcp = dv_len(cp);
    if (!(lab > 0.0 && lac > 0.0 && lcp > 0.0))
        return 0;
    double ca = dv_dot(nab, nac) / (lab * lac);
    ca = ca < -1.0 ? -1.0 : ca > 1.0 ? 1.0 : ca;
    t->cos_alpha = ca;
    t->sin_alpha = sqrt((1.0 - ca) * (1.0 + ca));
    dvec ab = dv_sub(a, b);
    t->omc_ab = 0.5 * dv_dot(ab, ab);
    t->c_perp[0] = cp.x / lcp;
    t->c_perp[1] = cp.y / lcp;
    t->c_perp[2] = cp.z / lcp;
    const dvec *v[3] = {&a, &b, &c};
    /* Oriented so that a direction inside has positive dot products with
     * each: the barycentrics up to their sum (spherical_tri_sample). */
    double sg = h < 0.0f ? -1.0 : 1.0;
    dvec e[3] = {dv_scale(dv_cross(pb, pc), sg), dv_scale(dv_cross(pc, pa), sg), dv_scale(dv_cross(pa, pb), sg)};
    for (int i = 0; i < 3; i++) {
        t->v[i][0] = v[i]->x;
        t->v[i][1] = v[i]->y;
        t->v[i][2] = v[i]->z;
        t->e[i][0] = e[i].x;
        t->e[i][1] = e[i].y;
        t->e[i][2] = e[i].z;
    }
    t->solid = solid;
    return 1;
}

/* Arvo's construction: the sub-triangle a, b, c' with c' on the arc from
 * a to c has area A = u1 omega where cos |a c'| = q below; the direction is
 * then uniform in solid angle on the arc from b to c', with
 * 1 - cos = u2 (1 - b.c'), and 1 - b.c' = |b - c'|^2 / 2 without
 * cancellation.  Arvo's s = sin(A - alpha), t = cos(A - alpha) are
 * expanded by the angle-difference formulas, so that his u = t - cos alpha
 * and v = s + sin alpha cos|ab| come out without cancellation from
 * sin A and 1 - cos A = 2 sin^2(A/2).  The barycentrics of the point the
 * direction reaches are its dot products with the edges' cross products,
 * over their sum. */
void spherical_tri_sample(const spherical_tri *t, float u1, float u2, float *b1, float *b2)
{
    float sh, chf;
    fm_sincosf(0.5f * (u1 * t->solid), &sh, &chf);
    double sA = 2.0 * (double)sh * (double)chf, omcA = 2.0 * (double)sh * (double)sh, cA = 1.0 - omcA;
    double ca = t->cos_alpha, sa = t->sin_alpha;
    double s = sA * ca - cA * sa, c = cA * ca + sA * sa;
    double u = sA * sa - ca * omcA, v = sA * ca + sa * (omcA - t->omc_ab);
    double q = ((v * c - u * s) * ca - v) / ((v * s + u * c) * sa);
    q = q > -1.0 ? (q < 1.0 ? q : 1.0) : -1.0;   /* a NaN goes to -1 */
    dvec a = {t->v[0][0], t->v[0][1], t->v[0][2]}, b = {t->v[1][0], t->v[1][1], t->v[1][2]};
    dvec cperp = {t->c_perp[0], t->c_perp[1], t->c_perp[2]};
    dvec ch = dv_add(dv_scale(a, q), dv_scale(cperp, sqrt((1.0 - q) * (1.0 + q))));
    dvec bc = dv_sub(ch, b);
    double omz = (double)u2 * 0.5 * dv_dot(bc, bc);
    dvec w = dv_sub(ch, dv_scale(b, dv_dot(ch, b)));
    double lw = dv_len(w);
    dvec dir = b;
    if (lw > 0.0)
        dir = dv_add(dv_scale(b, 1.0 - omz), dv_scale(w, sqrt(omz < 2.0 ? omz * (2.0 - omz) : 0.0) / lw));
    double wt[3], sum = 0.0;
    for (int i = 0; i < 3; i++) {
        wt[i] = dv_dot(dir, (dvec){t->e[i][0], t->e[i][1], t->e[i][2]});
        wt[i] = wt[i] > 0.0 ? wt[i] : 0.0;
        sum += wt[i];
    }
    if (!(sum > 0.0)) {
        *b1 = *b2 = 0.0f;
        return;
    }
    *b1 = (float)(wt[1] / sum);
    *b2 = (float)(wt[2] / sum);
}
