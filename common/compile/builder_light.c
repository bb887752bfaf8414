/* builder_light.c -- point, spot and sun lights and the environment added to a
 * builder (see builder_light.h). */

#include "compile/builder_light.h"

#include <math.h>
#include <string.h>

#include "fmath.h"

static int finite3(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static int colour_ok(vec3 c) { return finite3(c) && v3_min(c) >= 0.0f && !v3_is_zero(c) && v3_max(c) < 1e30f; }

/* Unit `d`, or -1 with an error naming `what`. */
static int unit(vec3 d, const char *what, vec3 *out, fr_error *err)
{
    float l2 = v3_len2(d);
    if (!finite3(d) || !(l2 > 1e-30f) || !isfinite(l2))
        return fr_fail(err, "%s: expected a finite, non-zero direction", what);
    *out = v3_norm(d);
    return 0;
}

static int push(fr_builder *b, const fr_light *l, fr_error *err)
{
    return bld_push(&b->lights, l) == FR_NONE ? fr_fail(err, "out of memory for lights") : 0;
}

static fr_light light_init(uint32_t kind)
{
    fr_light l;
    memset(&l, 0, sizeof l);
    l.kind = kind;
    l.prim = FR_NONE;
    return l;
}

/* A light at `position` with `intensity`: both checked. */
static int located(fr_light *l, vec3 position, vec3 intensity, fr_error *err)
{
    if (!finite3(position))
        return fr_fail(err, "position: expected finite coordinates");
    if (!colour_ok(intensity))
        return fr_fail(err, "intensity: expected a finite, non-negative, non-zero colour");
    l->position = position;
    l->intensity = intensity;
    return 0;
}

int bld_point_light(fr_builder *b, vec3 position, vec3 intensity, fr_error *err)
{
    fr_light l = light_init(FR_LIGHT_POINT);
    return located(&l, position, intensity, err) < 0 ? -1 : push(b, &l, err);
}

int bld_spot_light(fr_builder *b, vec3 position, vec3 direction, vec3 intensity, float inner, float outer,
                   fr_error *err)
{
    fr_light l = light_init(FR_LIGHT_SPOT);
    if (located(&l, position, intensity, err) < 0 || unit(direction, "direction", &l.axis, err) < 0)
        return -1;
    if (!(outer > 0.0f && outer <= FM_PI))
        return fr_fail(err, "outer cone angle: expected (0, 180] degrees from the axis");
    if (!(inner >= 0.0f && inner < outer))
        return fr_fail(err, "inner cone angle: expected [0, outer) degrees from the axis");
    l.cone_cos = fm_cosf(outer);
    l.cone_aux = fm_cosf(inner);
    if (!(l.cone_cos < l.cone_aux))
        return fr_fail(err, "inner and outer cone angles too close to tell apart");
    return push(b, &l, err);
}

int bld_sun_light(fr_builder *b, vec3 direction, vec3 irradiance, float diameter, fr_error *err)
{
    fr_light l = light_init(FR_LIGHT_SUN);
    if (unit(direction, "direction", &l.axis, err) < 0)
        return -1;
    l.axis = v3_neg(l.axis);
    if (!colour_ok(irradiance))
        return fr_fail(err, "irradiance: expected a finite, non-negative, non-zero colour");
    if (!(diameter >= 0.0f && diameter <= FM_PI))
        return fr_fail(err, "angle: expected an angular diameter in [0, 180] degrees");
    l.intensity = irradiance;
    /* 1 - cos(a) = 2 sin^2(a/2), exact for small half-angles a. */
    float sh = fm_sinf(0.25f * diameter);
    l.cone_aux = 2.0f * sh * sh;
    l.cone_cos = 1.0f - l.cone_aux;
    return push(b, &l, err);
}

int bld_environment(fr_builder *b, vec3 color, uint32_t texture, float rotation, fr_error *err)
{
    if (b->world.env != FR_ENV_NONE)
        return fr_fail(err, "the scene already has an environment");
    if (!colour_ok(color))
        return fr_fail(err, "color: expected a finite, non-negative, non-zero colour (times strength)");
    if (!isfinite(rotation) || fabsf(rotation) > 1e6f)
        return fr_fail(err, "rotation: expected a finite angle");
    if (texture != FR_NONE) {
        if (texture >= b->textures.count)
            return fr_fail(err, "texture %u does not exist", texture);
        const fr_texture *t = (const fr_texture *)b->textures.data + texture;
        if (t->kind != FR_TEX_IMAGE)
            return fr_fail(err, "an environment map must be an image texture");
        if (t->scale.u != 1.0f || t->scale.v != 1.0f || t->offset.u != 0.0f || t->offset.v != 0.0f)
            return fr_fail(err, "an environment map takes no scale or offset (turn it with rotation)");
        if ((uint64_t)t->width * t->height > (1u << 26))
            return fr_fail(err, "an environment map of %ux%u texels is larger than 2^26 texels", t->width, t->height);
    }
    fr_light l = light_init(FR_LIGHT_ENV);
    if (push(b, &l, err) < 0)
        return -1;
    b->world.env = texture == FR_NONE ? FR_ENV_CONSTANT : FR_ENV_MAP;
    b->world.env_texture = texture;
    b->world.env_color = color;
    fm_sincosf(rotation, &b->world.rot_sin, &b->world.rot_cos);
    return 0;
}
