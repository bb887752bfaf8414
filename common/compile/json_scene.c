/* json_scene.c -- the JSON scene reader: every field checked, shapes into a
 * builder (see json_scene.h). */

#include "compile/json_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsdf.h"
#include "file.h"
#include "fmath.h"
#include "passes.h"
#include "compile/freeze.h"
#include "compile/jsoncheck.h"
#include "compile/jsonval.h"
#include "proto_limits.h"
#include "compile/json_appear.h"
#include "compile/json_gltf.h"
#include "compile/json_keys.h"
#include "compile/json_motion.h"
#include "compile/json_light.h"
#include "compile/json_microfacet.h"
#include "compile/builder_group.h"
#include "compile/builder_object.h"

#define PATHLEN 160

typedef struct {
    const char *file;
    const char *dir;
    const confine *scope;      /* the folders its files may be read from */
    const scene_hooks *hooks;
    fr_builder *b;
    const cJSON *materials;    /* the "materials" object */
    struct mat_name { const char *name; uint32_t index; } *by_name; /* its names, sorted: lookups in log time */
    uint32_t n_names;
    int gltf_camera;           /* the camera comes from a gltf shape */
    fr_error *err;
    json_appear *look;          /* textures, media (json_appear.h) */
    int gltf_moving;           /* the gltf shape's camera moves across the shutter: *gltf_open is b->camera */
    fr_camera *gltf_open;
    cJSON **closes;            /* per shape: its pose at shutter close when it is a moving mesh (json_motion.h) */
    int n_closes;
    const cJSON *close;        /* the shape being read's */
} ctx;

