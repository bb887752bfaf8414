/* camera.c -- the camera as a sensor: lens points, raster positions and
 * importance (see camera.h). */

#include "camera.h"

#include "fmath.h"

vec3 cam_lens(const fr_camera *c, float lx, float ly)
{
    if (!(c->aperture > 0.0f))
        return v3s(0.0f);
    /* Concentric mapping of the square onto the disk (Shirley and Chiu). */
    float a = 2.0f * lx - 1.0f, b = 2.0f * ly - 1.0f, rad, phi;
    if (a == 0.0f && b == 0.0f) {
        rad = 0.0f; phi = 0.0f;
    } else if (fabsf(a) > fabsf(b)) {
        rad = a; phi = 0.25f * FM_PI * (b / a);
    } else {
        rad = b; phi = 0.5f * FM_PI - 0.25f * FM_PI * (a / b);
    }
    float sn, cs;
    fm_sincosf(phi, &sn, &cs);
    rad *= c->aperture;
    return v3_add(v3_scale(c->right, rad * cs), v3_scale(c->upv, rad * sn));
}

static vec3 lerp3(vec3 a, vec3 b, float u)
{
    return v3_add(v3_scale(a, 1.0f - u), v3_scale(b, u));
}

void cam_at(const fr_scene *s, float u, fr_camera *out)
{
    *out = s->camera;
    if (!(s->motion.flags & FR_MOTION_CAMERA) || u == 0.0f)
        return;
    const fr_camera *a = &s->camera, *b = &s->motion.camera_close;
    out->position = lerp3(a->position, b->position, u);
    vec3 f = lerp3(a->forward, b->forward, u), up = lerp3(a->upv, b->upv, u);
    vec3 r = v3_cross(f, up);
    if (v3_len2(f) > 1e-12f && v3_len2(r) > 1e-12f) {
        /* (a half turn within the shutter keeps the shutter-open axes) */
        f = v3_norm(f);
        r = v3_norm(v3_cross(f, up));
        out->forward = f;
        out->right = r;
        out->upv = v3_cross(r, f);
    }
    out->tan_half = (1.0f - u) * a->tan_half + u * b->tan_half;
    out->aperture = (1.0f - u) * a->aperture + u * b->aperture;
    out->focus = (1.0f - u) * a->focus + u * b->focus;
}

float cam_lens_area(const fr_camera *c)
{
    return c->aperture > 0.0f ? FM_PI * c->aperture * c->aperture : 1.0f;
}

float cam_pixel_spread(const fr_scene *s)
{
    float share = 1.0f / sqrtf((float)s->settings.spp);
    return 2.0f * s->camera.tan_half / (float)s->settings.height * (share > 0.125f ? share : 0.125f);
}

float cam_footprint(float width, vec3 ng, vec3 d)
{
    float c = fabsf(v3_dot(ng, d));
    return c > 0.0f ? width / sqrtf(c) : 0.0f;
}

/* cam_raster through camera c. */
static int raster(const fr_scene *s, const fr_camera *c, vec3 o, vec3 w, float *rx, float *ry)
{
    float cos_t = v3_dot(w, c->forward);
    if (!(cos_t > 0.0f))
        return 0;
    /* The point of the focal plane the ray reaches, seen from the pinhole
     * as a direction with unit component along the axis (for a pinhole,
     * the ray's own direction so scaled). */
    vec3 d;
    if (c->aperture > 0.0f) {
        vec3 q = v3_madd(o, w, c->focus / cos_t);
        d = v3_scale(v3_sub(q, c->position), 1.0f / c->focus);
    } else {
        d = v3_scale(w, 1.0f / cos_t);
    }
    float w_px = (float)s->settings.width, h_px = (float)s->settings.height;
    float sx = v3_dot(d, c->right) / c->tan_half, sy = v3_dot(d, c->upv) / c->tan_half;
    float x = 0.5f * (sx * h_px + w_px), y = 0.5f * (h_px - sy * h_px);
    if (!(x >= 0.0f && x < w_px && y >= 0.0f && y < h_px))
        return 0;
    *rx = x;
    *ry = y;
    return 1;
}

int cam_raster(const fr_scene *s, vec3 o, vec3 w, float *rx, float *ry)
{
    return raster(s, &s->camera, o, w, rx, ry);
}

float cam_importance(const fr_scene *s, const fr_camera *c, vec3 o, vec3 w, float *pdf_dir, float *rx, float *ry)
{
    float x, y;
    *pdf_dir = 0.0f;
    if (!raster(s, c, o, w, &x, &y))
        return 0.0f;
    if (rx && ry) {
        *rx = x;
        *ry = y;
    }
    float cos_t = v3_dot(w, c->forward), cos2 = cos_t * cos_t;
    float area = 4.0f * c->tan_half * c->tan_half * (float)s->settings.width / (float)s->settings.height;
    *pdf_dir = 1.0f / (area * cos2 * cos_t);
    return 1.0f / (area * cam_lens_area(c) * cos2 * cos2);
}
