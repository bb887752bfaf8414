/* imgstat.c -- statistics of a PFM image, for tests that look at pictures.
 *
 *   imgstat IMAGE.pfm [--rect X0 Y0 X1 Y1] [--diff OTHER.pfm | --ratio OTHER.pfm] [--rows | --cols]
 *
 * Prints one line "size=WxH mean=M sd=S min=A max=B r=R g=G b=B" over the
 * pixels [X0, X1) x [Y0, Y1) (default: all; y = 0 is the top row), where a
 * pixel's value is the average of its three channels: M their mean, S their
 * standard deviation, A and B the extremes; R, G, B are the channel means.
 * With --diff, the same over |IMAGE - OTHER| (same size), and "rel=" the
 * mean absolute difference over OTHER's mean.  With --ratio, the same over
 * IMAGE / OTHER, pixel by pixel (channel averages; pixels where OTHER is 0
 * are left out).  --rows (--cols) then prints "row Y MEAN" ("col X MEAN")
 * for every row (column) of the rectangle of IMAGE.
 * Exits 2 on a bad argument or an unreadable image. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfmread.h"

static int number(const char *s, int *out)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (*s == '\0' || *end != '\0' || v < 0 || v > 65536)
        return -1;
    *out = (int)v;
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = NULL, *other = NULL;
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1, rows = 0, cols = 0, ratio = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--rect") && i + 4 < argc) {
            if (number(argv[i + 1], &x0) || number(argv[i + 2], &y0) || number(argv[i + 3], &x1) ||
                number(argv[i + 4], &y1)) {
                fprintf(stderr, "imgstat: --rect needs four pixel coordinates\n");
                return 2;
            }
            i += 4;
        } else if ((!strcmp(argv[i], "--diff") || !strcmp(argv[i], "--ratio")) && i + 1 < argc && !other) {
            ratio = !strcmp(argv[i], "--ratio");
            other = argv[++i];
        } else if (!strcmp(argv[i], "--rows")) {
            rows = 1;
        } else if (!strcmp(argv[i], "--cols")) {
            cols = 1;
        } else if (argv[i][0] != '-' && !path) {
            path = argv[i];
        } else {
            fprintf(stderr, "usage: imgstat IMAGE.pfm [--rect X0 Y0 X1 Y1] [--diff OTHER.pfm | --ratio OTHER.pfm] [--rows | --cols]\n");
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "usage: imgstat IMAGE.pfm [--rect X0 Y0 X1 Y1] [--diff OTHER.pfm | --ratio OTHER.pfm] [--rows | --cols]\n");
        return 2;
    }
    image a, b = {0, 0, NULL};
    if (read_pfm("imgstat", path, &a) < 0)
        return 2;
    if (other) {
        if (read_pfm("imgstat", other, &b) < 0)
            return 2;
        if (b.w != a.w || b.h != a.h) {
            fprintf(stderr, "imgstat: %s is %dx%d, %s is %dx%d\n", path, a.w, a.h, other, b.w, b.h);
            return 2;
        }
    }
    if (x1 < 0) x1 = a.w;
    if (y1 < 0) y1 = a.h;
    if (x0 >= x1 || y0 >= y1 || x1 > a.w || y1 > a.h) {
        fprintf(stderr, "imgstat: rectangle %d %d %d %d is not inside %dx%d\n", x0, y0, x1, y1, a.w, a.h);
        return 2;
    }
    double sum = 0, sum2 = 0, ch[3] = {0, 0, 0}, lo = INFINITY, hi = -INFINITY, ref = 0, n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const float *p = a.px + ((size_t)y * a.w + x) * 3;
            double v[3];
            if (ratio) {
                const float *q = b.px + ((size_t)y * a.w + x) * 3;
                double den = ((double)q[0] + q[1] + q[2]) / 3;
                if (!(den > 0))
                    continue;
                v[0] = v[1] = v[2] = (((double)p[0] + p[1] + p[2]) / 3) / den;
            } else {
                for (int c = 0; c < 3; c++) {
                    v[c] = p[c];
                    if (b.px) {
                        double q = b.px[((size_t)y * a.w + x) * 3 + c];
                        ref += q;
                        v[c] = fabs(v[c] - q);
                    }
                }
            }
            for (int c = 0; c < 3; c++)
                ch[c] += v[c];
            n++;
            double m = (v[0] + v[1] + v[2]) / 3;
            sum += m;
            sum2 += m * m;
            lo = m < lo ? m : lo;
            hi = m > hi ? m : hi;
        }
    if (n == 0) {
        fprintf(stderr, "imgstat: no pixel to measure\n");
        return 2;
    }
    double mean = sum / n, var = sum2 / n - mean * mean;
    printf("size=%dx%d mean=%.6g sd=%.6g min=%.6g max=%.6g r=%.6g g=%.6g b=%.6g", a.w, a.h, mean,
           sqrt(var > 0 ? var : 0), lo, hi, ch[0] / n, ch[1] / n, ch[2] / n);
    if (b.px && !ratio)
        printf(" rel=%.6g", ref > 0 ? sum / (ref / 3) : INFINITY);
    printf("\n");
    if (rows || cols) {
        int outer0 = rows ? y0 : x0, outer1 = rows ? y1 : x1;
        for (int o = outer0; o < outer1; o++) {
            double s = 0;
            int inner0 = rows ? x0 : y0, inner1 = rows ? x1 : y1;
            for (int k = inner0; k < inner1; k++) {
                int x = rows ? k : o, y = rows ? o : k;
                const float *p = a.px + ((size_t)y * a.w + x) * 3;
                s += (p[0] + p[1] + p[2]) / 3.0;
            }
            printf("%s %d %.6g\n", rows ? "row" : "col", o, s / (inner1 - inner0));
        }
    }
    free(a.px);
    free(b.px);
    return 0;
}