static int nonneg3(vec3 v) { return v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

static int parse_image(ctx *c, const cJSON *o)
{
    static const char *const fields[] = {"width", "height", "spp", "max_depth", "seed", "integrator",
                                         "noise_threshold", "light_sampling", "passes", NULL};
    static const char *const integrators[] = {"path", "bdpt", "mlt", NULL};
    static const char *const light_samplings[] = {"tree", "power", NULL};
    fr_settings *s = &c->b->settings;
    int integrator, light_sampling;
    if (!cJSON_IsObject(o))
        return fr_fail(c->err, "image: missing or not an object");
    if (jv_only_fields(o, "image", fields, c->err) < 0 ||
        jv_uint(o, "width", "image", 1, 0, 1, PROTO_MAX_SIZE, &s->width, c->err) < 0 ||
        jv_uint(o, "height", "image", 1, 0, 1, PROTO_MAX_SIZE, &s->height, c->err) < 0 ||
        jv_uint(o, "spp", "image", 0, 16, 1, PROTO_MAX_SPP, &s->spp, c->err) < 0 ||
        jv_uint(o, "max_depth", "image", 0, 8, 0, PROTO_MAX_DEPTH, &s->max_depth, c->err) < 0 ||
        jv_uint(o, "seed", "image", 0, 0, 0, 0xffffffffu, &s->seed, c->err) < 0 ||
        jv_choice(o, "integrator", "image", integrators, FR_INTEGRATOR_PATH, &integrator, c->err) < 0 ||
        jv_number(o, "noise_threshold", "image", 0, 0.0f, &s->noise_threshold, c->err) < 0 ||
        jv_choice(o, "light_sampling", "image", light_samplings, 0, &light_sampling, c->err) < 0)
        return -1;
    s->integrator = (uint32_t)integrator;
    c->b->no_light_tree = light_sampling == 1;
    const cJSON *passes = cJSON_GetObjectItemCaseSensitive(o, "passes");
    if (passes) {
        fr_error e;
        if (!cJSON_IsString(passes))
            return fr_fail(c->err, "image.passes: expected a string of pass names separated by commas");
        if (pass_parse(passes->valuestring, &s->passes, &e) < 0)
            return fr_fail(c->err, "image.passes: %s", e.msg);
    }
    if (!(s->noise_threshold >= 0.0f && s->noise_threshold <= 1.0f))
        return fr_fail(c->err, "image.noise_threshold: expected a number in [0, 1] (0: off), got %g",
                       (double)s->noise_threshold);
    return 0;
}

static int parse_camera(ctx *c, const cJSON *o)
{
    static const char *const fields[] = {"position", "target", "up", "fov", "aperture", "focus", "fstop",
                                         "focal_length", "shutter", NULL};
    fr_camera *cam = &c->b->camera;
    float fov;
    if (!cJSON_IsObject(o))
        return fr_fail(c->err, "camera: missing or not an object");
    if (jv_only_fields(o, "camera", fields, c->err) < 0 ||
        jv_vec3(o, "position", "camera", 1, v3s(0), &cam->position, c->err) < 0 ||
        jv_vec3(o, "target", "camera", 1, v3s(0), &cam->target, c->err) < 0 ||
        jv_vec3(o, "up", "camera", 0, v3(0, 1, 0), &cam->up, c->err) < 0 ||
        jv_number(o, "fov", "camera", 1, 0, &fov, c->err) < 0 ||
        jv_number(o, "aperture", "camera", 0, 0, &cam->aperture, c->err) < 0 ||
        json_camera_lens(o, cam, c->err) < 0)
        return -1;
    if (!(fov > 0.0f && fov < 180.0f))
        return fr_fail(c->err, "camera.fov: expected degrees in (0, 180)");
    if (cam->aperture < 0.0f)
        return fr_fail(c->err, "camera.aperture: expected a lens radius >= 0");
    cam->vfov = fov * (FM_PI / 180.0f);
    fr_error e;
    if (bld_camera_finish(cam, &e) < 0)
        return fr_fail(c->err, "%s", e.msg);
    float dist = v3_len(v3_sub(cam->target, cam->position));
    if (jv_number(o, "focus", "camera", 0, dist, &cam->focus, c->err) < 0)
        return -1;
    if (!(cam->focus > 0.0f))
        return fr_fail(c->err, "camera.focus: expected a positive distance");
    return 0;
}

/* Keyed fields (json_keys.h) of the camera and the shapes posed at the
 * hooks' frame (frame 0, warned, when the scene is not a frame of an
 * animation); with a shutter (the hooks', else the camera's `shutter`, in
 * frames), a keyed camera is posed at the shutter's opening and closing
 * into *open and *close too (new trees, the caller's). */
static int pose_keys(ctx *c, cJSON *root, cJSON **open, cJSON **close)
{
    const scene_hooks *h = c->hooks;
    cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    cJSON *shapes = cJSON_GetObjectItemCaseSensitive(root, "shapes");
    int cam_keyed = json_keys_in(cam), any = cam_keyed;
    for (const cJSON *s = cJSON_IsArray(shapes) ? shapes->child : NULL; s && !any; s = s->next)
        any = json_keys_in(s);
    if (!any)
        return 0;
    int timed = h && h->timed;
    double frame = timed ? h->frame : 0.0, shutter = timed ? h->shutter : 0.0;
    if (!timed && h && h->warn)
        h->warn(h->user, "keyed values are posed at frame 0 (render the file with --frames to play them)");
    const cJSON *sh = cJSON_GetObjectItemCaseSensitive(cam, "shutter");
    if (sh && (!cJSON_IsNumber(sh) || !(sh->valuedouble >= 0.0 && sh->valuedouble <= 1.0)))
        return fr_fail(c->err, "camera.shutter: expected the fraction of a frame the shutter is open, in [0, 1]");
    if (timed && !(shutter > 0.0) && sh)
        shutter = sh->valuedouble;
    if (timed && shutter > 0.0 && cam_keyed) {
        c->b->motion.shutter = (float)(shutter / (h->fps > 0.0 ? h->fps : 24.0));
        if (!(*open = cJSON_Duplicate(cam, 1)) || !(*close = cJSON_Duplicate(cam, 1)))
            return fr_fail(c->err, "camera: out of memory");
        if (json_keys_pose(*open, "camera", frame - 0.5 * shutter, c->err) < 0 ||
            json_keys_pose(*close, "camera", frame + 0.5 * shutter, c->err) < 0)
            return -1;
    }
    if (json_keys_pose(cam, "camera", frame, c->err) < 0)
        return -1;
    int i = 0;
    if (timed && shutter > 0.0 && cJSON_IsArray(shapes)) {
        int n = cJSON_GetArraySize(shapes);
        if (!(c->closes = calloc((size_t)n + 1, sizeof *c->closes)))
            return fr_fail(c->err, "shapes: out of memory");
        c->n_closes = n;
        c->b->motion.shutter = (float)(shutter / (h->fps > 0.0 ? h->fps : 24.0));
    }
    for (cJSON *s = cJSON_IsArray(shapes) ? shapes->child : NULL; s; s = s->next, i++) {
        char where[PATHLEN];
        snprintf(where, sizeof where, "shapes[%d]", i);
        if (c->closes && json_keys_in(s)) {
            scene_hooks at = *h;
            at.shutter = shutter;
            if (json_motion_pose(s, where, &at, &c->closes[i], c->err) < 0)
                return -1;
        } else if (json_keys_pose(s, where, frame, c->err) < 0) {
            return -1;
        }
    }
    return 0;
}

/* The camera at the shutter's opening (b->camera) and closing (b->motion)
 * from the posed trees of pose_keys, when they differ. */
static int camera_motion(ctx *c, const cJSON *open, const cJSON *close)
{
    if (parse_camera(c, close) < 0)
        return -1;
    fr_camera shut = c->b->camera;
    if (parse_camera(c, open) < 0)
        return -1;
    if (memcmp(&shut, &c->b->camera, sizeof shut) != 0) {
        c->b->motion.camera_close = shut;
        c->b->motion.flags |= FR_MOTION_CAMERA;
    }
    return 0;
}

/* The top-level camera, or (without one) the camera of a gltf shape: with
 * a shutter, the file's camera at the shutter's opening, and at its
 * closing in b->motion when it moved. */
static int camera(ctx *c, const cJSON *root)
{
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    if (cam)
        return parse_camera(c, cam);
    c->gltf_camera = 1;
    const cJSON *shapes = cJSON_GetObjectItemCaseSensitive(root, "shapes");
    const scene_hooks *h = c->hooks;
    if (json_gltf_camera(c->b, shapes, c->dir, c->scope, h, c->err) < 0)
        return -1;
    if (!h || !h->timed || !(h->shutter > 0.0))
        return 0;
    scene_hooks at = *h;
    at.frame = h->frame + 0.5 * h->shutter;
    if (json_gltf_camera(c->b, shapes, c->dir, c->scope, &at, c->err) < 0)
        return -1;
    fr_camera shut = c->b->camera;
    at.frame = h->frame - 0.5 * h->shutter;
    if (json_gltf_camera(c->b, shapes, c->dir, c->scope, &at, c->err) < 0)
        return -1;
    c->b->motion.shutter = (float)(h->shutter / (h->fps > 0.0 ? h->fps : 24.0));
    if (memcmp(&shut, &c->b->camera, sizeof shut) != 0) {
        c->b->motion.camera_close = shut;
        c->b->motion.flags |= FR_MOTION_CAMERA;
        /* (the shape takes the camera again, at the frame: undone after) */
        c->gltf_moving = 1;
        *c->gltf_open = c->b->camera;
    }
    return 0;
}

#define TYPES "lambert, phong, mirror, glass, mix, conductor, principled, emitter or interface"

static int parse_material(ctx *c, const cJSON *o, const char *where, fr_material *m)
{
    static const char *const lobe_fields[] = {"type", "albedo", "diffuse", "glossy", "specular", "exponent",
                                              "reflectance", "transmit", "tint", "ior", "emission", "two_sided",
                                              "bump", "normal_map", "medium", NULL};
    enum { N_LOBE = sizeof lobe_fields / sizeof lobe_fields[0] - 1, N_MF = SCN_MICROFACET_NFIELDS };
    const char *fields[N_LOBE + N_MF + 1];
    memcpy(fields, lobe_fields, N_LOBE * sizeof *fields);
    memcpy(fields + N_LOBE, json_microfacet_fields, (N_MF + 1) * sizeof *fields);
    bld_material_init(m);
    json_appear *a = c->look;
    if (!cJSON_IsObject(o))
        return fr_fail(c->err, "%s: expected an object", where);
    if (jv_only_fields(o, where, fields, c->err) < 0)
        return -1;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "type");
    if (!cJSON_IsString(t))
        return fr_fail(c->err, "%s.type: missing (expected %s)", where, TYPES);
    const char *type = t->valuestring;
    int rc = 0;
    /* Colours may be textures (json_colour). */
    if (!strcmp(type, "lambert")) {
        rc = json_colour(a, o, "albedo", where, 1, v3s(0), &m->diffuse, &m->tex_diffuse, c->err);
    } else if (!strcmp(type, "phong")) {
        rc = json_colour(a, o, "diffuse", where, 0, v3s(0), &m->diffuse, &m->tex_diffuse, c->err) |
             json_colour(a, o, "glossy", where, 1, v3s(0), &m->glossy, &m->tex_glossy, c->err) |
             jv_number(o, "exponent", where, 1, 0, &m->exponent, c->err);
    } else if (!strcmp(type, "mirror")) {
        rc = json_colour(a, o, "reflectance", where, 0, v3s(1), &m->specular, &m->tex_specular, c->err);
    } else if (!strcmp(type, "glass")) {
        rc = json_colour(a, o, "tint", where, 0, v3s(1), &m->transmit, &m->tex_transmit, c->err) |
             jv_number(o, "ior", where, 0, 1.5f, &m->ior, c->err);
    } else if (!strcmp(type, "mix")) {
        rc = json_colour(a, o, "diffuse", where, 0, v3s(0), &m->diffuse, &m->tex_diffuse, c->err) |
             json_colour(a, o, "glossy", where, 0, v3s(0), &m->glossy, &m->tex_glossy, c->err) |
             jv_number(o, "exponent", where, 0, 0, &m->exponent, c->err) |
             json_colour(a, o, "specular", where, 0, v3s(0), &m->specular, &m->tex_specular, c->err) |
             json_colour(a, o, "transmit", where, 0, v3s(0), &m->transmit, &m->tex_transmit, c->err) |
             jv_number(o, "ior", where, 0, 1.5f, &m->ior, c->err);
    } else if (strcmp(type, "emitter") != 0 && strcmp(type, "interface") != 0 && strcmp(type, "conductor") != 0 &&
               strcmp(type, "principled") != 0) {
        return fr_fail(c->err, "%s.type: '%s' is not %s", where, type, TYPES);
    }
    if (rc < 0 || json_microfacet(a, o, where, type, m, c->err) < 0 ||
        json_colour(a, o, "emission", where, 0, v3s(0), &m->emission, &m->tex_emission, c->err) < 0 ||
        json_material_appearance(a, o, where, !strcmp(type, "interface"), m, c->err) < 0)
        return -1;
    const cJSON *ts = cJSON_GetObjectItemCaseSensitive(o, "two_sided");
    if (ts && !cJSON_IsBool(ts))
        return fr_fail(c->err, "%s.two_sided: expected true or false", where);
    m->two_sided = ts && cJSON_IsTrue(ts);
    if (!nonneg3(m->diffuse) || !nonneg3(m->glossy) || !nonneg3(m->specular) || !nonneg3(m->transmit) ||
        !nonneg3(m->emission))
        return fr_fail(c->err, "%s: colours must be >= 0", where);
    vec3 sum = v3_add(v3_add(m->diffuse, m->glossy), v3_add(m->specular, m->transmit));
    if (v3_max(sum) > 1.0f)
        return fr_fail(c->err, "%s: lobe albedos sum to %g > 1 in some channel (the material would create energy)",
                       where, (double)v3_max(sum));
    if (!(m->exponent >= 0.0f && m->exponent <= 1.0e6f))
        return fr_fail(c->err, "%s.exponent: expected a number in [0, 1e6]", where);
    if (!(m->ior >= 1.0f / 16.0f && m->ior <= 16.0f) || m->ior == 1.0f)
        return fr_fail(c->err, "%s.ior: expected an index of refraction in [1/16, 16], not 1", where);
    bsdf_material_finish(m);
    return 0;
}

