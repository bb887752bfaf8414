/* tonemap.c -- exposure, the filmic curve and sRGB encoding of the final image
 * (see tonemap.h). */

#include "tonemap.h"

#include <string.h>

#include "fmath.h"
#include "image.h"

/* Hable's piecewise-rational fit of a film response: shoulder strength A,
 * linear strength B, linear angle C, toe strength D, toe numerator E,
 * toe denominator F; W the linear white point. */
static float hable(float x)
{
    const float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

float tm_filmic(float x)
{
    const float W = 11.2f;
    if (!(x > 0.0f))
        return 0.0f;
    float v = hable(x) / hable(W);
    return v < 1.0f ? v : 1.0f;
}

float tm_display(const fr_tonemap *t, float linear)
{
    float v = t->exposure == 0.0f ? linear : linear * fm_powf(2.0f, t->exposure);
    if (t->curve == FR_CURVE_FILMIC)
        v = tm_filmic(v);
    return img_srgb_encode(v);
}

int tm_curve_parse(const char *name, uint32_t *curve)
{
    if (!strcmp(name, "none"))
        *curve = FR_CURVE_NONE;
    else if (!strcmp(name, "filmic"))
        *curve = FR_CURVE_FILMIC;
    else
        return -1;
    return 0;
}
