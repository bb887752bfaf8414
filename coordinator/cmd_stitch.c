/* cmd_stitch.c -- `franja stitch`: an image from whatever a job directory
 * holds, for a look at a render in progress or cut short. */
#include "cmd.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "opt.h"
#include "fbin.h"
#include "jobdir.h"
#include "output.h"
#include "preview.h"
#include "scene.h"
#include "tonemap.h"

static const char usage[] =
    "usage: franja stitch JOBDIR -o OUT [--exposure E] [--tonemap CURVE]\n"
    "\n"
    "Makes OUT from the finished slabs a job directory holds (a render in\n"
    "progress, interrupted or failed: OUT.franja-job), at the render's size.\n"
    "Rows not rendered yet show as a grey checkerboard.  Says how many rows\n"
    "are present and which are missing; changes nothing in JOBDIR.  Tone\n"
    "mapping is the scene's when JOBDIR holds the compiled scene.\n"
    "\n"
    "  -o OUT               the image to write (.png .exr .tif .jpg .hdr .ppm .bmp .pfm)\n"
    "  --exposure E         scale LDR outputs by 2^E before the sRGB curve\n"
    "                       (default: the scene's tonemap)\n"
    "  --tonemap CURVE      none or filmic (default: the scene's, else none)\n";

int cmd_stitch(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"exposure", required_argument, NULL, 'E'},
        {"tonemap", required_argument, NULL, 'T'},
        {NULL, 0, NULL, 0},
    };
    static const char *const curves[] = {"none", "filmic", NULL};
    const char *out = NULL;
    float exposure = 0;
    int exposure_set = 0, curve = -1, c;
    optind = 0;
    while ((c = opt_next("stitch", argc, argv, "ho:", longopts)) != -1) {
        switch (c) {
        case 'h':
            fputs(usage, stdout);
            return 0;
        case 'o':
            out = optarg;
            break;
        case 'E':
            if (opt_float("stitch", "--exposure", optarg, -64, 64, &exposure))
                return 2;
            exposure_set = 1;
            break;
        case 'T':
            if ((curve = opt_choice("stitch", "--tonemap", optarg, curves)) < 0)
                return 2;
            break;
        default:
            return 2;
        }
    }
    const char *problem = argc - optind > 1   ? "one job directory at a time"
                          : argc - optind == 0 ? "a JOBDIR is required"
                          : !out               ? "-o OUT is required"
                                               : NULL;
    if (problem) {
        fprintf(stderr, "franja stitch: %s (see franja stitch --help)\n", problem);
        return 2;
    }
    const char *dir = argv[optind];
    fr_error err;
    if (out_check(out, &err)) {
        fprintf(stderr, "franja stitch: %s\n", err.msg);
        return 2;
    }
    job_spec spec;
    if (job_read_spec(dir, &spec, &err)) {
        fprintf(stderr, "franja stitch: %s\n", err.msg);
        return 1;
    }
    /* The scene's tone mapping, when its compiled scene is here. */
    fr_tonemap tm = {0};
    char fbin[4200];
    snprintf(fbin, sizeof fbin, "%s/scene.fbin", dir);
    fr_scene sc;
    fr_error ignore;
    if (fbin_load(fbin, &sc, &ignore) == 0) {
        if (sc.hash == spec.hash)
            tm = sc.tonemap;
        scn_free(&sc);
    }
    if (exposure_set)
        tm.exposure = exposure;
    if (curve >= 0)
        tm_curve_parse(curves[curve], &tm.curve);

    float *rgb = calloc((size_t)spec.width * spec.height * 3, sizeof *rgb);
    unsigned char *have = calloc(spec.height, 1);
    int rc = 1, skipped = 0;
    if (!rgb || !have) {
        fprintf(stderr, "franja stitch: out of memory for a %ux%u image\n", spec.width, spec.height);
        goto done;
    }
    int rows = preview_image(dir, &spec, rgb, have, &skipped, &err);
    if (rows >= 0 && fr_integrator_splats(spec.integrator)) {
        /* A bidirectional job: the rows lack the light traced from the
         * lights (every slab's splats over the whole image), so only a
         * complete job, whose every slab checked out, makes an image. */
        if ((uint32_t)rows < spec.height || skipped) {
            char missing[300] = "";
            job_missing_rows(have, spec.height, missing, sizeof missing);
            fprintf(stderr, "franja stitch: %s: a bidirectional render makes an image only when every row is there "
                            "(rows %s are missing, %d slab files did not check out)\n", dir,
                    missing[0] ? missing : "none", skipped);
            goto done;
        }
        if (job_stitch(dir, &spec, rgb, NULL, &err))
            rows = -1;
    }
    if (rows < 0) {
        fprintf(stderr, "franja stitch: %s\n", err.msg);
        goto done;
    }
    out_meta meta;
    out_meta_make(&meta, &spec, -1, NULL);
    iio_options io = {.attrs = meta.attrs};
    if (out_write_with(out, rgb, &spec, &tm, &io, &err)) {
        fprintf(stderr, "franja stitch: %s\n", err.msg);
        goto done;
    }
    char missing[300] = "";
    if ((uint32_t)rows < spec.height)
        job_missing_rows(have, spec.height, missing, sizeof missing);
    printf("%s: %d of %u rows present (%ux%u, %u spp)%s%s\n", out, rows, spec.height, spec.width, spec.height,
           spec.spp, missing[0] ? "; missing rows " : "", missing);
    if (skipped)
        printf("%s: %d slab file%s that did not check out were left out\n", dir, skipped, skipped == 1 ? "" : "s");
    rc = 0;
done:
    free(rgb);
    free(have);
    return rc;
}
