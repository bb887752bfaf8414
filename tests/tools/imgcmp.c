/* imgcmp.c -- compare a rendered PFM against a reference PFM.
 *
 *   imgcmp IMAGE.pfm REFERENCE.pfm [--max-rmse X] [--max-mean-rel Y]
 *          [--max-block-rel Z [--block N]] [--down D] [--region X0,Y0,X1,Y1 [--mask M.pfm]]
 *          [--clamp-pct P] [--light L]
 *
 * IMAGE is box-downsampled to the reference's size when it is an integer
 * multiple of it; with --down, both are then box-downsampled by D (which
 * must divide the reference's sides), and everything below is measured on
 * the smaller images (block sizes in their pixels).  Prints each channel's mean (image and reference) and the
 * RMSE over all channels of the pixels off the light (reference pixels with
 * a channel >= L are the light; L = 10 unless --light says otherwise: 1
 * leaves out the lamp's edge pixels too, where renderers may disagree by
 * a fraction of a pixel), and with --max-block-rel the worst
 * relative difference of the mean (all channels, off the light) over the
 * N x N blocks of the reference (N = 64 by default).  With limits, prints
 * the closing "N passed, N failed" line and exits non-zero when one is
 * exceeded.  With --region (fractions of the width and height, top row 0),
 * also the RMSE inside that rectangle of pixels and outside it, both off
 * the light; with --mask (a PFM of the reference's size, before --down),
 * the pixels where the mask has a channel above 0 are not in the region
 * (they count as outside it).  With --clamp-pct P (0 < P < 100), also the
 * RMSE off the light after clamping both images' channels to the P-th
 * percentile of the reference's channel values off the light: a measure of
 * noise that rare bright outliers (fireflies) do not rule. */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfmread.h"

/* Box-downsample im by f in place (f divides its sides). */
static void box_down(image *im, int f)
{
    int w = im->w / f, h = im->h / f;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int ch = 0; ch < 3; ch++) {
                double v = 0;
                for (int j = 0; j < f; j++)
                    for (int i = 0; i < f; i++)
                        v += im->px[((size_t)(y * f + j) * im->w + x * f + i) * 3 + ch];
                im->px[((size_t)y * w + x) * 3 + ch] = (float)(v / (f * f));
            }
    im->w = w;
    im->h = h;
}

static int cmp_float(const void *x, const void *y)
{
    float a = *(const float *)x, b = *(const float *)y;
    return (a > b) - (a < b);
}

/* The light's threshold (--light): a reference pixel with a channel at or
 * above it is the light. */
static double light_at = 10;

static int is_light(const float *q) { return q[0] >= light_at || q[1] >= light_at || q[2] >= light_at; }

/* RMSE off the light of a against r with every channel clamped to the
 * pct-th percentile of r's channels off the light (in *at); -1 when
 * memory runs out or nothing is off the light. */
static double clamped_rmse(const image *a, const image *r, double pct, double *at)
{
    size_t n = (size_t)r->w * r->h, m = 0;
    float *v = malloc(n * 3 * sizeof *v);
    if (!v) return -1;
    for (size_t i = 0; i < n; i++) {
        const float *q = r->px + i * 3;
        if (!is_light(q))
            for (int ch = 0; ch < 3; ch++) v[m++] = q[ch];
    }
    if (!m) { free(v); return -1; }
    qsort(v, m, sizeof *v, cmp_float);
    size_t idx = (size_t)(pct / 100.0 * (double)(m - 1) + 0.5);
    double t = v[idx < m ? idx : m - 1], se = 0;
    free(v);
    for (size_t i = 0; i < n; i++) {
        const float *q = r->px + i * 3, *p = a->px + i * 3;
        if (is_light(q)) continue;
        for (int ch = 0; ch < 3; ch++) {
            double d = fmin(p[ch], t) - fmin(q[ch], t);
            se += d * d;
        }
    }
    *at = t;
    return sqrt(se / (double)m);
}

