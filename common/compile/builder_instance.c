/* builder_instance.c -- meshes placed many times: begun, ended, placed,
 * flattened (see builder_instance.h). */

#include "compile/builder_instance.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/builder_motion.h"
#include "compile/builder_object.h"
#include "motion.h"

uint32_t bld_mesh_begin(fr_builder *b)
{
    bld_mesh m = {b->prims.count, 0, v3s(INFINITY), v3s(-INFINITY)};
    return bld_push(&b->meshes, &m);
}

int bld_mesh_end(fr_builder *b, uint32_t mesh, fr_error *err)
{
    if (mesh >= b->meshes.count || mesh + 1 != b->meshes.count)
        return fr_fail(err, "mesh %u is not the last one begun", mesh);
    bld_mesh *m = (bld_mesh *)b->meshes.data + mesh;
    const fr_prim *p = b->prims.data;
    const fr_triangle *t = b->triangles.data;
    const vec3 *pos = b->positions.data;
    m->count = b->prims.count - m->first;
    for (uint32_t i = m->first; i < b->prims.count; i++) {
        if (p[i].kind != FR_PRIM_TRIANGLE)
            return fr_fail(err, "mesh %u: primitive %u is not a triangle", mesh, i);
        for (int k = 0; k < 3; k++) {
            m->lo = v3_vmin(m->lo, pos[t[p[i].index].v[k]]);
            m->hi = v3_vmax(m->hi, pos[t[p[i].index].v[k]]);
        }
    }
    return 0;
}

int bld_instance(fr_builder *b, uint32_t mesh, const float xf[3][4], fr_error *err)
{
    if (mesh >= b->meshes.count)
        return fr_fail(err, "instance of mesh %u: no such mesh", mesh);
    double m[3][3], det;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m[i][j] = xf[i][j];
    det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
          m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabs(det) > 1e-30) || !isfinite(det) || !isfinite(xf[0][3]) || !isfinite(xf[1][3]) || !isfinite(xf[2][3]))
        return fr_fail(err, "instance of mesh %u: the transform is singular or not finite", mesh);
    fr_instance in;
    memset(&in, 0, sizeof in);
    in.mesh = mesh;
    memcpy(in.xf, xf, sizeof in.xf);
    double inv[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            inv[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
        }
    for (int i = 0; i < 3; i++) {
        double t = 0.0;
        for (int j = 0; j < 3; j++) {
            in.inv[i][j] = (float)inv[i][j];
            t -= inv[i][j] * xf[j][3];
        }
        in.inv[i][3] = (float)t;
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(in.inv[i][j]) || fabsf(in.inv[i][j]) > 1e30f || fabsf(in.xf[i][j]) > 1e30f)
                return fr_fail(err, "instance of mesh %u: the transform's inverse is out of single precision", mesh);
    uint32_t k = bld_push(&b->instances, &in);
    fr_prim p = {FR_PRIM_INSTANCE, k, 0, FR_NONE};
    if (k == FR_NONE || bld_push(&b->prims, &p) == FR_NONE)
        return fr_fail(err, "out of memory for instances");
    return 0;
}

static vec3 xf_point(const float (*m)[4], vec3 p)
{
    return v3(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
              m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
              m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]);
}

void bld_instance_bounds(const fr_builder *b, uint32_t i, vec3 *lo, vec3 *hi)
{
    const fr_instance *in = (const fr_instance *)b->instances.data + i;
    const bld_mesh *m = (const bld_mesh *)b->meshes.data + in->mesh;
    *lo = v3s(INFINITY);
    *hi = v3s(-INFINITY);
    if (in->motion)
        bld_motion_bounds((const fr_inst_motion *)b->inst_motions.data + in->motion - 1, m->lo, m->hi, lo, hi);
    else
        bld_box_placed(in->xf, m->lo, m->hi, lo, hi);
    /* The corners are rounded, and the ray test runs in object space: a
     * margin of 2^-16 of the box's size and position covers both. */
    vec3 pad = v3_scale(v3_add(v3_sub(*hi, *lo), v3_add(v3_vmax(v3_neg(*lo), *lo), v3_vmax(v3_neg(*hi), *hi))),
                        1.0f / 65536.0f);
    *lo = v3_sub(*lo, pad);
    *hi = v3_add(*hi, pad);
}

