/* test_tonemap.c -- exposure, the filmic curve and the sRGB transfer curve.
 *
 * Tone mapping: exposure in stops, the filmic curve's shape, the sRGB
 * transfer curve at the end. */
#include <math.h>

#include "check.h"
#include "image.h"
#include "tonemap.h"

/* Inverse of the sRGB curve (libm is fine in a test). */
static double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }

int main(void)
{
    fr_tonemap plain = {0.0f, FR_CURVE_NONE, {0, 0}}, bright = {1.0f, FR_CURVE_NONE, {0, 0}},
               dark = {-2.5f, FR_CURVE_NONE, {0, 0}}, film = {0.0f, FR_CURVE_FILMIC, {0, 0}};
    const float xs[] = {0.0f, 0.001f, 0.05f, 0.18f, 0.4f, 0.9f};
    for (int i = 0; i < 6; i++) {
        float x = xs[i];
        CHECK(tm_display(&plain, x) == img_srgb_encode(x), "exposure 0 is the plain sRGB curve at %g", x);
        CHECK(fabs(srgb_decode(tm_display(&bright, x * 0.5f)) - x) < 2e-6 + 1e-5 * x,
              "+1 stop doubles: %g -> %g", x * 0.5, srgb_decode(tm_display(&bright, x * 0.5f)));
        CHECK(fabs(srgb_decode(tm_display(&dark, x)) - x / pow(2.0, 2.5)) < 2e-6 + 1e-5 * x, "-2.5 stops at %g", x);
    }
    CHECK(tm_display(&plain, 7.0f) == 1.0f && tm_display(&plain, -1.0f) == 0.0f, "clamping");
    /* Filmic: 0 -> 0, white point -> 1, increasing, highlights compressed
     * but not clipped below the white point, no NaN for huge values. */
    CHECK(tm_filmic(0.0f) == 0.0f && fabsf(tm_filmic(11.2f) - 1.0f) < 1e-6f, "filmic end points %g %g", tm_filmic(0.0f),
          tm_filmic(11.2f));
    float prev = 0.0f;
    int mono = 1;
    for (int i = 1; i <= 2000; i++) {
        float v = tm_filmic(i * 0.0056f);
        mono &= v > prev;
        prev = v;
    }
    CHECK(mono, "filmic is not strictly increasing below the white point");
    CHECK(tm_filmic(2.0f) < 1.0f && tm_filmic(2.0f) > tm_filmic(1.0f) + 0.05f, "filmic shoulder: %g %g", tm_filmic(1.0f),
          tm_filmic(2.0f));
    CHECK(tm_filmic(1e30f) == 1.0f && tm_display(&film, INFINITY) == 1.0f, "filmic at huge values");
    CHECK(tm_display(&film, 0.18f) > 0.2f && tm_display(&film, 0.18f) < tm_display(&plain, 0.18f),
          "filmic mid grey %g (plain %g)", tm_display(&film, 0.18f), tm_display(&plain, 0.18f));
    uint32_t c = 7;
    CHECK(tm_curve_parse("filmic", &c) == 0 && c == FR_CURVE_FILMIC && tm_curve_parse("none", &c) == 0 && c == 0 &&
              tm_curve_parse("aces", &c) < 0,
          "curve names");
    return check_done();
}