int main(int argc, char **argv)
{
    double max_rmse = -1, max_rel = -1, max_block = -1, reg[4] = {-1, -1, -1, -1}, clamp_pct = -1;
    const char *mask_path = NULL;
    int bs = 64, down = 1;
    if (argc < 3) {
        fprintf(stderr, "usage: imgcmp IMAGE.pfm REFERENCE.pfm [--max-rmse X] [--max-mean-rel Y] "
                        "[--max-block-rel Z [--block N]] [--down D] [--region X0,Y0,X1,Y1 [--mask M.pfm]] "
                        "[--clamp-pct P] [--light L]\n");
        return 2;
    }
    for (int i = 3; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--max-rmse")) max_rmse = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--max-mean-rel")) max_rel = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--max-block-rel")) max_block = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--block")) bs = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--down")) down = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--mask")) mask_path = argv[i + 1];
        else if (!strcmp(argv[i], "--clamp-pct")) {
            clamp_pct = atof(argv[i + 1]);
            if (!(clamp_pct > 0 && clamp_pct < 100)) {
                fprintf(stderr, "imgcmp: --clamp-pct: expected a percentile between 0 and 100\n");
                return 2;
            }
        }
        else if (!strcmp(argv[i], "--light")) {
            light_at = atof(argv[i + 1]);
            if (!(light_at > 0 && light_at < 1e30)) {
                fprintf(stderr, "imgcmp: --light: expected a positive radiance\n");
                return 2;
            }
        }
        else if (!strcmp(argv[i], "--region")) {
            char tail;
            if (sscanf(argv[i + 1], "%lf,%lf,%lf,%lf%c", &reg[0], &reg[1], &reg[2], &reg[3], &tail) != 4 ||
                !(reg[0] >= 0 && reg[0] < reg[2] && reg[2] <= 1 && reg[1] >= 0 && reg[1] < reg[3] && reg[3] <= 1)) {
                fprintf(stderr, "imgcmp: --region: expected X0,Y0,X1,Y1, fractions with X0 < X1, Y0 < Y1\n");
                return 2;
            }
        }
        else { fprintf(stderr, "imgcmp: unknown option %s\n", argv[i]); return 2; }
    }
    if (bs < 1 || bs > 65536) { fprintf(stderr, "imgcmp: bad block size\n"); return 2; }
    if (down < 1 || down > 65536) { fprintf(stderr, "imgcmp: bad --down\n"); return 2; }
    image a, r;
    if (read_pfm("imgcmp", argv[1], &a) < 0 || read_pfm("imgcmp", argv[2], &r) < 0) return 2;
    image m = {0, 0, NULL};
    if (mask_path) {
        if (reg[0] < 0) { fprintf(stderr, "imgcmp: --mask needs --region\n"); return 2; }
        if (read_pfm("imgcmp", mask_path, &m) < 0) return 2;
        if (m.w != r.w || m.h != r.h) {
            fprintf(stderr, "imgcmp: the mask is %dx%d, the reference %dx%d\n", m.w, m.h, r.w, r.h);
            return 2;
        }
    }
    if (a.w % r.w || a.h % r.h || a.w / r.w != a.h / r.h) {
        fprintf(stderr, "imgcmp: %dx%d is not a multiple of %dx%d\n", a.w, a.h, r.w, r.h);
        return 2;
    }
    if (r.w % down || r.h % down) {
        fprintf(stderr, "imgcmp: --down %d does not divide %dx%d\n", down, r.w, r.h);
        return 2;
    }
    box_down(&a, a.w / r.w * down);
    box_down(&r, down);
    if (m.px) box_down(&m, down);
    int k = 1;
    double mean[3] = {0}, rmean[3] = {0}, se = 0, se_in = 0, se_out = 0;
    long off = 0, n_in = 0, n_out = 0;
    int nbx = (r.w + bs - 1) / bs, nby = (r.h + bs - 1) / bs;
    double *blk = calloc((size_t)nbx * nby * 2, sizeof(double));
    if (!blk) return 2;
    for (int y = 0; y < r.h; y++)
        for (int x = 0; x < r.w; x++) {
            const float *q = r.px + ((size_t)y * r.w + x) * 3;
            int light = is_light(q);
            double fx = (x + 0.5) / r.w, fy = (y + 0.5) / r.h, px_se = 0;
            int in = fx >= reg[0] && fx < reg[2] && fy >= reg[1] && fy < reg[3];
            if (in && m.px) {
                const float *mq = m.px + ((size_t)y * m.w + x) * 3;
                in = !(mq[0] > 0 || mq[1] > 0 || mq[2] > 0);
            }
            for (int ch = 0; ch < 3; ch++) {
                double v = 0;
                for (int j = 0; j < k; j++)
                    for (int i = 0; i < k; i++)
                        v += a.px[((size_t)(y * k + j) * a.w + x * k + i) * 3 + ch];
                v /= k * k;
                mean[ch] += v;
                rmean[ch] += q[ch];
                if (!light) {
                    px_se += (v - q[ch]) * (v - q[ch]);
                    double *b = blk + ((size_t)(y / bs) * nbx + x / bs) * 2;
                    b[0] += v;
                    b[1] += q[ch];
                }
            }
            se += px_se;
            off += !light;
            if (!light && in) { se_in += px_se; n_in++; }
            if (!light && !in) { se_out += px_se; n_out++; }
        }
    int npx = r.w * r.h, pass = 0, fail = 0;
    double rmse = sqrt(se / (3.0 * off));
    for (int ch = 0; ch < 3; ch++) {
        mean[ch] /= npx;
        rmean[ch] /= npx;
        double rel = fabs(mean[ch] - rmean[ch]) / rmean[ch];
        printf("channel %c: mean %.5f, reference %.5f (%.2f %%)\n", "RGB"[ch], mean[ch], rmean[ch], 100 * rel);
        if (max_rel >= 0) {
            if (rel <= max_rel) pass++;
            else { fail++; printf("FAIL: channel %c mean off by %.2f %% (limit %.2f %%)\n", "RGB"[ch], 100 * rel, 100 * max_rel); }
        }
    }
    printf("rmse %.5f over %ld pixels off the light\n", rmse, off);
    if (clamp_pct > 0) {
        double at, c = clamped_rmse(&a, &r, clamp_pct, &at);
        if (c < 0) { fprintf(stderr, "imgcmp: --clamp-pct: no pixel off the light, or out of memory\n"); return 2; }
        printf("clamped rmse %.5f (both clamped at %.5f, the reference's %gth percentile)\n", c, at, clamp_pct);
    }
    if (reg[0] >= 0)
        printf("rmse in region %.5f over %ld pixels, outside %.5f over %ld pixels\n",
               n_in ? sqrt(se_in / (3.0 * n_in)) : 0.0, n_in, n_out ? sqrt(se_out / (3.0 * n_out)) : 0.0, n_out);
    if (max_block >= 0) {
        double worst = 0;
        int wx = 0, wy = 0;
        for (int by = 0; by < nby; by++)
            for (int bx = 0; bx < nbx; bx++) {
                const double *b = blk + ((size_t)by * nbx + bx) * 2;
                double rel = b[1] > 0 ? fabs(b[0] - b[1]) / b[1] : (b[0] > 0 ? INFINITY : 0);
                if (rel > worst) { worst = rel; wx = bx; wy = by; }
            }
        printf("worst %dx%d block: (%d, %d) from the top left, mean off by %.2f %%\n", bs, bs, wx, wy, 100 * worst);
        if (worst <= max_block) pass++;
        else { fail++; printf("FAIL: a block's mean is off by %.2f %% (limit %.2f %%)\n", 100 * worst, 100 * max_block); }
    }
    free(blk);
    if (max_rmse >= 0) {
        if (rmse <= max_rmse) pass++;
        else { fail++; printf("FAIL: rmse %.5f above %.5f\n", rmse, max_rmse); }
    }
    if (max_rmse >= 0 || max_rel >= 0 || max_block >= 0) printf("%d passed, %d failed\n", pass, fail);
    return fail ? 1 : 0;
}
