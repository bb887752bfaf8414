/* gensky.c -- writes a procedural sky for environment lighting as a Radiance
 * HDR file (RGBE, run-length encoded scanlines), in Franja's
 * equirectangular layout (scenes/README.md, "environment"): nothing can be
 * downloaded, so the example skies are made here.
 *
 *   bin/gen/gensky [--width W] [--sun-elevation DEG] [--sun-azimuth DEG]
 *                    [--sun-angle DEG] [--sun-irradiance E] [--sky S] -o sky.hdr
 *
 * The image is W x W/2 (default 1024).  The sky above the horizon fades
 * from a deep blue zenith to a pale horizon, with a warm glow around the
 * sun; below the horizon lies a dull brown ground.  The sun is a disk of
 * angular diameter --sun-angle (default 1 degree) at --sun-elevation above
 * the horizon (default 35) and --sun-azimuth degrees from +x toward +z
 * (default 60; the map's column u = 1/2 + azimuth / 360), whose radiance
 * gives a surface facing it the irradiance --sun-irradiance (default 10);
 * --sky scales the sky and ground (default 1: about 1 at the horizon).
 * Texels are averaged over 4 x 4 points (16 x 16 near the sun's rim), so
 * the disk's edge is antialiased and its total light exact to 1 %.  Same
 * output on every run; the file appears atomically (temporary name, then
 * rename). */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct {
    int width;
    double elev, azim, angle, irradiance, sky;
    const char *out;
} options;

typedef struct { double x, y, z; } dvec;

static double dot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* The direction of map point (u, v), v = 1 at the top (Franja's mapping). */
static dvec dir_of(double u, double v)
{
    double th = M_PI * (1 - v), ph = 2 * M_PI * (u - 0.5);
    dvec d = {sin(th) * cos(ph), cos(th), sin(th) * sin(ph)};
    return d;
}

/* Radiance of sky and ground (no sun disk) toward direction d. */
static void sky(const options *o, dvec d, dvec sun, double rgb[3])
{
    static const double zenith[3] = {0.16, 0.33, 0.85}, horizon[3] = {0.85, 0.92, 1.05};
    static const double ground[3] = {0.20, 0.16, 0.12}, glow[3] = {1.0, 0.85, 0.62};
    double y = d.y;
    double t = pow(1 - fmax(0, y), 3);
    double g = acos(fmax(-1, fmin(1, dot(d, sun))));
    double halo = 2.5 * exp(-g / 0.06) + 0.45 * exp(-g / 0.5);
    /* A soft step of half a degree at the horizon. */
    double above = 1 / (1 + exp(-y / 0.004));
    for (int c = 0; c < 3; c++) {
        double s = zenith[c] * (1 - t) + horizon[c] * t + halo * glow[c];
        rgb[c] = o->sky * (above * s + (1 - above) * ground[c] * (0.6 + 0.4 * exp(y / 0.2)));
    }
}

/* Write one scanline of RGBE pixels run-length encoded (the "new" Radiance
 * scheme: each of the four byte planes as runs and literals). */
static int put_line(FILE *f, const unsigned char *rgbe, int w)
{
    unsigned char head[4] = {2, 2, (unsigned char)(w >> 8), (unsigned char)(w & 255)};
    if (fwrite(head, 1, 4, f) != 4)
        return -1;
    unsigned char *plane = malloc((size_t)w);
    if (!plane)
        return -1;
    int rc = 0;
    for (int c = 0; c < 4 && rc == 0; c++) {
        for (int i = 0; i < w; i++)
            plane[i] = rgbe[4 * i + c];
        int i = 0;
        while (i < w && rc == 0) {
            /* A run of at least 4 equal bytes starting at i? */
            int run = 1;
            while (i + run < w && run < 127 && plane[i + run] == plane[i])
                run++;
            if (run >= 4) {
                unsigned char r[2] = {(unsigned char)(128 + run), plane[i]};
                rc = fwrite(r, 1, 2, f) == 2 ? 0 : -1;
                i += run;
                continue;
            }
            /* Literals up to the next run of 4 (at most 128). */
            int n = 0;
            while (i + n < w && n < 128) {
                if (i + n + 3 < w && plane[i + n] == plane[i + n + 1] && plane[i + n] == plane[i + n + 2] &&
                    plane[i + n] == plane[i + n + 3])
                    break;
                n++;
            }
            unsigned char cnt = (unsigned char)n;
            rc = (fwrite(&cnt, 1, 1, f) == 1 && fwrite(plane + i, 1, (size_t)n, f) == (size_t)n) ? 0 : -1;
            i += n;
        }
    }
    free(plane);
    return rc;
}

static void to_rgbe(const double rgb[3], unsigned char *p)
{
    double v = fmax(rgb[0], fmax(rgb[1], rgb[2]));
    if (v < 1e-32) {
        p[0] = p[1] = p[2] = p[3] = 0;
        return;
    }
    int e;
    double m = frexp(v, &e) * 256.0 / v;
    for (int c = 0; c < 3; c++)
        p[c] = (unsigned char)fmin(255, fmax(0, rgb[c] * m));
    p[3] = (unsigned char)(e + 128);
}

static int usage(void)
{
    fprintf(stderr, "usage: gensky [--width W] [--sun-elevation DEG] [--sun-azimuth DEG] [--sun-angle DEG]\n"
                    "              [--sun-irradiance E] [--sky S] -o FILE.hdr\n");
    return 2;
}

static int number(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !(v >= lo && v <= hi))
        return -1;
    *out = v;
    return 0;
}

