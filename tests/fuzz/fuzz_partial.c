/* fuzz_partial.c -- libFuzzer target for the partial images workers send
 * back (common/image.h, read by the coordinator as a network message):
 * img_read_partial, then job_check_partial (coordinator/jobdir.h) against
 * the render the header names and against others, the splat block's sums
 * (img_splat_add) and the sample sums (img_sums_get).
 *
 * A fuzzer cannot make a block match a 64-bit hash, so an input refused
 * only for its splat or sums block's hash is read again with the hash in
 * its header made right (the last 16 characters of the header's second
 * line): the checks behind the hash (every pixel its sum over spp
 * samples) are fuzzed too.  Seeds: partials that franja-worker writes,
 * made by tests/fuzz/run.sh (path-traced with sums, bidirectional with
 * splats, 8- and 16-bit P6), and tests/fuzz/corpus/partial. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define XXH_INLINE_ALL
#include <xxhash.h>

#include "image.h"
#include "jobdir.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Makes the header's block hash in buf[0..len) that of the block starting
 * at byte at; 0 when the header had the room for it. */
static int fix_hash(unsigned char *buf, size_t len, size_t at)
{
    unsigned char *nl1 = memchr(buf, '\n', len);
    unsigned char *nl2 = nl1 ? memchr(nl1 + 1, '\n', len - (size_t)(nl1 + 1 - buf)) : NULL;
    if (!nl2 || nl2 - nl1 < 17 || at > len)
        return -1;
    char hex[17];
    snprintf(hex, sizeof hex, "%016llx", (unsigned long long)XXH3_64bits(buf + at, len - at));
    memcpy(nl2 - 16, hex, 16);
    return 0;
}

/* Checks an accepted partial as the coordinator would (scheduler, job
 * directory, stitch). */
static void use(const unsigned char *buf, size_t len, const img_partial_info *info, const float *rgb)
{
    if (info->y0 >= info->y1 || info->y1 > info->height || info->width == 0 || !rgb)
        abort();
    size_t n = (size_t)info->width * (info->y1 - info->y0) * 3;
    for (size_t i = 0; i < n; i++)
        if (!(rgb[i] >= 0.0f))
            abort();
    job_spec spec = {info->scene, info->width, info->height, info->spp,
                     info->splat_paths ? FR_INTEGRATOR_BDPT : FR_INTEGRATOR_PATH, 0.0f, info->passes};
    fr_error err;
    /* When the render it names takes it, the scheduler's bound on a
     * worker's output leaves room for it. */
    if (job_check_partial(buf, len, &spec, info->y0, info->y1, info->sums_offset != 0, &err) == 0 &&
        len > job_max_partial(&spec, info->y0, info->y1))
        abort();
    spec.spp++;
    (void)job_check_partial(buf, len, &spec, info->y0, info->y1, 0, &err);
    spec.integrator = spec.integrator == FR_INTEGRATOR_BDPT ? FR_INTEGRATOR_PATH : FR_INTEGRATOR_BDPT;
    (void)job_check_partial(buf, len, &spec, info->y0, info->y1, 1, &err);
    if (info->splat_paths) {
        uint64_t *acc = calloc((size_t)info->width * info->height * 3, sizeof *acc);
        if (acc) {
            img_splat_add(buf, info, acc);
            free(acc);
        }
    }
    if (info->sums_offset) {
        double *sums = malloc(n * sizeof *sums);
        if (sums) {
            img_sums_get(buf, info, sums);
            free(sums);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    img_partial_info info;
    float *rgb = NULL;
    fr_error err;
    if (img_read_partial(data, size, &info, &rgb, &err) == 0) {
        use(data, size, &info, rgb);
        free(rgb);
        return 0;
    }
    size_t at;
    char what[8];
    if (sscanf(err.msg, "byte %zu: the %5s block does not match its hash", &at, what) != 2)
        return 0;
    unsigned char *copy = malloc(size ? size : 1);
    if (!copy)
        return 0;
    memcpy(copy, data, size);
    if (fix_hash(copy, size, at) == 0 && img_read_partial(copy, size, &info, &rgb, &err) == 0) {
        use(copy, size, &info, rgb);
        free(rgb);
    }
    free(copy);
    return 0;
}