void bld_bounds(const fr_builder *b, vec3 *lo, vec3 *hi)
{
    *lo = v3s(INFINITY);
    *hi = v3s(-INFINITY);
    const fr_prim *p = b->prims.data;
    const bld_mesh *m = b->meshes.data;
    const fr_triangle *t = b->triangles.data;
    const vec3 *pos = b->positions.data;
    for (uint32_t i = 0, k = 0; i < b->prims.count; i++) {
        while (k < b->meshes.count && i >= m[k].first + m[k].count)
            k++;
        if (k < b->meshes.count && i >= m[k].first)
            continue;
        vec3 l, h;
        if (p[i].kind == FR_PRIM_INSTANCE) {
            bld_instance_bounds(b, p[i].index, &l, &h);
        } else if (p[i].kind == FR_PRIM_TRIANGLE) {
            l = v3_vmin(v3_vmin(pos[t[p[i].index].v[0]], pos[t[p[i].index].v[1]]), pos[t[p[i].index].v[2]]);
            h = v3_vmax(v3_vmax(pos[t[p[i].index].v[0]], pos[t[p[i].index].v[1]]), pos[t[p[i].index].v[2]]);
        } else {
            continue;
        }
        *lo = v3_vmin(*lo, l);
        *hi = v3_vmax(*hi, h);
    }
}

/* Copies of mesh m's triangles placed by xf, appended to `out` (prims). */
static int place_copy(fr_builder *b, const bld_mesh *m, const fr_prim *src, const fr_instance *in, fr_array *out,
                      fr_error *err)
{
    const float (*xf)[4] = in->xf;
    float det = xf[0][0] * (xf[1][1] * xf[2][2] - xf[1][2] * xf[2][1]) -
                xf[0][1] * (xf[1][0] * xf[2][2] - xf[1][2] * xf[2][0]) +
                xf[0][2] * (xf[1][0] * xf[2][1] - xf[1][1] * xf[2][0]);
    for (uint32_t i = 0; i < m->count; i++) {
        const fr_prim *p = &src[m->first + i];
        fr_triangle t = ((const fr_triangle *)b->triangles.data)[p->index], nt;
        nt.flags = t.flags;
        for (int k = 0; k < 3; k++) {
            uint32_t v = t.v[k], at = b->positions.count;
            vec3 q = xf_point(xf, ((const vec3 *)b->positions.data)[v]);
            if (bld_push(&b->positions, &q) == FR_NONE)
                return fr_fail(err, "out of memory flattening instances");
            if (t.flags & FR_TRI_NORMALS) {
                vec3 n = ((const vec3 *)b->normals.data)[v];
                const float (*iv)[4] = in->inv;
                n = v3(iv[0][0] * n.x + iv[1][0] * n.y + iv[2][0] * n.z, iv[0][1] * n.x + iv[1][1] * n.y + iv[2][1] * n.z,
                       iv[0][2] * n.x + iv[1][2] * n.y + iv[2][2] * n.z);
                float l2 = v3_len2(n);
                n = l2 > 0.0f && isfinite(l2) ? v3_scale(n, 1.0f / sqrtf(l2)) : v3s(0.0f);
                if (bld_pad(&b->normals, at) < 0 || bld_push(&b->normals, &n) == FR_NONE)
                    return fr_fail(err, "out of memory flattening instances");
            }
            if (t.flags & FR_TRI_UVS) {
                vec2 uv = ((const vec2 *)b->uvs.data)[v];
                if (bld_pad(&b->uvs, at) < 0 || bld_push(&b->uvs, &uv) == FR_NONE)
                    return fr_fail(err, "out of memory flattening instances");
            }
            nt.v[k] = at;
        }
        if (det < 0.0f) {
            uint32_t x = nt.v[1];
            nt.v[1] = nt.v[2];
            nt.v[2] = x;
        }
        const vec3 *pos = b->positions.data;
        if (!(v3_len2(v3_cross(v3_sub(pos[nt.v[1]], pos[nt.v[0]]), v3_sub(pos[nt.v[2]], pos[nt.v[0]]))) > 0.0f))
            continue;
        uint32_t ti = bld_push(&b->triangles, &nt);
        fr_prim np = {FR_PRIM_TRIANGLE, ti, p->material, FR_NONE};
        if (ti == FR_NONE || bld_push(out, &np) == FR_NONE)
            return fr_fail(err, "out of memory flattening instances");
    }
    return 0;
}