static int by_name_cmp(const void *a, const void *b)
{
    return strcmp(((const struct mat_name *)a)->name, ((const struct mat_name *)b)->name);
}

static int parse_materials(ctx *c, const cJSON *o)
{
    if (!cJSON_IsObject(o))
        return fr_fail(c->err, "materials: missing or not an object (name -> material)");
    for (const cJSON *m = o->child; m; m = m->next) {
        char where[PATHLEN];
        snprintf(where, sizeof where, "materials.%s", m->string);
        fr_material mat;
        /* A light_group is set aside while the material's fields are read. */
        cJSON *g = cJSON_IsObject(m) ? cJSON_DetachItemFromObjectCaseSensitive((cJSON *)m, "light_group") : NULL;
        int rc = g && (!cJSON_IsString(g) || !g->valuestring[0])
                     ? fr_fail(c->err, "%s.light_group: expected a non-empty string", where)
                     : parse_material(c, m, where, &mat);
        uint32_t k = rc < 0 ? 0 : bld_push(&c->b->materials, &mat);
        if (rc == 0 && (k == FR_NONE || bld_material_name(c->b, k, m->string) < 0))
            rc = fr_fail(c->err, "%s: out of memory", where);
        if (rc == 0 && g)
            rc = bld_material_group(c->b, k, g->valuestring, where, c->err);
        if (g)
            cJSON_AddItemToObject((cJSON *)m, "light_group", g);
        if (rc < 0)
            return -1;
    }
    c->materials = o;
    uint32_t n = 0;
    for (const cJSON *m = o->child; m; m = m->next)
        n++;
    if ((c->by_name = malloc((n ? n : 1) * sizeof *c->by_name)) == NULL)
        return fr_fail(c->err, "materials: out of memory");
    n = 0;
    for (const cJSON *m = o->child; m; m = m->next, n++)
        c->by_name[n] = (struct mat_name){m->string, n};
    qsort(c->by_name, n, sizeof *c->by_name, by_name_cmp);
    c->n_names = n;
    return 0;
}

