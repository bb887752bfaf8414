/* test_dof.c -- depth of field blurs a point into the thin lens's circle of
 * confusion.
 *
 * Depth of field: a thin lens of radius A focused at distance F (along the
 * view axis) images a point at depth z as a uniform disk whose radius on
 * the focal plane is A |z - F| / z (the circle of confusion of the
 * thin-lens formula, seen through the lens' magnification).  Tiny emissive
 * spheres stand for points; the blur radius is measured from the second
 * moment of the rendered spot (a uniform disk of radius R has
 * E[r^2] = R^2 / 2). */
#include <math.h>
#include <string.h>

#include "check.h"
#include "pathtrace.h"
#include "scenes.h"

enum { W = 96, H = 96, SPP = 4096 };
static const double FOCUS = 10.0, FOV = 30.0;

/* Pixel size on the focal plane. */
static double pixel_at_focus(void) { return 2.0 * FOCUS * tan(FOV * M_PI / 360.0) / H; }

/* Render the spot of a sphere of radius rho at (x, y, -z) seen by a camera
 * at the origin looking down -z; return its blur radius in pixels (moment
 * estimate, sphere and pixel footprint removed) and the fraction of its
 * energy farther than `outer` pixels from the centroid. */
static float img[H][W];

static double spot(const char *lens, double x, double y, double z, double rho, double outer, double *far_frac,
                   double *cx_out, double *cy_out)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d, \"spp\": 1, \"max_depth\": 0},"
             " \"camera\": {\"position\": [0, 0, 0], \"target\": [0, 0, -1], \"fov\": %g, \"focus\": %g, %s},"
             " \"materials\": {\"e\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
             " \"shapes\": [{\"type\": \"sphere\", \"center\": [%.9g, %.9g, %.9g], \"radius\": %.9g, \"material\": \"e\"}]}",
             W, H, FOV, FOCUS, lens, x, y, -z, rho);
    fr_scene s;
    test_scene(json, &s);
    /* Where the pinhole image of the centre is, and a window around it. */
    double px = W / 2.0 + x / z * FOCUS / pixel_at_focus(), py = H / 2.0 - y / z * FOCUS / pixel_at_focus();
    int half = (int)(outer + 4.0);
    memset(img, 0, sizeof img);
    double sum = 0, sx = 0, sy = 0;
    for (int j = (int)py - half; j <= (int)py + half; j++)
        for (int i = (int)px - half; i <= (int)px + half; i++) {
            if (i < 0 || j < 0 || i >= W || j >= H)
                continue;
            double acc = 0;
            for (uint32_t k = 0; k < SPP; k++)
                acc += pt_sample(&s, PT_MIS, (uint32_t)i, (uint32_t)j, k).x;
            img[j][i] = (float)(acc / SPP);
            sum += img[j][i];
            sx += img[j][i] * (i + 0.5);
            sy += img[j][i] * (j + 0.5);
        }
    double cx = sx / sum, cy = sy / sum, m2 = 0, far = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            double r2 = (i + 0.5 - cx) * (i + 0.5 - cx) + (j + 0.5 - cy) * (j + 0.5 - cy);
            m2 += img[j][i] * r2;
            if (r2 > outer * outer)
                far += img[j][i];
        }
    m2 /= sum;
    *far_frac = far / sum;
    *cx_out = cx - px;
    *cy_out = cy - py;
    scn_free(&s);
    /* The sphere's own image (radius rho/z * F on the focal plane) and the
     * one-pixel box filter add their second moments. */
    double rho_px = rho / z * FOCUS / pixel_at_focus();
    double r2 = 2.0 * (m2 - 1.0 / 6.0 - rho_px * rho_px / 2.0);
    return r2 > 0 ? sqrt(r2) : 0.0;
}

static void blur(const char *lens, double aperture, double x, double y, double z)
{
    double expect = aperture * fabs(z - FOCUS) / z / pixel_at_focus();
    double far, dx, dy;
    /* A sphere whose own image is 1.5 px in radius: enough light to
     * measure, a known second moment to remove. */
    double rho = 1.5 * pixel_at_focus() * z / FOCUS;
    double r = spot(lens, x, y, z, rho, expect * 1.05 + 2.0, &far, &dx, &dy);
    CHECK(fabs(r - expect) < 0.015 * expect + 0.05, "%s, point at depth %g: blur radius %.3f px, thin lens says %.3f px",
          lens, z, r, expect);
    CHECK(far < 0.002, "%s, point at depth %g: %.4f of the light outside the circle of confusion", lens, z, far);
    CHECK(fabs(dx) < 0.01 * expect + 0.03 && fabs(dy) < 0.01 * expect + 0.03, "%s, depth %g: spot centred (%.3f, %.3f) px off the pinhole image",
          lens, z, dx, dy);
}

/* A point on the focal plane images as sharply through the lens as through
 * a pinhole: the two spots agree pixel by pixel up to noise. */
static void sharp(const char *lens, double x, double y)
{
    static float pinhole[H][W];
    double far, dx, dy, rho = 1.5 * pixel_at_focus();
    spot("\"aperture\": 0", x, y, FOCUS, rho, 4.0, &far, &dx, &dy);
    memcpy(pinhole, img, sizeof img);
    spot(lens, x, y, FOCUS, rho, 4.0, &far, &dx, &dy);
    double diff = 0, sum = 0;
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            diff += fabs(img[j][i] - pinhole[j][i]), sum += pinhole[j][i];
    CHECK(diff / sum < 0.02, "%s: the focal-plane point at (%g, %g) differs from its pinhole image by %.4f (L1)", lens,
          x, y, diff / sum);
    CHECK(far < 1e-5, "%s: focal-plane point leaks %.5f of its light beyond 4 px", lens, far);
}

static void fstop_form(void)
{
    fr_scene s;
    test_scene("{\"image\": {\"width\": 8, \"height\": 8},"
               " \"camera\": {\"position\": [0, 0, 0], \"target\": [0, 0, -1], \"fov\": 30, \"focus\": 10,"
               "   \"fstop\": 2.8, \"focal_length\": 0.05},"
               " \"materials\": {\"e\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},"
               " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, -5], \"radius\": 1, \"material\": \"e\"}]}",
               &s);
    CHECK(fabsf(s.camera.aperture - 0.05f / (2.0f * 2.8f)) < 1e-8f, "fstop 2.8, f 50 mm: lens radius %g",
          s.camera.aperture);
    scn_free(&s);
}

int main(void)
{
    fstop_form();
    /* Lens radius 0.4 at focus 10: in front, behind and off axis. */
    const char *lens = "\"aperture\": 0.4";
    sharp(lens, 0, 0);
    sharp(lens, 1.5, -0.8);   /* focus is a plane, not a sphere around the camera */
    blur(lens, 0.4, 0, 0, 5);
    blur(lens, 0.4, 0, 0, 25);
    blur(lens, 0.4, 1.0, 0.5, 6);
    /* The f-number form: N = 1.25, f = 1 gives the same radius 0.4. */
    blur("\"fstop\": 1.25, \"focal_length\": 1", 0.4, -0.5, 0.3, 4);
    return check_done();
}
