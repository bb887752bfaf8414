/* gentex.c -- writes the example scenes' textures (nothing can be
 * downloaded, so they are made here) as binary PPM/PGM files:
 *
 *   bin/gen/gentex DIR
 *
 * and the PNG files in scenes/textures are these converted by OpenImageIO's
 * oiiotool (`oiiotool DIR/bricks.ppm -o scenes/textures/bricks.png`, ...).
 *
 *   bricks.ppm         256x256 running-bond brick wall (sRGB colour)
 *   bricks-height.pgm  its height map: bricks up, mortar down, worn edges
 *   planet.ppm         512x256 longitude/latitude map of a made-up planet
 *   tiles-normal.ppm   256x256 tangent-space normal map of bevelled tiles
 *   dimples-height.pgm 256x256 height map of hammered metal
 *
 * Every pattern comes from the sampler's integer hash (smp_hash), so the
 * files are the same on every run. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "sampler.h"

static double hash01(int a, int b, int c)
{
    return smp_hash((uint32_t)a * 73856093u ^
                    smp_hash((uint32_t)b * 19349663u ^ smp_hash((uint32_t)c * 83492791u))) /
           4294967296.0;
}

static double smooth(double t) { return t * t * (3 - 2 * t); }

/* Value noise in 3D, in [0, 1]. */
static double noise3(double x, double y, double z)
{
    int ix = (int)floor(x), iy = (int)floor(y), iz = (int)floor(z);
    double fx = smooth(x - ix), fy = smooth(y - iy), fz = smooth(z - iz), v = 0;
    for (int k = 0; k < 8; k++) {
        int dx = k & 1, dy = k >> 1 & 1, dz = k >> 2;
        double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
        v += w * hash01(ix + dx, iy + dy, iz + dz);
    }
    return v;
}

static double fbm(double x, double y, double z, int octaves)
{
    double v = 0, amp = 0.5, norm = 0;
    for (int i = 0; i < octaves; i++) {
        v += amp * noise3(x, y, z);
        norm += amp;
        x *= 2.03, y *= 2.03, z *= 2.03, amp *= 0.5;
    }
    return v / norm;
}

static unsigned char byte(double v) { return (unsigned char)(v <= 0 ? 0 : v >= 1 ? 255 : v * 255 + 0.5); }

static int write_image(const char *dir, const char *name, int w, int h, int channels, const double *px)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        return -1;
    }
    fprintf(f, "P%d\n%d %d\n255\n", channels == 3 ? 6 : 5, w, h);
    for (int i = 0; i < w * h * channels; i++)
        fputc(byte(px[i]), f);
    if (fclose(f) != 0) {
        perror(path);
        return -1;
    }
    return 0;
}

/* Brick layout at texel (x, y) of a 256 texture: 8 courses of 4 bricks,
 * every other course shifted by half a brick.  Returns the distance in
 * texels to the nearest mortar line (0 inside the mortar) and the brick's
 * row and column. */
static double brick(int x, int y, int *row, int *col)
{
    const double bw = 64, bh = 32, mortar = 2.5;
    *row = (int)(y / bh);
    double sx = x + (*row % 2 ? bw / 2 : 0);
    *col = (int)(sx / bw);
    double fx = fmod(sx, bw), fy = fmod((double)y, bh);
    double d = fmin(fmin(fx, bw - fx), fmin(fy, bh - fy)) - mortar;
    return d < 0 ? 0 : d;
}

static double *bricks(int with_height)
{
    double *px = malloc(sizeof(double) * 256 * 256 * 3);
    for (int y = 0; y < 256; y++)
        for (int x = 0; x < 256; x++) {
            int row, col;
            double d = brick(x, y, &row, &col);
            double n = fbm(x / 9.0, y / 9.0, 0.5, 4), grain = fbm(x / 2.0, y / 2.0, 7.5, 2);
            double *p = px + (y * 256 + x) * 3;
            if (with_height) {
                /* Bricks stand 1 above the mortar with rounded, chipped edges. */
                double edge = fmin(d / 4.0, 1.0);
                p[0] = d > 0 ? 0.35 + 0.65 * smooth(edge) - 0.15 * n - 0.05 * grain : 0.1 * grain;
            } else if (d == 0) {
                double m = 0.55 + 0.15 * grain;
                p[0] = m, p[1] = m * 0.97, p[2] = m * 0.9;
            } else {
                double tone = 0.75 + 0.25 * hash01(row, col, 3) - 0.25 * n + 0.1 * grain;
                p[0] = 0.62 * tone, p[1] = (0.27 + 0.06 * hash01(row, col, 4)) * tone, p[2] = 0.2 * tone;
            }
        }
    return px;
}

