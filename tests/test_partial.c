/* test_partial.c -- partial images and their splat blocks: exact round trips,
 * refusals.
 *
 * Partial images with and without light-tracing splats: what a worker
 * writes reads back exactly; a damaged, truncated or padded splat block,
 * a malformed splat field and splats in an sRGB image are refused; and
 * fixed-point splat sums round once, saturate, and do not depend on the
 * order they are added in. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "image.h"
#include "sampler.h"
#include "splat.h"

enum { W = 5, H = 4, Y0 = 1, Y1 = 3 };

/* Writes a partial of rows Y0:Y1 (with splats unless splat is NULL) into
 * a malloc'd buffer. */
static unsigned char *written(const uint64_t *splat, img_format fmt, size_t *len, int *rc)
{
    float rgb[W * (Y1 - Y0) * 3];
    for (int i = 0; i < W * (Y1 - Y0) * 3; i++)
        rgb[i] = 0.25f * (float)i;
    img_partial_info info = {0x0123456789abcdefull, Y0, Y1, 8, W, H, splat ? (uint64_t)W * (Y1 - Y0) * 8 : 0, 0, 0, 0, 0, 0};
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    fr_error err;
    *rc = img_write(f, fmt, &info, rgb, splat, &err);
    fclose(f);
    return (unsigned char *)buf;
}

static void round_trip(void)
{
    uint64_t splat[W * H * 3];
    for (int i = 0; i < W * H * 3; i++)
        splat[i] = (uint64_t)smp_hash((uint32_t)i) << 20 | (uint64_t)i;
    size_t len;
    int rc;
    unsigned char *buf = written(splat, IMG_PF, &len, &rc);
    CHECK(rc == 0, "writing a partial with splats failed");
    CHECK(strstr((char *)buf, " splat=80:") != NULL, "the header does not count the light subpaths");
    img_partial_info info;
    float *rgb = NULL;
    fr_error err;
    CHECK(img_read_partial(buf, len, &info, &rgb, &err) == 0, "reading it back: %s", err.msg);
    CHECK(info.splat_paths == 80 && info.y0 == Y0 && info.y1 == Y1 && info.width == W && info.height == H &&
              info.spp == 8, "header read back wrong");
    int same = rgb != NULL;
    for (int i = 0; same && i < W * (Y1 - Y0) * 3; i++)
        same = rgb[i] == 0.25f * (float)i;
    CHECK(same, "pixels read back differ");
    free(rgb);
    uint64_t acc[W * H * 3];
    memset(acc, 0, sizeof acc);
    img_splat_add(buf, &info, acc);
    CHECK(!memcmp(acc, splat, sizeof acc), "splats read back differ");
    img_splat_add(buf, &info, acc);
    int twice = 1;
    for (int i = 0; i < W * H * 3; i++)
        twice &= acc[i] == (splat[i] > UINT64_MAX / 2 ? UINT64_MAX : 2 * splat[i]);
    CHECK(twice, "adding the splats twice does not double (saturating) them");

    /* Damage: a flipped byte in the block, one byte less, one more. */
    buf[len - 3] ^= 0x40;
    CHECK(img_read_partial(buf, len, &info, &rgb, &err) < 0 && strstr(err.msg, "hash"),
          "a damaged splat block is accepted (%s)", err.msg);
    buf[len - 3] ^= 0x40;
    CHECK(img_read_partial(buf, len - 1, &info, &rgb, &err) < 0, "a truncated splat block is accepted");
    unsigned char *more = malloc(len + 1);
    memcpy(more, buf, len);
    more[len] = 0;
    CHECK(img_read_partial(more, len + 1, &info, &rgb, &err) < 0, "a padded splat block is accepted");
    free(more);
    free(buf);

    /* Without splats: no field, no block. */
    buf = written(NULL, IMG_PF, &len, &rc);
    CHECK(rc == 0 && !strstr((char *)buf, "splat="), "a partial without splats names splats");
    CHECK(img_read_partial(buf, len, &info, &rgb, &err) == 0 && info.splat_paths == 0, "plain partial: %s", err.msg);
    free(rgb);
    free(buf);
    buf = written(splat, IMG_PPM8, &len, &rc);
    CHECK(rc < 0, "splats in an sRGB image are written");
    free(buf);
}

/* Malformed splat fields in an otherwise valid header. */
static void bad_fields(void)
{
    const char *tails[] = {" splat=0:0123456789abcdef", " splat=12:abc", " splat=:0123456789abcdef",
                           " splat=12", " splat=12:0123456789abcdef x", " splats=12:0123456789abcdef",
                           " splat=-1:0123456789abcdef", " splat=12:0123456789abcdefa"};
    for (size_t k = 0; k < sizeof tails / sizeof *tails; k++) {
        char head[256];
        int n = snprintf(head, sizeof head, "PF\n# franja scene=0123456789abcdef rows=0:1 spp=1 size=1x1%s\n1 1\n-1.0\n",
                         tails[k]);
        size_t len = (size_t)n + 12 + 24;
        unsigned char *buf = calloc(1, len);
        memcpy(buf, head, (size_t)n);
        img_partial_info info;
        float *rgb = NULL;
        fr_error err;
        CHECK(img_read_partial(buf, len, &info, &rgb, &err) < 0, "header tail '%s' accepted", tails[k]);
        free(buf);
    }
}

static void fixed_point(void)
{
    CHECK(spl_fixed(1.0f) == 1ull << 32, "1.0 is not 2^32");
    CHECK(spl_fixed(0x1p-33f) == 1 && spl_fixed(0x1p-34f) == 0, "2^-33 does not round to 1 unit, 2^-34 to 0");
    CHECK(spl_fixed(-1.0f) == 0 && spl_fixed(0.0f / 0.0f) == 0, "negative or NaN splats count");
    CHECK(spl_fixed(1e30f) == UINT64_MAX, "a huge splat does not saturate");
    uint64_t a = UINT64_MAX - 5;
    spl_add(&a, 10);
    CHECK(a == UINT64_MAX, "addition does not saturate");
    CHECK(spl_value(3ull << 32, 4) == 0.75f, "3 units over 4 samples is not 0.75");
    /* Any order, any grouping: the same sum. */
    enum { N = 1000 };
    uint64_t v[N], fwd = 0, back = 0, pairs = 0;
    for (int i = 0; i < N; i++)
        v[i] = spl_fixed((float)(smp_hash((uint32_t)i) >> 8) * 0x1p-20f);
    for (int i = 0; i < N; i++)
        spl_add(&fwd, v[i]);
    for (int i = N - 1; i >= 0; i--)
        spl_add(&back, v[i]);
    for (int i = 0; i < N; i += 2) {
        uint64_t p = v[i];
        spl_add(&p, v[i + 1]);
        spl_add(&pairs, p);
    }
    CHECK(fwd == back && back == pairs, "the sum depends on the order");
    float rgb[3] = {0.5f, 0.5f, 0.5f};
    uint64_t sp[3] = {1ull << 32, 0, 2ull << 32};
    spl_resolve(rgb, sp, 1, 0, 1, 2);
    CHECK(rgb[0] == 1.0f && rgb[1] == 0.5f && rgb[2] == 1.5f, "spl_resolve adds sum / spp");
}

int main(void)
{
    round_trip();
    bad_fields();
    fixed_point();
    return check_done();
}
