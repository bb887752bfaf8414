/* test_mis.c -- light sampling, BSDF sampling and MIS estimate the same image.
 *
 * Multiple importance sampling is unbiased: light sampling only, BSDF
 * sampling only and their MIS combination estimate the same image, within
 * their noise.  The scene has a rectangle light, a small sphere light and
 * a glossy floor, so each strategy is weak somewhere. */
#include <math.h>

#include "check.h"
#include "estimate.h"
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


int main(void)
{
    fr_scene s;
    test_scene(scene, &s);
    estimate mis = est_image(&s, PT_MIS, 1024);
    estimate light = est_image(&s, PT_LIGHT_ONLY, 1024);
    estimate bsdf = est_image(&s, PT_BSDF_ONLY, 4096);
    printf("MIS %.5f +- %.5f, light only %.5f +- %.5f, BSDF only %.5f +- %.5f\n", mis.mean, mis.se, light.mean,
           light.se, bsdf.mean, bsdf.se);
    double d1 = fabs(mis.mean - light.mean), s1 = sqrt(mis.se * mis.se + light.se * light.se);
    double d2 = fabs(mis.mean - bsdf.mean), s2 = sqrt(mis.se * mis.se + bsdf.se * bsdf.se);
    CHECK(d1 < 4 * s1, "MIS and light sampling differ by %.5f (%.1f sigma)", d1, d1 / s1);
    CHECK(d2 < 4 * s2, "MIS and BSDF sampling differ by %.5f (%.1f sigma)", d2, d2 / s2);
    /* And MIS is the better estimator here: lower error than either. */
    CHECK(mis.se < light.se && mis.se < bsdf.se * 2.0,
          "MIS standard error %.5f not below light %.5f / BSDF %.5f", mis.se, light.se, bsdf.se);
    scn_free(&s);
    return check_done();
}
