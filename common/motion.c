/* motion.c -- the transform of a moving instance at a time across the
 * shutter (see motion.h). */

#include "motion.h"

#include <math.h>
#include <string.h>

#include "fmath.h"

void motion_at(const fr_inst_motion *m, float u, float xf[3][4], float inv[3][4])
{
    /* The rotation: slerp weights, or linear ones for a small angle; then
     * renormalised, which also removes the slerp's rounding. */
    float a = 1.0f - u, b = u;
    if (m->inv_sin > 0.0f) {
        a = fm_sinf(a * m->angle) * m->inv_sin;
        b = fm_sinf(u * m->angle) * m->inv_sin;
    }
    float q[4], n2 = 0.0f;
    for (int i = 0; i < 4; i++) {
        q[i] = a * m->q0[i] + b * m->q1[i];
        n2 += q[i] * q[i];
    }
    float k = 1.0f / sqrtf(n2);
    float x = q[0] * k, y = q[1] * k, z = q[2] * k, w = q[3] * k;
    float r[3][3] = {{1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y - w * z), 2.0f * (x * z + w * y)},
                     {2.0f * (x * y + w * z), 1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z - w * x)},
                     {2.0f * (x * z - w * y), 2.0f * (y * z + w * x), 1.0f - 2.0f * (x * x + y * y)}};
    float t[3] = {(1.0f - u) * m->t0.x + u * m->t1.x, (1.0f - u) * m->t0.y + u * m->t1.y,
                  (1.0f - u) * m->t0.z + u * m->t1.z};
    float s[3][3], mm[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            s[i][j] = (1.0f - u) * m->s0[i][j] + u * m->s1[i][j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            mm[i][j] = r[i][0] * s[0][j] + r[i][1] * s[1][j] + r[i][2] * s[2][j];
    if (xf)
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++)
                xf[i][j] = mm[i][j];
            xf[i][3] = t[i];
        }
    if (!inv)
        return;
    /* The inverse by cofactors: c[i][j] is the cofactor of mm[j][i]. */
    const float (*mt)[3] = mm;
    float c[3][3] = {{mt[1][1] * mt[2][2] - mt[1][2] * mt[2][1], mt[0][2] * mt[2][1] - mt[0][1] * mt[2][2],
                      mt[0][1] * mt[1][2] - mt[0][2] * mt[1][1]},
                     {mt[1][2] * mt[2][0] - mt[1][0] * mt[2][2], mt[0][0] * mt[2][2] - mt[0][2] * mt[2][0],
                      mt[0][2] * mt[1][0] - mt[0][0] * mt[1][2]},
                     {mt[1][0] * mt[2][1] - mt[1][1] * mt[2][0], mt[0][1] * mt[2][0] - mt[0][0] * mt[2][1],
                      mt[0][0] * mt[1][1] - mt[0][1] * mt[1][0]}};
    float det = mt[0][0] * c[0][0] + mt[0][1] * c[1][0] + mt[0][2] * c[2][0], id = 1.0f / det;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            inv[i][j] = c[i][j] * id;
        inv[i][3] = -(inv[i][0] * t[0] + inv[i][1] * t[1] + inv[i][2] * t[2]);
    }
}

/* The cache of motion_at_cached: direct-mapped by the motion's index, so a
 * scene of up to MOTION_CACHE moving instances keeps each one's pose
 * for as long as the time stays. */
#define MOTION_CACHE 16

typedef struct {
    fr_inst_motion m;   /* the motion the pose was made from */
    uint32_t ubits;     /* and the time's bits */
    int valid;
    motion_pose pose;
} motion_entry;

static _Thread_local motion_entry motion_cache[MOTION_CACHE];

const motion_pose *motion_at_cached(const fr_inst_motion *m, uint32_t slot, float u)
{
    motion_entry *e = &motion_cache[slot % MOTION_CACHE];
    uint32_t ubits;
    memcpy(&ubits, &u, sizeof ubits);
    if (!e->valid || e->ubits != ubits || memcmp(&e->m, m, sizeof *m) != 0) {
        motion_at(m, u, e->pose.xf, e->pose.inv);
        e->m = *m;
        e->ubits = ubits;
        e->valid = 1;
    }
    return &e->pose;
}
