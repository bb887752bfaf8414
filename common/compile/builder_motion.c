/* builder_motion.c -- instances moving across the shutter: their motion
 * split into translation, rotation and stretch, and bounded (see
 * builder_motion.h). */

#include "compile/builder_motion.h"

#include <math.h>
#include <string.h>

#include "fmath.h"
#include "motion.h"

/* The polar decomposition m = r s of a 3x3 matrix (r a rotation, s the
 * rest), by Newton's iteration r <- (r + r^-T) / 2 from m (Higham 1986),
 * in double; for a mirroring m (det < 0) r is the rotation of -m, and
 * s (= r^T m) the mirror.
 * Returns 0, or -1 when m is singular. */
static int polar(const double m[3][3], double r[3][3], double s[3][3])
{
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabs(det) > 1e-30) || !isfinite(det))
        return -1;
    double sign = det < 0.0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[i][j] = sign * m[i][j];
    for (int it = 0; it < 100; it++) {
        double c[3][3], d = 0.0, change = 0.0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
                c[i][j] = r[i1][j1] * r[i2][j2] - r[i1][j2] * r[i2][j1]; /* cofactor: r^-T = c / det */
            }
        for (int j = 0; j < 3; j++)
            d += r[0][j] * c[0][j];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double v = 0.5 * (r[i][j] + c[i][j] / d);
                change += fabs(v - r[i][j]);
                r[i][j] = v;
            }
        if (change < 1e-15)
            break;
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            s[i][j] = r[0][i] * m[0][j] + r[1][i] * m[1][j] + r[2][i] * m[2][j]; /* r^T m */
    return 0;
}

/* The unit quaternion (x, y, z, w) of rotation matrix r. */
static void quaternion(const double r[3][3], double q[4])
{
    double tr = r[0][0] + r[1][1] + r[2][2];
    if (tr > 0.0) {
        double k = 2.0 * sqrt(tr + 1.0);
        q[3] = 0.25 * k;
        q[0] = (r[2][1] - r[1][2]) / k;
        q[1] = (r[0][2] - r[2][0]) / k;
        q[2] = (r[1][0] - r[0][1]) / k;
    } else {
        int i = r[1][1] > r[0][0] ? 1 : 0;
        if (r[2][2] > r[i][i])
            i = 2;
        int j = (i + 1) % 3, k3 = (i + 2) % 3;
        double k = 2.0 * sqrt(1.0 + r[i][i] - r[j][j] - r[k3][k3]);
        q[i] = 0.25 * k;
        q[3] = (r[k3][j] - r[j][k3]) / k;
        q[j] = (r[j][i] + r[i][j]) / k;
        q[k3] = (r[k3][i] + r[i][k3]) / k;
    }
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; i++)
        q[i] /= n;
}

/* Transform xf split into m's translation t, rotation q and stretch s. */
static int split(const float xf[3][4], vec3 *t, float q[4], float s[3][3])
{
    double m[3][3], r[3][3], st[3][3], qd[4];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m[i][j] = xf[i][j];
    if (polar(m, r, st) < 0)
        return -1;
    quaternion(r, qd);
    for (int i = 0; i < 4; i++)
        q[i] = (float)qd[i];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            s[i][j] = (float)st[i][j];
    *t = v3(xf[0][3], xf[1][3], xf[2][3]);
    return 0;
}

static double det3(const float (*m)[3])
{
    return (double)m[0][0] * ((double)m[1][1] * m[2][2] - (double)m[1][2] * m[2][1]) -
           (double)m[0][1] * ((double)m[1][0] * m[2][2] - (double)m[1][2] * m[2][0]) +
           (double)m[0][2] * ((double)m[1][0] * m[2][1] - (double)m[1][1] * m[2][0]);
}

