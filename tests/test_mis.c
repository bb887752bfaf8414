/* Multiple importance sampling is unbiased: light sampling only, BSDF
 * sampling only and their MIS combination estimate the same image, within
 * their noise.  The scene has a rectangle light, a small sphere light and
 * a glossy floor, so each strategy is weak somewhere. */
#include <math.h>

#include "check.h"
#include "pathtrace.h"
#include "scenes.h"

static const char scene[] =
    "{\"image\": {\"width\": 16, \"height\": 12, \"spp\": 1, \"max_depth\": 3},"
    " \"camera\": {\"position\": [0, 1.2, -4], \"target\": [0, 0.6, 3], \"fov\": 30},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.3, 0.3, 0.3], \"glossy\": [0.5, 0.5, 0.5], \"exponent\": 30},"
    "   \"wall\": {\"type\": \"lambert\", \"albedo\": [0.6, 0.5, 0.4]},"
    "   \"panel\": {\"type\": \"emitter\", \"emission\": [4, 4, 4]},"
    "   \"bulb\": {\"type\": \"emitter\", \"emission\": [60, 50, 40]}},"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"rect\", \"origin\": [-3, 0, 3], \"edge_u\": [6, 0, 0], \"edge_v\": [0, 4, 0], \"material\": \"wall\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"panel\"},"
    "   {\"type\": \"sphere\", \"center\": [1.2, 2.6, -2], \"radius\": 0.15, \"material\": \"bulb\"}]}";

typedef struct { double mean, stderr_; } estimate;

/* Mean of the image (green channel) and its standard error: the sum of
 * the variances of the pixel means, each from its samples' spread (an
 * overestimate with stratified samples, so the test is conservative). */
static estimate run(const fr_scene *s, pt_strategy strategy, uint32_t spp)
{
    double sum = 0, var = 0;
    uint32_t npix = s->settings.width * s->settings.height;
    for (uint32_t y = 0; y < s->settings.height; y++)
        for (uint32_t x = 0; x < s->settings.width; x++) {
            double px = 0, px2 = 0;
            for (uint32_t i = 0; i < spp; i++) {
                double v = pt_sample(s, strategy, x, y, i).y;
                px += v;
                px2 += v * v;
            }
            double m = px / spp;
            sum += m;
            var += (px2 / spp - m * m) / spp;
        }
    estimate e = {sum / npix, sqrt(var) / npix};
    return e;
}

int main(void)
{
    fr_scene s;
    test_scene(scene, &s);
    estimate mis = run(&s, PT_MIS, 1024);
    estimate light = run(&s, PT_LIGHT_ONLY, 1024);
    estimate bsdf = run(&s, PT_BSDF_ONLY, 4096);
    printf("MIS %.5f +- %.5f, light only %.5f +- %.5f, BSDF only %.5f +- %.5f\n", mis.mean, mis.stderr_, light.mean,
           light.stderr_, bsdf.mean, bsdf.stderr_);
    double d1 = fabs(mis.mean - light.mean), s1 = sqrt(mis.stderr_ * mis.stderr_ + light.stderr_ * light.stderr_);
    double d2 = fabs(mis.mean - bsdf.mean), s2 = sqrt(mis.stderr_ * mis.stderr_ + bsdf.stderr_ * bsdf.stderr_);
    CHECK(d1 < 4 * s1, "MIS and light sampling differ by %.5f (%.1f sigma)", d1, d1 / s1);
    CHECK(d2 < 4 * s2, "MIS and BSDF sampling differ by %.5f (%.1f sigma)", d2, d2 / s2);
    /* And MIS is the better estimator here: lower error than either. */
    CHECK(mis.stderr_ < light.stderr_ && mis.stderr_ < bsdf.stderr_ * 2.0,
          "MIS standard error %.5f not below light %.5f / BSDF %.5f", mis.stderr_, light.stderr_, bsdf.stderr_);
    scn_free(&s);
    return check_done();
}