int main(int argc, char **argv)
{
    options o = {1024, 35, 60, 1.0, 10.0, 1.0, NULL};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        double w;
        int bad = !v;
        if (!bad && !strcmp(a, "-o"))
            o.out = v;
        else if (!bad && !strcmp(a, "--width"))
            bad = number(v, 16, 16384, &w) < 0 || w != floor(w) || ((int)w & 1), o.width = (int)w;
        else if (!bad && !strcmp(a, "--sun-elevation"))
            bad = number(v, -90, 90, &o.elev) < 0;
        else if (!bad && !strcmp(a, "--sun-azimuth"))
            bad = number(v, -360, 360, &o.azim) < 0;
        else if (!bad && !strcmp(a, "--sun-angle"))
            bad = number(v, 0.01, 20, &o.angle) < 0;
        else if (!bad && !strcmp(a, "--sun-irradiance"))
            bad = number(v, 0, 1e6, &o.irradiance) < 0;
        else if (!bad && !strcmp(a, "--sky"))
            bad = number(v, 0, 1e6, &o.sky) < 0;
        else
            bad = 1;
        if (bad) {
            fprintf(stderr, "gensky: bad argument %s%s%s\n", a, v ? " " : "", v ? v : "");
            return usage();
        }
        i++;
    }
    if (!o.out)
        return usage();
    int w = o.width, h = w / 2;
    double el = o.elev * M_PI / 180, az = o.azim * M_PI / 180, rs = 0.5 * o.angle * M_PI / 180;
    dvec sun = {cos(el) * cos(az), sin(el), cos(el) * sin(az)};
    /* Uniform radiance over the disk giving the irradiance asked for. */
    double lsun = o.irradiance / (M_PI * sin(rs) * sin(rs));
    char tmp[4096];
    if (snprintf(tmp, sizeof tmp, "%s.XXXXXX", o.out) >= (int)sizeof tmp) {
        fprintf(stderr, "gensky: %s: path too long\n", o.out);
        return 1;
    }
    int fd = mkstemp(tmp);
    FILE *f = fd < 0 || fchmod(fd, 0644) < 0 ? NULL : fdopen(fd, "wb");
    if (!f) {
        fprintf(stderr, "gensky: %s: %s\n", tmp, strerror(errno));
        return 1;
    }
    fprintf(f, "#?RADIANCE\n# gensky: procedural sky, sun at elevation %g, azimuth %g\nFORMAT=32-bit_rle_rgbe\n\n"
               "-Y %d +X %d\n", o.elev, o.azim, h, w);
    unsigned char *line = malloc((size_t)w * 4);
    int rc = line ? 0 : -1;
    double texel = M_PI / h;
    for (int j = 0; j < h && rc == 0; j++) {
        for (int i = 0; i < w; i++) {
            dvec c = dir_of((i + 0.5) / w, 1 - (j + 0.5) / h);
            int near = acos(fmax(-1, fmin(1, dot(c, sun)))) < rs + 2 * texel;
            int n = near ? 16 : 4;
            double acc[3] = {0, 0, 0};
            for (int b = 0; b < n; b++)
                for (int a = 0; a < n; a++) {
                    dvec d = dir_of((i + (a + 0.5) / n) / w, 1 - (j + (b + 0.5) / n) / h);
                    double rgb[3];
                    sky(&o, d, sun, rgb);
                    if (dot(d, sun) >= cos(rs))
                        rgb[0] += lsun, rgb[1] += lsun * 0.97, rgb[2] += lsun * 0.9;
                    for (int k = 0; k < 3; k++)
                        acc[k] += rgb[k];
                }
            double rgb[3] = {acc[0] / (n * n), acc[1] / (n * n), acc[2] / (n * n)};
            to_rgbe(rgb, line + 4 * i);
        }
        rc = put_line(f, line, w);
    }
    free(line);
    if (fclose(f) != 0)
        rc = -1;
    if (rc < 0 || rename(tmp, o.out) < 0) {
        fprintf(stderr, "gensky: %s: %s\n", o.out, strerror(errno));
        unlink(tmp);
        return 1;
    }
    return 0;
}