static int material_ref(ctx *c, const cJSON *shape, const char *where, uint32_t *out)
{
    const cJSON *n = cJSON_GetObjectItemCaseSensitive(shape, "material");
    if (!cJSON_IsString(n))
        return fr_fail(c->err, "%s.material: missing (expected a material name)", where);
    /* Names are unique (jsoncheck refuses a repeated member). */
    struct mat_name key = {n->valuestring, 0};
    const struct mat_name *m = bsearch(&key, c->by_name, c->n_names, sizeof key, by_name_cmp);
    if (m) {
        *out = m->index;
        return 0;
    }
    return fr_fail(c->err, "%s.material: no material named '%s'", where, n->valuestring);
}

static int vertices(ctx *c, const cJSON *o, const char *where, int n, vec3 *v)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, "vertices");
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n)
        return fr_fail(c->err, "%s.vertices: expected an array of %d points", where, n);
    for (int i = 0; i < n; i++) {
        char path[PATHLEN];
        snprintf(path, sizeof path, "%s.vertices[%d]", where, i);
        if (jv_vec3_value(cJSON_GetArrayItem(a, i), path, &v[i], c->err) < 0)
            return -1;
    }
    return 0;
}

/* A triangle, with texture coordinates when uv is not NULL. */
static int add_triangle(ctx *c, const char *where, vec3 a, vec3 b, vec3 d, const vec2 *uv, uint32_t mat)
{
    if (!(v3_len2(v3_cross(v3_sub(b, a), v3_sub(d, a))) > 0.0f))
        return fr_fail(c->err, "%s: zero-area triangle", where);
    vec3 p[3] = {a, b, d};
    uint32_t t = uv ? bld_triangle_uv(c->b, p, uv, mat) : bld_triangle(c->b, a, b, d, mat);
    return t == FR_NONE ? fr_fail(c->err, "%s: out of memory", where) : 0;
}

