/* Split invariance: the full image and its concatenation from uneven
 * slabs (2, 3 and 7 of them) are byte-identical, on a scene with every
 * material kind and both light kinds. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "pathtrace.h"
#include "scenes.h"

static const char scene[] =
    "{\"image\": {\"width\": 23, \"height\": 19, \"spp\": 3, \"max_depth\": 8, \"seed\": 5},"
    " \"camera\": {\"position\": [0, 1, -5], \"target\": [0, 0.8, 0], \"fov\": 50, \"aperture\": 0.05},"
    " \"materials\": {"
    "   \"floor\": {\"type\": \"phong\", \"diffuse\": [0.4, 0.3, 0.3], \"glossy\": [0.3, 0.3, 0.3], \"exponent\": 40},"
    "   \"mirror\": {\"type\": \"mirror\"}, \"glass\": {\"type\": \"glass\", \"ior\": 1.5},"
    "   \"mix\": {\"type\": \"mix\", \"diffuse\": [0.3, 0.1, 0.1], \"specular\": [0.2, 0.2, 0.2], \"transmit\": [0.3, 0.3, 0.3]},"
    "   \"lamp\": {\"type\": \"emitter\", \"emission\": [8, 7, 6]}},"
    " \"lights\": [{\"type\": \"point\", \"position\": [2, 3, -2], \"intensity\": [20, 20, 20]}],"
    " \"shapes\": ["
    "   {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 1, 0], \"material\": \"floor\"},"
    "   {\"type\": \"sphere\", \"center\": [-1, 0.7, 0], \"radius\": 0.7, \"material\": \"mirror\"},"
    "   {\"type\": \"sphere\", \"center\": [0.8, 0.6, -0.5], \"radius\": 0.6, \"material\": \"glass\"},"
    "   {\"type\": \"triangle\", \"vertices\": [[-2, 0, 2], [2, 0, 2], [0, 2.5, 2]], \"material\": \"mix\"},"
    "   {\"type\": \"rect\", \"origin\": [-1, 3, -1], \"edge_u\": [2, 0, 0], \"edge_v\": [0, 0, 1], \"material\": \"lamp\"}]}";

static void check_split(const fr_scene *s, const float *full, const uint32_t *cuts, int n)
{
    uint32_t w = s->settings.width, h = s->settings.height;
    float *img = malloc((size_t)w * h * 3 * sizeof *img);
    for (int i = 0; i + 1 < n; i++)
        pt_render_rows(s, PT_MIS, cuts[i], cuts[i + 1], img + (size_t)cuts[i] * w * 3);
    CHECK(memcmp(img, full, (size_t)w * h * 3 * sizeof *img) == 0, "%d slabs differ from the full image", n - 1);
    free(img);
}

int main(void)
{
    fr_scene s;
    test_scene(scene, &s);
    uint32_t w = s.settings.width, h = s.settings.height;
    float *full = malloc((size_t)w * h * 3 * sizeof *full);
    pt_render_rows(&s, PT_MIS, 0, h, full);
    /* The image is not black (the test would be empty otherwise). */
    double sum = 0;
    for (size_t i = 0; i < (size_t)w * h * 3; i++)
        sum += full[i];
    CHECK(sum > 1.0, "the test image is black");
    const uint32_t two[] = {0, 11, 19};
    const uint32_t three[] = {0, 1, 13, 19};
    const uint32_t seven[] = {0, 2, 3, 7, 8, 12, 18, 19};
    check_split(&s, full, two, 3);
    check_split(&s, full, three, 4);
    check_split(&s, full, seven, 8);
    /* A different seed gives a different image: the seed is really used. */
    fr_scene s2 = s;
    s2.settings.seed = 6;
    float *other = malloc((size_t)w * h * 3 * sizeof *other);
    pt_render_rows(&s2, PT_MIS, 0, h, other);
    CHECK(memcmp(other, full, (size_t)w * h * 3 * sizeof *other) != 0, "seed does not change the image");
    free(other);
    free(full);
    scn_free(&s);
    return check_done();
}