static double *planet(void)
{
    int w = 512, h = 256;
    double *px = malloc(sizeof(double) * w * h * 3);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            /* Texel centre to a direction: u = (phi + pi) / 2pi, v = 1 - theta/pi,
             * theta from +y (row 0 is the top: v = 1, the north pole). */
            double u = (x + 0.5) / w, v = 1 - (y + 0.5) / h;
            double phi = 2 * M_PI * u - M_PI, theta = M_PI * (1 - v);
            double dx = sin(theta) * cos(phi), dy = cos(theta), dz = -sin(theta) * sin(phi);
            double e = fbm(2.2 * dx + 5, 2.2 * dy + 5, 2.2 * dz + 5, 6);
            double lat = fabs(dy), *p = px + (y * w + x) * 3;
            if (lat + 0.1 * (e - 0.5) > 0.9) {
                p[0] = p[1] = p[2] = 0.92;                      /* ice caps */
            } else if (e < 0.52) {
                double d = e / 0.52;                            /* ocean, deeper is darker */
                p[0] = 0.08 + 0.1 * d, p[1] = 0.25 + 0.2 * d, p[2] = 0.5 + 0.25 * d;
            } else {
                double hgt = (e - 0.52) / 0.48, dry = fbm(6 * dx, 6 * dy, 6 * dz, 3);
                p[0] = 0.3 + 0.4 * dry + 0.3 * hgt, p[1] = 0.5 + 0.1 * dry + 0.2 * hgt, p[2] = 0.2 + 0.15 * hgt;
            }
        }
    return px;
}

/* Tiles: height 1 on a tile's top, falling to 0 over a bevel at its
 * border; the normal map stores (0.5 + 0.5 n) of n = normalize(-dh/du,
 * -dh/dv, 1) with v growing upward (image rows grow downward). */
static double tile_height(double x, double y)
{
    const double size = 64, bevel = 9, gap = 2;
    double fx = fmod(x, size), fy = fmod(y, size);
    double d = fmin(fmin(fx, size - fx), fmin(fy, size - fy)) - gap;
    return d <= 0 ? 0 : d >= bevel ? 1 : sin(0.5 * M_PI * d / bevel);
}

static double *tiles_normal(void)
{
    double *px = malloc(sizeof(double) * 256 * 256 * 3);
    const double k = 6.0;   /* bevel steepness, texels of height per unit */
    for (int y = 0; y < 256; y++)
        for (int x = 0; x < 256; x++) {
            double cx = x + 0.5, cy = y + 0.5;
            double dhdu = (tile_height(cx + 0.5, cy) - tile_height(cx - 0.5, cy)) * k;
            double dhdv = -(tile_height(cx, cy + 0.5) - tile_height(cx, cy - 0.5)) * k;
            double nx = -dhdu, ny = -dhdv, nz = 1, len = sqrt(nx * nx + ny * ny + nz * nz);
            double *p = px + (y * 256 + x) * 3;
            p[0] = 0.5 + 0.5 * nx / len, p[1] = 0.5 + 0.5 * ny / len, p[2] = 0.5 + 0.5 * nz / len;
        }
    return px;
}

/* Hammered metal: the lowest of overlapping spherical dents around
 * jittered points of a 12x12 grid (wrapping, so the map tiles). */
static double *dimples(void)
{
    double *px = malloc(sizeof(double) * 256 * 256);
    const int cells = 12;
    const double cell = 256.0 / cells;
    for (int y = 0; y < 256; y++)
        for (int x = 0; x < 256; x++) {
            double h = 1;
            int gx = (int)(x / cell), gy = (int)(y / cell);
            for (int j = -1; j <= 1; j++)
                for (int i = -1; i <= 1; i++) {
                    int cxi = gx + i, cyi = gy + j;
                    int wx = (cxi % cells + cells) % cells, wy = (cyi % cells + cells) % cells;
                    double px0 = (cxi + 0.2 + 0.6 * hash01(wx, wy, 1)) * cell;
                    double py0 = (cyi + 0.2 + 0.6 * hash01(wx, wy, 2)) * cell;
                    double r = cell * (0.7 + 0.4 * hash01(wx, wy, 3));
                    double d2 = ((x + 0.5 - px0) * (x + 0.5 - px0) + (y + 0.5 - py0) * (y + 0.5 - py0)) / (r * r);
                    if (d2 < 1)
                        h = fmin(h, 1 - 0.8 * (1 - d2));
                }
            px[y * 256 + x] = h;
        }
    return px;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: gentex DIR\n");
        return 2;
    }
    double *b = bricks(0), *bh = bricks(1), *pl = planet(), *tn = tiles_normal(), *dm = dimples();
    /* The height map was laid out 3 values per texel; keep the first. */
    for (int i = 0; i < 256 * 256; i++)
        bh[i] = bh[i * 3];
    int rc = write_image(argv[1], "bricks.ppm", 256, 256, 3, b) | write_image(argv[1], "bricks-height.pgm", 256, 256, 1, bh) |
             write_image(argv[1], "planet.ppm", 512, 256, 3, pl) | write_image(argv[1], "tiles-normal.ppm", 256, 256, 3, tn) |
             write_image(argv[1], "dimples-height.pgm", 256, 256, 1, dm);
    free(b), free(bh), free(pl), free(tn), free(dm);
    return rc ? 1 : 0;
}