/* An axis-aligned box: six outward-facing rectangles. */
static int parse_box(fr_builder *b, const cJSON *o, const char *where, uint32_t material, fr_error *err)
{
    static const char *const fields[] = {"type", "material", "min", "max", NULL};
    vec3 lo, hi;
    if (jv_only_fields(o, where, fields, err) < 0 || jv_vec3(o, "min", where, 1, v3s(0), &lo, err) < 0 ||
        jv_vec3(o, "max", where, 1, v3s(0), &hi, err) < 0)
        return -1;
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
        return fr_fail(err, "%s.max: expected every coordinate greater than min's", where);
    vec3 dx = v3(hi.x - lo.x, 0, 0), dy = v3(0, hi.y - lo.y, 0), dz = v3(0, 0, hi.z - lo.z);
    /* Each face: origin and two edges whose cross product points out. */
    const vec3 faces[6][3] = {
        {lo, dz, dy}, {v3_add(lo, dx), dy, dz},     /* -x, +x */
        {lo, dx, dz}, {v3_add(lo, dy), dz, dx},     /* -y, +y */
        {lo, dy, dx}, {v3_add(lo, dz), dx, dy},     /* -z, +z */
    };
    for (int i = 0; i < 6; i++)
        if (bld_rect(b, faces[i][0], faces[i][1], faces[i][2], material) == FR_NONE)
            return fr_fail(err, "%s: out of memory", where);
    return 0;
}

