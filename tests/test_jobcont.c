/* test_jobcont.c -- a job directory with slabs of several sample counts
 * (jobdir.h): job_scan finds, for each row, the slabs with the samples
 * asked for and the most samples kept below them with their sums;
 * job_cont_build gathers those sums for rows of any split; job_open lets
 * the same render ask for more samples, and refuses fewer than a slab holds
 * and more for an adaptive render; job_prune, job_gather and job_rows_at
 * see the sample counts too. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "file.h"
#include "jobdir.h"

enum { W = 5, H = 12 };

/* The value of channel c of pixel (x, y) in a slab of spp samples: a
 * multiple of 1/8, so that the sum spp * v is exact. */
static float value(uint32_t x, uint32_t y, int c, uint32_t spp)
{
    return (float)((x + 2 * y + c + spp) % 16) / 8.0f;
}

/* Writes rows [y0, y1) with spp samples as DIR/rows-Y0-Y1.pf, with sums
 * or without. */
static void slab(const char *dir, const job_spec *sp, uint32_t y0, uint32_t y1, uint32_t spp, int sums)
{
    size_t n = (size_t)W * (y1 - y0) * 3;
    float *rgb = malloc(n * sizeof *rgb);
    double *s = malloc(n * sizeof *s);
    for (uint32_t y = y0; y < y1; y++)
        for (uint32_t x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                size_t k = ((size_t)(y - y0) * W + x) * 3 + c;
                rgb[k] = value(x, y, c, spp);
                s[k] = (double)rgb[k] * spp;
            }
    char path[600], *buf = NULL;
    size_t len = 0;
    snprintf(path, sizeof path, "%s/rows-%05u-%05u.pf", dir, y0, y1);
    FILE *f = open_memstream(&buf, &len);
    img_partial_info info = {sp->hash, y0, y1, spp, W, H, 0, 0, 0, 0, 0, 0};
    fr_error err;
    int rc = sums ? img_write_sums(f, &info, rgb, s, &err) : img_write(f, IMG_PF, &info, rgb, NULL, &err);
    fclose(f);
    CHECK(rc == 0 && file_write_atomic(path, buf, len, &err) == 0, "writing %s", path);
    free(buf);
    free(rgb);
    free(s);
}

static int exists(const char *dir, const char *name)
{
    char path[600];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return access(path, F_OK) == 0;
}

