/* json_gltf.c -- the gltf shape of JSON scenes (json_gltf.h). */
#include "compile/json_gltf.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fmath.h"
#include "compile/gltf_anim.h"
#include "compile/gltf_scene.h"
#include "compile/jsonval.h"

/* The shape's placement: scale, then rotations about x, y, z (degrees),
 * then translation; or a row-major 4x4 matrix. */
static int placement(const cJSON *o, const char *where, double m[3][4], fr_error *err)
{
    memset(m, 0, 12 * sizeof(double));
    const cJSON *mx = cJSON_GetObjectItemCaseSensitive(o, "matrix");
    if (mx) {
        if (cJSON_GetObjectItemCaseSensitive(o, "scale") || cJSON_GetObjectItemCaseSensitive(o, "rotate") ||
            cJSON_GetObjectItemCaseSensitive(o, "translate"))
            return fr_fail(err, "%s.matrix: give either matrix or scale/rotate/translate, not both", where);
        if (!cJSON_IsArray(mx) || cJSON_GetArraySize(mx) != 16)
            return fr_fail(err, "%s.matrix: expected 16 numbers (4x4, row-major)", where);
        int i = 0;
        double v[16];
        for (const cJSON *e = mx->child; e; e = e->next, i++) {
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1.0e30)
                return fr_fail(err, "%s.matrix[%d]: expected a finite number", where, i);
            v[i] = e->valuedouble;
        }
        if (v[12] != 0.0 || v[13] != 0.0 || v[14] != 0.0 || v[15] != 1.0)
            return fr_fail(err, "%s.matrix: the last row must be 0 0 0 1 (no projective transforms)", where);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++)
                m[r][c] = v[4 * r + c];
    } else {
        vec3 s = v3s(1.0f), rot, t;
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(o, "scale");
        float k;
        if (cJSON_IsNumber(sc)) {
            if (jv_number(o, "scale", where, 1, 1.0f, &k, err) < 0)
                return -1;
            s = v3s(k);
        } else if (jv_vec3(o, "scale", where, 0, v3s(1.0f), &s, err) < 0) {
            return -1;
        }
        if (jv_vec3(o, "rotate", where, 0, v3s(0.0f), &rot, err) < 0 ||
            jv_vec3(o, "translate", where, 0, v3s(0.0f), &t, err) < 0)
            return -1;
        double a[3][3] = {{s.x, 0, 0}, {0, s.y, 0}, {0, 0, s.z}};
        float ang[3] = {rot.x, rot.y, rot.z};
        for (int ax = 0; ax < 3; ax++) {
            if (ang[ax] == 0.0f)
                continue;
            float sn, cs;
            fm_sincosf(ang[ax] * (FM_PI / 180.0f), &sn, &cs);
            double r[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, n[3][3];
            int i = (ax + 1) % 3, j = (ax + 2) % 3;
            r[i][i] = cs;
            r[i][j] = -sn;
            r[j][i] = sn;
            r[j][j] = cs;
            for (int p = 0; p < 3; p++)
                for (int q = 0; q < 3; q++)
                    n[p][q] = r[p][0] * a[0][q] + r[p][1] * a[1][q] + r[p][2] * a[2][q];
            memcpy(a, n, sizeof a);
        }
        for (int r = 0; r < 3; r++) {
            for (int c = 0; c < 3; c++)
                m[r][c] = a[r][c];
        }
        m[0][3] = t.x;
        m[1][3] = t.y;
        m[2][3] = t.z;
    }
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabs(det) > 1e-30) || !isfinite(det))
        return fr_fail(err, "%s: the transform is singular (a zero scale?)", where);
    return 0;
}