static int parse_shape_fields(ctx *c, const cJSON *o, const char *where);

/* A shape: an object (builder_object.h) named by its optional "name" key,
 * else by where it is ("shapes[3]"), but a glTF file (its nodes are); the
 * key is set aside while the shape's own fields are read. */
static int parse_shape(ctx *c, const cJSON *o, const char *where)
{
    if (!cJSON_IsObject(o))
        return fr_fail(c->err, "%s: expected an object", where);
    cJSON *name = cJSON_DetachItemFromObjectCaseSensitive((cJSON *)o, "name");
    int rc = 0;
    if (name && (!cJSON_IsString(name) || !name->valuestring[0]))
        rc = fr_fail(c->err, "%s.name: expected a non-empty string", where);
    /* A glTF file's nodes are objects of their own (gltf_scene.c). */
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "type");
    if (rc == 0 && !(cJSON_IsString(t) && !strcmp(t->valuestring, "gltf")))
        rc = bld_object(c->b, name ? name->valuestring : where, c->err);
    if (rc == 0)
        rc = parse_shape_fields(c, o, where);
    if (name)
        cJSON_AddItemToObject((cJSON *)o, "name", name);
    return rc;
}

/* A shape's fields but its name. */
static int parse_shape_fields(ctx *c, const cJSON *o, const char *where)
{
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "type");
    if (!cJSON_IsString(t))
        return fr_fail(c->err, "%s.type: missing (expected sphere, plane, rect, quad, triangle, box, mesh or gltf)", where);
    const char *type = t->valuestring;
    /* Meshes and glTF files may take their materials from their own files. */
    uint32_t mat = FR_NONE;
    int own_materials = !strcmp(type, "mesh") || !strcmp(type, "gltf");
    if (!own_materials || cJSON_GetObjectItemCaseSensitive(o, "material"))
        if (material_ref(c, o, where, &mat) < 0)
            return -1;
    const fr_material *m = mat == FR_NONE ? NULL : (const fr_material *)c->b->materials.data + mat;
    uint32_t r = 0;
    if (!strcmp(type, "sphere")) {
        static const char *const f[] = {"type", "material", "center", "radius", NULL};
        vec3 center;
        float radius;
        if (jv_only_fields(o, where, f, c->err) < 0 || jv_vec3(o, "center", where, 1, v3s(0), &center, c->err) < 0 ||
            jv_number(o, "radius", where, 1, 0, &radius, c->err) < 0)
            return -1;
        if (!(radius > 0.0f))
            return fr_fail(c->err, "%s.radius: expected a positive number", where);
        r = bld_sphere(c->b, center, radius, mat);
    } else if (!strcmp(type, "plane")) {
        static const char *const f[] = {"type", "material", "point", "normal", NULL};
        fr_plane p;
        memset(&p, 0, sizeof p);
        if (jv_only_fields(o, where, f, c->err) < 0 || jv_vec3(o, "point", where, 1, v3s(0), &p.point, c->err) < 0 ||
            jv_vec3(o, "normal", where, 1, v3s(0), &p.normal, c->err) < 0)
            return -1;
        if (!(v3_len2(p.normal) > 0.0f))
            return fr_fail(c->err, "%s.normal: expected a non-zero vector", where);
        if (m && !v3_is_zero(m->emission))
            return fr_fail(c->err, "%s.material: an infinite plane cannot emit light", where);
        p.normal = v3_norm(p.normal);
        p.material = mat;
        r = bld_push(&c->b->planes, &p);
    } else if (!strcmp(type, "rect")) {
        static const char *const f[] = {"type", "material", "origin", "edge_u", "edge_v", NULL};
        vec3 org, eu, ev;
        if (jv_only_fields(o, where, f, c->err) < 0 || jv_vec3(o, "origin", where, 1, v3s(0), &org, c->err) < 0 ||
            jv_vec3(o, "edge_u", where, 1, v3s(0), &eu, c->err) < 0 ||
            jv_vec3(o, "edge_v", where, 1, v3s(0), &ev, c->err) < 0)
            return -1;
        if (!(v3_len2(v3_cross(eu, ev)) > 0.0f))
            return fr_fail(c->err, "%s: zero-area rectangle (edges parallel or zero)", where);
        r = bld_rect(c->b, org, eu, ev, mat);
    } else if (!strcmp(type, "quad")) {
        static const char *const f[] = {"type", "material", "vertices", NULL};
        vec3 v[4];
        if (jv_only_fields(o, where, f, c->err) < 0 || vertices(c, o, where, 4, v) < 0)
            return -1;
        /* Two triangles, even for a parallelogram: the BVH tests triangles
         * four at a time, so they trace faster than one rectangle. */
        /* UVs as on a rect: u along v0->v1, v along v0->v3. */
        const vec2 uv1[3] = {{0, 0}, {1, 0}, {1, 1}}, uv2[3] = {{0, 0}, {1, 1}, {0, 1}};
        if (add_triangle(c, where, v[0], v[1], v[2], uv1, mat) < 0 || add_triangle(c, where, v[0], v[2], v[3], uv2, mat) < 0)
            return -1;
    } else if (!strcmp(type, "triangle")) {
        static const char *const f[] = {"type", "material", "vertices", NULL};
        vec3 v[3];
        if (jv_only_fields(o, where, f, c->err) < 0 || vertices(c, o, where, 3, v) < 0 ||
            add_triangle(c, where, v[0], v[1], v[2], NULL, mat) < 0)
            return -1;
    } else if (!strcmp(type, "box")) {
        if (parse_box(c->b, o, where, mat, c->err) < 0)
            return -1;
    } else if (!strcmp(type, "mesh")) {
        if (!c->hooks || !c->hooks->mesh)
            return fr_fail(c->err, "%s: meshes need the scene compiler: run `franja compile` and render the .fbin", where);
        fr_error e;
        if (c->close)
            return json_motion_mesh(c->b, (cJSON *)o, c->close, where, c->dir, c->scope, c->hooks, mat, c->err);
        if (c->hooks->mesh(c->b, o, where, c->dir, c->scope, mat, &e) < 0)
            return fr_fail(c->err, "%s", e.msg);
    } else if (!strcmp(type, "gltf")) {
        /* Without the compiler's image decoder its textures would be lost. */
        if (!c->hooks || !c->hooks->image_mem || !c->hooks->texture)
            return fr_fail(c->err, "%s: glTF files need the scene compiler: run `franja compile` and render the .fbin",
                           where);
        if (json_gltf_shape(c->b, o, where, c->dir, c->scope, c->hooks, mat, c->gltf_camera, c->err) < 0)
            return -1;
        c->gltf_camera = 0;            /* taken by the first that asks */
    } else {
        return fr_fail(c->err, "%s.type: '%s' is not sphere, plane, rect, quad, triangle, box, mesh or gltf", where,
                       type);
    }
    return r == FR_NONE ? fr_fail(c->err, "%s: out of memory", where) : 0;
}