int main(void)
{
    char dir[] = "/tmp/franja-jobcont.XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    job_spec sp = {0x1234abcdULL, W, H, 8, 0, 0.0f, 0, NULL, 0};
    fr_error err;
    CHECK(job_sums(&sp), "path tracing without a threshold keeps sums");
    CHECK(job_open(dir, &sp, 0, &err) == 0, "job_open: %s", err.msg);
    /* Rows 0:6 with 4 samples and sums, 5:9 with 8, 9:12 with 4 and no
     * sums; 6:8 with 2 (below the 4 of 0:6, above nothing). */
    slab(dir, &sp, 0, 6, 4, 1);
    slab(dir, &sp, 5, 9, 8, 1);
    slab(dir, &sp, 9, 12, 4, 0);
    slab(dir, &sp, 6, 8, 2, 1);
    CHECK(job_rows_at(dir, 8) == 4 && job_rows_at(dir, 4) == 12 && job_rows_at(dir, 1) == 12,
          "rows at 8, 4, 1 samples: %d %d %d", job_rows_at(dir, 8), job_rows_at(dir, 4), job_rows_at(dir, 1));

    unsigned char have[H];
    uint32_t base[H];
    CHECK(job_scan(dir, &sp, have, base, NULL, &err) == 4, "rows at 8 samples");
    static const uint32_t want[H] = {4, 4, 4, 4, 4, 0, 0, 0, 0, 0, 0, 0};
    for (uint32_t y = 0; y < H; y++) {
        CHECK(have[y] == (y >= 5 && y < 9), "row %u: have %d", y, have[y]);
        CHECK(base[y] == want[y], "row %u: base %u, want %u", y, base[y], want[y]);
    }
    CHECK(!exists(dir, "rows-00009-00012.pf"), "a slab with fewer samples and no sums is discarded");
    CHECK(exists(dir, "rows-00006-00008.pf"), "a slab with fewer samples and sums is kept");

    /* The sums of rows 2:5 at 4 samples, from the slab 0:6; of 6:8 at 2. */
    char path[4400];
    for (int t = 0; t < 2; t++) {
        uint32_t y0 = t ? 6 : 2, y1 = t ? 8 : 5, spp = t ? 2 : 4;
        CHECK(job_cont_build(dir, &sp, y0, y1, spp, path, sizeof path, &err) == 0, "job_cont_build: %s", err.msg);
        char *buf;
        size_t len;
        img_partial_info info;
        float *rgb = NULL;
        int ok = file_read(path, &buf, &len, &err) == 0 &&
                 img_read_partial((unsigned char *)buf, len, &info, &rgb, &err) == 0;
        CHECK(ok && info.y0 == y0 && info.y1 == y1 && info.spp == spp && info.sums_offset && info.scene == sp.hash,
              "the sums of rows %u:%u: %s", y0, y1, ok ? "another header" : err.msg);
        double s[W * 3 * 3];
        if (ok) {
            img_sums_get((unsigned char *)buf, &info, s);
            for (uint32_t y = y0; y < y1; y++)
                for (uint32_t x = 0; x < W; x++)
                    for (int c = 0; c < 3; c++) {
                        size_t k = ((size_t)(y - y0) * W + x) * 3 + c;
                        CHECK(rgb[k] == value(x, y, c, spp) && s[k] == (double)value(x, y, c, spp) * spp,
                              "pixel (%u, %u) of rows %u:%u", x, y, y0, y1);
                    }
            free(buf);
        }
        free(rgb);
        CHECK(path[0] && strstr(path, "/.cont-") && strstr(path, ".tmp-"), "a temporary name: %s", path);
        unlink(path);
    }
    CHECK(job_cont_build(dir, &sp, 3, 7, 4, path, sizeof path, &err) == -1 && strstr(err.msg, "row 6"),
          "rows 3:7 at 4 samples are not all there: %s", err.msg);
    CHECK(job_cont_build(dir, &sp, 9, 10, 4, path, sizeof path, &err) == -1, "rows 9:10 at 4 samples are gone");

    /* The image so far: each row from its slab with the most samples. */
    float img[W * H * 3];
    unsigned char got[H];
    memset(img, 0, sizeof img);
    CHECK(job_gather(dir, &sp, img, got, NULL, &err) == 9, "job_gather: 9 rows");
    for (uint32_t y = 0; y < 9; y++) {
        uint32_t spp = y >= 5 ? 8 : 4;
        CHECK(got[y] && img[(y * W + 1) * 3] == value(1, y, 0, spp), "gathered row %u from %u samples", y, spp);
    }

    /* Another sample count for the same render. */
    job_spec more = sp, fewer = sp, ad = sp;
    more.spp = 16;
    fewer.spp = 4;
    CHECK(job_open(dir, &fewer, 1, &err) == JOB_REFUSED && strstr(err.msg, "8 samples per pixel, more than the 4") &&
              strstr(err.msg, "cannot be taken away"),
          "fewer samples than a slab holds: %s", err.msg);
    CHECK(job_open(dir, &more, 1, &err) == 0, "more samples: %s", err.msg);
    job_spec now;
    CHECK(job_read_spec(dir, &now, &err) == 0 && now.spp == 16, "the job file records 16 samples");
    ad.noise_threshold = 0.1f;
    CHECK(!job_sums(&ad), "an adaptive render keeps no sums");
    CHECK(job_open(dir, &ad, 1, &err) == JOB_REFUSED, "an adaptive render of the directory is another render");
    job_spec other = more;
    other.hash ^= 1;
    CHECK(job_open(dir, &other, 1, &err) == JOB_REFUSED && strstr(err.msg, "belongs to another render"),
          "another scene: %s", err.msg);

    /* Rows 5:9 at 8 and 6:8 at 2: the 2-sample slab is covered. */
    job_prune(dir, &sp);
    CHECK(!exists(dir, "rows-00006-00008.pf"), "a slab covered by more samples is pruned");
    CHECK(exists(dir, "rows-00000-00006.pf") && exists(dir, "rows-00005-00009.pf"), "the others stay");

    job_remove(dir);
    CHECK(access(dir, F_OK) != 0, "job_remove leaves nothing");
    return check_done();
}