int bld_flatten(fr_builder *b, int all, fr_error *err)
{
    uint32_t nm = b->meshes.count, ni = b->instances.count;
    if (nm == 0)
        return 0;
    const fr_material *mats = b->materials.data;
    bld_mesh *meshes = b->meshes.data;
    fr_instance *inst = b->instances.data;
    /* flat[k]: mesh k's instances become copies (or vanish, for an empty
     * mesh); used[k]: an instance keeps it. */
    unsigned char *flat = calloc(nm, 1), *used = calloc(nm, 1);
    uint32_t *owner = malloc((size_t)(b->prims.count ? b->prims.count : 1) * sizeof *owner);
    uint32_t *inst_to = malloc((size_t)(ni ? ni : 1) * sizeof *inst_to);
    fr_array out = {NULL, 0, 0, sizeof(fr_prim)};
    int rc = 0;
    if (!flat || !used || !owner || !inst_to) {
        rc = fr_fail(err, "out of memory flattening instances");
        goto done;
    }
    if ((rc = bld_object_instances(b, err)) < 0)
        goto done;
    const fr_prim *prims = b->prims.data;
    for (uint32_t i = 0; i < b->prims.count; i++)
        owner[i] = FR_NONE;
    for (uint32_t k = 0; k < nm; k++) {
        flat[k] = all || meshes[k].count == 0;
        for (uint32_t i = meshes[k].first; i < meshes[k].first + meshes[k].count; i++) {
            owner[i] = k;
            if (!v3_is_zero(mats[prims[i].material].emission))
                flat[k] = 1;
        }
    }
    uint32_t kept = 0;
    /* A moving instance flattened (an emitter) is placed where it is at
     * the middle of the shutter, with a warning. */
    uint32_t still = 0;
    for (uint32_t i = 0; i < ni; i++)
        if (flat[inst[i].mesh] && inst[i].motion) {
            motion_at((const fr_inst_motion *)b->inst_motions.data + inst[i].motion - 1, 0.5f, inst[i].xf,
                      inst[i].inv);
            inst[i].motion = 0;
            still++;
        }
    /* With no instance left moving, no sample needs a time. */
    int moving = 0;
    for (uint32_t i = 0; i < ni; i++)
        moving |= inst[i].motion != 0;
    if (!moving) {
        b->inst_motions.count = 0;
        b->motion.flags &= ~(uint32_t)FR_MOTION_INSTANCES;
    }
    if (still && b->warn) {
        char msg[200];
        snprintf(msg, sizeof msg, "%u moving instance%s of an emissive mesh: moving lights are not motion blurred; "
                 "placed where they are at the middle of the shutter, sharp", still, still == 1 ? "" : "s");
        b->warn(b->warn_user, msg);
    }
    for (uint32_t i = 0; i < ni; i++) {
        inst_to[i] = flat[inst[i].mesh] ? FR_NONE : kept++;
        if (inst_to[i] != FR_NONE)
            used[inst[i].mesh] = 1;
    }
    /* The prims again: instances kept (renumbered) or replaced by copies
     * where they stood, meshes' prims kept where the mesh is. */
    uint32_t *mesh_to = malloc((size_t)nm * sizeof *mesh_to), nkeep = 0;
    if (!mesh_to) {
        rc = fr_fail(err, "out of memory flattening instances");
        goto done;
    }
    for (uint32_t k = 0; k < nm; k++)
        mesh_to[k] = used[k] ? nkeep++ : FR_NONE;
    uint32_t n = b->prims.count;
    for (uint32_t i = 0; i < n && rc == 0; i++) {
        fr_prim p = ((const fr_prim *)b->prims.data)[i];
        if (owner[i] != FR_NONE) {
            bld_mesh *m = &meshes[owner[i]];
            if (!used[owner[i]])
                continue;
            if (used[owner[i]] == 1) {
                m->first = out.count;   /* its prims stay together, in order */
                used[owner[i]] = 2;
            }
        } else if (p.kind == FR_PRIM_INSTANCE) {
            uint32_t k = p.index;
            if (inst_to[k] == FR_NONE) {
                uint32_t *io = b->inst_objects.data;
                rc = io ? bld_object_continue(b, io[k], err) : 0;
                if (rc == 0)
                    rc = place_copy(b, &meshes[inst[k].mesh], b->prims.data, &inst[k], &out, err);
                continue;
            }
            p.index = inst_to[k];
        }
        if (bld_push(&out, &p) == FR_NONE)
            rc = fr_fail(err, "out of memory flattening instances");
    }
    if (rc == 0) {
        for (uint32_t i = 0; i < ni; i++)
            if (inst_to[i] != FR_NONE) {
                fr_instance x = inst[i];
                x.mesh = mesh_to[x.mesh];
                inst[inst_to[i]] = x;
                if (b->inst_objects.count)
                    ((uint32_t *)b->inst_objects.data)[inst_to[i]] = ((uint32_t *)b->inst_objects.data)[i];
            }
        b->instances.count = kept;
        if (b->inst_objects.count)
            b->inst_objects.count = kept;
        for (uint32_t k = 0; k < nm; k++)
            if (mesh_to[k] != FR_NONE)
                meshes[mesh_to[k]] = meshes[k];
        b->meshes.count = nkeep;
        free(b->prims.data);
        b->prims = out;
        out.data = NULL;
    }
    free(mesh_to);
done:
    free(out.data);
    free(flat);
    free(used);
    free(owner);
    free(inst_to);
    return rc;
}