int json_scene_parse(const char *text, const char *file, const scene_hooks *hooks, fr_builder *b, fr_error *err)
{
    fr_error e;
    if (!text[strspn(text, " \t\r\n")])
        return fr_fail(err, "%s: empty file (expected a JSON object)", file);
    /* Strict syntax first, with line and column: cJSON would take the first
     * of two members of the same name, ignore text after the scene and
     * say little about where it stopped. */
    if (jc_check(text, strlen(text), file, err) < 0)
        return -1;
    cJSON *root = cJSON_ParseWithOpts(text, NULL, 1);
    if (!root)
        return fr_fail(err, "%s: the JSON reader failed (out of memory?)", file);
    char dir[4096];
    file_dir(file, dir, sizeof dir);
    /* Every file the scene names is read from its folder (confine.h). */
    confine scope;
    if (confine_init(&scope, file, hooks ? hooks->allow : NULL, hooks ? hooks->n_allow : 0, err) < 0) {
        cJSON_Delete(root);
        return -1;
    }
    json_appear look;
    memset(&look, 0, sizeof look);
    fr_camera gltf_open;
    ctx c = {file, dir, &scope, hooks, b, NULL, NULL, 0, 0, &e, &look, 0, &gltf_open, NULL, 0, NULL};
    static const char *const top[] = {"image", "camera", "materials", "shapes", "lights", "description",
                                      "textures", "media", "medium", "tonemap", "environment", NULL};
    int rc = -1;
    cJSON *cam_open = NULL, *cam_close = NULL;
    if (!cJSON_IsObject(root)) {
        fr_fail(&e, "(top level): expected an object");
    } else if (jv_only_fields(root, "(top level)", top, &e) == 0 && pose_keys(&c, root, &cam_open, &cam_close) == 0 &&
               parse_image(&c, cJSON_GetObjectItemCaseSensitive(root, "image")) == 0 &&
               camera(&c, root) == 0 &&
               json_appear_begin(&look, root, dir, &scope, hooks, b, &e) == 0 &&
               parse_materials(&c, cJSON_GetObjectItemCaseSensitive(root, "materials")) == 0 &&
               json_lights(&look, cJSON_GetObjectItemCaseSensitive(root, "lights"), &e) == 0 &&
               json_environment(&look, cJSON_GetObjectItemCaseSensitive(root, "environment"), &e) == 0) {
        const cJSON *shapes = cJSON_GetObjectItemCaseSensitive(root, "shapes");
        if (!cJSON_IsArray(shapes)) {
            fr_fail(&e, "shapes: missing or not an array");
        } else {
            rc = 0;
            int i = 0;
            for (const cJSON *s = shapes->child; s && rc == 0; s = s->next, i++) {
                char where[PATHLEN];
                snprintf(where, sizeof where, "shapes[%d]", i);
                c.close = c.closes ? c.closes[i] : NULL;
                rc = parse_shape(&c, s, where);
            }
            if (rc == 0 && b->prims.count == 0 && b->planes.count == 0)
                rc = fr_fail(&e, "shapes: the scene has no shapes");
            if (rc == 0 && b->lights.count == 0) {
                int emissive = 0;
                for (uint32_t k = 0; k < b->prims.count; k++) {
                    const fr_prim *p = (const fr_prim *)b->prims.data + k;
                    emissive |= !v3_is_zero(((const fr_material *)b->materials.data)[p->material].emission);
                }
                if (!emissive)
                    rc = fr_fail(&e, "lights: the scene has no light (no point, spot or sun light, no environment, no "
                                 "emissive shape)");
            }
            if (rc == 0)
                rc = json_appear_finish(&look, root, &e);
            if (rc == 0 && cam_open)
                rc = camera_motion(&c, cam_open, cam_close);
            if (c.gltf_moving)
                b->camera = gltf_open;
        }
    }
    cJSON_Delete(cam_open);
    cJSON_Delete(cam_close);
    for (int i = 0; i < c.n_closes; i++)
        cJSON_Delete(c.closes[i]);
    free(c.closes);
    json_appear_free(&look);
    free(c.by_name);
    cJSON_Delete(root);
    return rc < 0 ? fr_fail(err, "%s: %s", file, e.msg) : 0;
}

int json_scene_load(const char *path, const scene_hooks *hooks, fr_scene *out, fr_error *err)
{
    char *text;
    size_t len;
    if (file_read(path, &text, &len, err))
        return -1;
    /* A NUL byte would end the text early: say where it is. */
    if (memchr(text, 0, len) && jc_check(text, len, path, err) < 0) {
        free(text);
        return -1;
    }
    fr_builder b;
    bld_init(&b);
    b.budget = hooks ? hooks->budget : NULL;
    b.warn = hooks ? hooks->warn : NULL;
    b.warn_user = hooks ? hooks->user : NULL;
    if (budget_take(b.budget, BUDGET_READ, len, path, err) < 0) {
        free(text);
        return -1;
    }
    int rc = json_scene_parse(text, path, hooks, &b, err);
    free(text);
    if (rc == 0) {
        fr_error e;
        rc = hooks && hooks->fbin ? frz_scene_file(&b, hooks->fbin, out, &e) : frz_scene(&b, out, &e);
        if (rc < 0)
            fr_fail(err, "%s: %s", path, e.msg);
    }
    bld_free(&b);
    return rc;
}