/* The shape's options, everything but geometry. */
static int options(const cJSON *o, const char *where, const char *dir, const confine *scope, gltf_options *g,
                   char *path, size_t cap, fr_error *err)
{
    static const char *const fields[] = {"type", "file", "material", "scale", "rotate", "translate", "matrix",
                                         "lights", "camera", NULL};
    gltf_options_default(g);
    g->scope = scope;
    if (jv_only_fields(o, where, fields, err) < 0 || placement(o, where, g->place, err) < 0)
        return -1;
    const cJSON *f = cJSON_GetObjectItemCaseSensitive(o, "file");
    if (!cJSON_IsString(f) || !f->valuestring[0])
        return fr_fail(err, "%s.file: missing (expected a .gltf or .glb file)", where);
    const char *s = f->valuestring;
    if ((size_t)snprintf(path, cap, "%s%s%s", s[0] == '/' ? "" : dir, s[0] == '/' ? "" : "/", s) >= cap)
        return fr_fail(err, "%s.file: name too long", where);
    const cJSON *l = cJSON_GetObjectItemCaseSensitive(o, "lights");
    if (l && !cJSON_IsBool(l))
        return fr_fail(err, "%s.lights: expected true or false", where);
    g->take_lights = !l || cJSON_IsTrue(l);
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(o, "camera");
    if (c && !cJSON_IsBool(c) && !cJSON_IsString(c))
        return fr_fail(err, "%s.camera: expected true or the name of a camera of the file", where);
    g->take_camera = 0;
    g->camera = cJSON_IsString(c) ? c->valuestring : NULL;
    return 0;
}

int json_gltf_shape(fr_builder *b, const cJSON *o, const char *where, const char *dir, const confine *scope,
                   const scene_hooks *hooks, uint32_t material, int take_camera, fr_error *err)
{
    gltf_options g;
    char path[4096];
    if (options(o, where, dir, scope, &g, path, sizeof path, err) < 0)
        return -1;
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(o, "camera");
    if (c && cJSON_IsTrue(c) == 0 && !cJSON_IsString(c))
        c = NULL;                                   /* "camera": false */
    if (c && !take_camera)
        return fr_fail(err, "%s.camera: the scene has a camera of its own (give one or the other)", where);
    g.take_camera = take_camera && c;
    g.material = material;
    g.animate = hooks && hooks->timed;
    g.time = g.animate ? ganim_hooks_time(hooks, hooks->frame) : 0.0;
    gltf_result r;
    fr_error e;
    if (gltf_import(path, hooks, &g, b, &r, &e) < 0)
        return fr_fail(err, "%s: %s", where, e.msg);
    if (g.take_camera && !r.camera_found)
        return fr_fail(err, "%s.camera: %s has no perspective camera", where, path);
    if (r.triangles == 0)
        return fr_fail(err, "%s: %s has no triangles", where, path);
    return 0;
}

int json_gltf_camera(fr_builder *b, const cJSON *shapes, const char *dir, const confine *scope,
                     const scene_hooks *hooks, fr_error *err)
{
    int i = 0;
    for (const cJSON *s = cJSON_IsArray(shapes) ? shapes->child : NULL; s; s = s->next, i++) {
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(s, "type");
        const cJSON *c = cJSON_GetObjectItemCaseSensitive(s, "camera");
        if (!cJSON_IsString(t) || strcmp(t->valuestring, "gltf") != 0 || !c || cJSON_IsFalse(c))
            continue;
        char where[64], path[4096];
        snprintf(where, sizeof where, "shapes[%d]", i);
        gltf_options g;
        if (options(s, where, dir, scope, &g, path, sizeof path, err) < 0)
            return -1;
        /* The camera alone: a builder of its own takes the rest. */
        fr_builder tmp;
        gltf_result r;
        fr_error e;
        bld_init(&tmp);
        /* The same limits, counted apart: this import is looked at once more. */
        fr_budget own;
        if (b->budget) {
            own = *b->budget;
            tmp.budget = &own;
        }
        g.take_camera = 1;
        g.take_lights = 0;
        g.animate = hooks && hooks->timed;
        g.time = g.animate ? ganim_hooks_time(hooks, hooks->frame) : 0.0;
        int rc = gltf_import(path, NULL, &g, &tmp, &r, &e);
        if (rc == 0 && !r.camera_found)
            rc = fr_fail(&e, "%s has no perspective camera", path);
        if (rc == 0)
            b->camera = tmp.camera;
        bld_free(&tmp);
        if (rc < 0)
            return fr_fail(err, "%s.camera: %s", where, e.msg);
        return 0;
    }
    return fr_fail(err, "camera: missing or not an object (or a gltf shape with \"camera\": true)");
}