int bld_instance_motion(fr_builder *b, uint32_t inst, const float close[3][4], fr_error *err)
{
    if (inst >= b->instances.count)
        return fr_fail(err, "motion of instance %u: no such instance", inst);
    fr_instance *in = (fr_instance *)b->instances.data + inst;
    if (!memcmp(in->xf, close, sizeof in->xf))
        return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(close[i][j]) || fabsf(close[i][j]) > 1e30f)
                return fr_fail(err, "the transform at shutter close is not finite");
    fr_inst_motion m;
    memset(&m, 0, sizeof m);
    if (split((const float(*)[4])in->xf, &m.t0, m.q0, m.s0) < 0 || split(close, &m.t1, m.q1, m.s1) < 0)
        return fr_fail(err, "the transform at shutter open or close is singular");
    double dot = 0.0;
    for (int i = 0; i < 4; i++)
        dot += (double)m.q0[i] * m.q1[i];
    if (dot < 0.0) {
        for (int i = 0; i < 4; i++)
            m.q1[i] = -m.q1[i];
    }
    /* The angle between the rotations, 2 atan2(|q1 - q0|, |q1 + q0|):
     * accurate at small angles, where acos of the dot product is not, and
     * the project's own atan2 and sine, the same bits on every machine. */
    float dm = 0.0f, dp = 0.0f;
    for (int i = 0; i < 4; i++) {
        dm += (m.q1[i] - m.q0[i]) * (m.q1[i] - m.q0[i]);
        dp += (m.q1[i] + m.q0[i]) * (m.q1[i] + m.q0[i]);
    }
    m.angle = 2.0f * fm_atan2f(sqrtf(dm), sqrtf(dp));
    m.inv_sin = m.angle >= MOTION_SLERP_MIN ? 1.0f / fm_sinf(m.angle) : 0.0f;
    /* The blended stretch must stay invertible: its determinant keeps the
     * sign it has at both ends, at every sampled time. */
    double d0 = det3((const float(*)[3])m.s0);
    for (int k = 0; k <= 64; k++) {
        float u = (float)k / 64.0f, s[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                s[i][j] = (1.0f - u) * m.s0[i][j] + u * m.s1[i][j];
        double d = det3((const float(*)[3])s);
        if (!(d * d0 > 0.0) || !(fabs(d) > 1e-12 * fabs(d0)))
            return fr_fail(err, "the motion across the shutter passes through a flat transform (a scale through 0, "
                           "or a mirror turning into its image)");
    }
    uint32_t k = bld_push(&b->inst_motions, &m);
    if (k == FR_NONE)
        return fr_fail(err, "out of memory for moving instances");
    in = (fr_instance *)b->instances.data + inst;
    in->motion = k + 1;
    b->motion.flags |= FR_MOTION_INSTANCES;
    return 0;
}

static double frobenius(const float (*s)[3])
{
    double f = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            f += (double)s[i][j] * s[i][j];
    return sqrt(f);
}

void bld_box_placed(const float xf[3][4], vec3 blo, vec3 bhi, vec3 *lo, vec3 *hi)
{
    for (int c = 0; c < 8; c++) {
        vec3 p = v3(c & 1 ? bhi.x : blo.x, c & 2 ? bhi.y : blo.y, c & 4 ? bhi.z : blo.z);
        vec3 q = v3(xf[0][0] * p.x + xf[0][1] * p.y + xf[0][2] * p.z + xf[0][3],
                    xf[1][0] * p.x + xf[1][1] * p.y + xf[1][2] * p.z + xf[1][3],
                    xf[2][0] * p.x + xf[2][1] * p.y + xf[2][2] * p.z + xf[2][3]);
        *lo = v3_vmin(*lo, q);
        *hi = v3_vmax(*hi, q);
    }
}

void bld_motion_bounds(const fr_inst_motion *m, vec3 blo, vec3 bhi, vec3 *lo, vec3 *hi)
{
    for (int k = 0; k <= BLD_MOTION_SAMPLES; k++) {
        float xf[3][4];
        motion_at(m, (float)k / BLD_MOTION_SAMPLES, xf, NULL);
        bld_box_placed((const float(*)[4])xf, blo, bhi, lo, hi);
    }
    float ds[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            ds[i][j] = m->s1[i][j] - m->s0[i][j];
    vec3 far = v3_vmax(v3_vmax(v3_neg(blo), blo), v3_vmax(v3_neg(bhi), bhi));
    double r = sqrt((double)far.x * far.x + (double)far.y * far.y + (double)far.z * far.z);
    double sn = fmax(frobenius((const float(*)[3])m->s0), frobenius((const float(*)[3])m->s1));
    vec3 dt = v3_sub(m->t1, m->t0);
    /* 2.01 angle: the rotation turns at 2 angle per unit time (slerp), a
     * little faster in places when blended linearly (nlerp, angles below
     * MOTION_SLERP_MIN). */
    double speed = sqrt((double)dt.x * dt.x + (double)dt.y * dt.y + (double)dt.z * dt.z) +
                   (2.01 * m->angle * sn + frobenius((const float(*)[3])ds)) * r;
    float pad = (float)(speed / (2.0 * BLD_MOTION_SAMPLES) * (1.0 + 1e-6));
    *lo = v3_sub(*lo, v3s(pad));
    *hi = v3_add(*hi, v3s(pad));
}
