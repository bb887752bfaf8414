/* main.c -- franja-worker: render rows [y0, y1) of a scene and write them
 * as a partial image of the PPM family (see franja-worker(1)). */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bdpt.h"
#include "cont.h"
#include "fbin.h"
#include "scene_pages.h"
#include "file.h"
#include "image.h"
#include "lifeline.h"
#include "passes.h"
#include "mlt_path.h"
#include "pathtrace.h"
#include "protocol.h"
#include "quick.h"
#include "splat.h"
#include "trace.h"
#include "unpack.h"
#include "fpatch.h"
#ifndef FRANJA_NO_JSON
#include "compile/json_scene.h"
#endif

static const char usage[] =
    "usage: franja-worker --scene FILE --rows Y0:Y1 [--spp N] [--size WxH]\n"
    "                     [--integrator path|bdpt|mlt] [--noise-threshold E] [--format pf|ppm16|ppm8]\n"
    "                     [-o FILE|-] [--lifeline] [--sums] [--continue FILE] [--passes LIST]\n"
    "                     [--mlt-norm LIST]\n"
    "       franja-worker --scene FILE --check\n"
    "       franja-worker --unpack FILE --scene FILE\n"
    "       franja-worker --features\n"
    "       franja-worker --help | --version\n"
    "\n"
    "Renders rows Y0 (inclusive) to Y1 (exclusive) of a scene and writes them as a\n"
    "partial image: PF (linear float PFM, the default), or P6 16-bit / 8-bit sRGB.\n"
    "\n"
    "  --scene FILE   binary scene (.fbin, from `franja compile`) or JSON scene\n"
    "  --rows Y0:Y1   rows of the full image, 0 <= Y0 < Y1 <= height\n"
    "  --spp N        samples per pixel (default: the scene's)\n"
    "  --noise-threshold E  adaptive sampling: each pixel stops once its relative\n"
    "                 error estimate is below E, in (0, 1] (default: the scene's)\n"
    "  --size WxH     image size (default: the scene's)\n"
    "  --integrator I path, bdpt or mlt (default: the scene's); mlt renders\n"
    "                 chain y for row y (Metropolis chains splat anywhere)\n"
    "  --mlt-norm LIST  mlt's normalisation, b per path depth (max_depth + 1 floats\n"
    "                 as 8 hex digits of their bits, comma-separated), computed\n"
    "                 once for the whole render by franja; without it the worker\n"
    "                 computes the same itself\n"
    "  --format F     pf, ppm16 or ppm8 (default pf)\n"
    "  -o FILE        output file, or - for standard output (default -)\n"
    "  --check        validate the scene and print its content hash\n"
    "  --unpack F     unpack the packed scene, zstd file or scene patch F into the\n"
    "                 --scene file (a patch: of the scene HASH.fbin beside it),\n"
    "                 check it as --check does (printing its hash) and remove F\n"
    "  --features     print what this build can do besides rendering\n"
    "                 (" PROTO_FEATURE_UNPACK ", " UNPACK_FEATURE ": --unpack of the two forms;\n"
    "                 " FPATCH_FEATURE ": of scene patches)\n"
    "  --lifeline     end when standard input (a pipe) reaches its end\n"
    "  --sums         append each pixel's sample sums to the PF image, so that a\n"
    "                 later render can add samples exactly (path integrator, no\n"
    "                 adaptive sampling)\n"
    "  --continue FILE  start from the sums in FILE, a --sums image of the same\n"
    "                 rows with fewer samples: only the samples it lacks are\n"
    "                 rendered, to the bits of a render of them all\n"
    "  --passes LIST  append render passes to the PF image (path integrator, or\n"
    "                 bdpt's camera-subpath ones; not with sums): comma-separated\n"
    "                 albedo, normal, depth, position,\n"
    "                 emission, diffuse_direct, diffuse_indirect, glossy_direct,\n"
    "                 glossy_indirect, transmission_direct, transmission_indirect,\n"
    "                 material_id, crypto_material, variance, object_id,\n"
    "                 crypto_object, light_groups, shadow; or all, light,\n"
    "                 denoise, none\n"
    "\n"
    "Writing to a pipe (-o -), the worker ends itself when the pipe's reader is\n"
    "gone or its parent process ends.\n";

static int load_scene(const char *path, fr_scene *s, fr_error *err)
{
    int fd;
    size_t size;
    if (file_open_regular(path, SIZE_MAX, &fd, &size, err) < 0)
        return -1;
    unsigned char magic[2] = {0, 0};
    ssize_t n = read(fd, magic, 2);
    close(fd);
    if (n <= 0)
        return fr_fail(err, "%s: empty file (expected a binary scene from `franja compile`, or a JSON scene)", path);
    /* A binary scene by its first bytes, or by its name (so that a damaged
     * one is reported as such, not as bad JSON). */
    size_t len = strlen(path);
    if ((n == 2 && magic[0] == 0x89 && magic[1] == 'F') || (len >= 5 && !strcmp(path + len - 5, ".fbin")))
        return fbin_load(path, s, err);
#ifdef FRANJA_NO_JSON
    return fr_fail(err, "%s: this worker reads binary scenes only; run `franja compile` first", path);
#else
    return json_scene_load(path, NULL, s, err);
#endif
}

int main(int argc, char **argv)
{
    proto_request req;
    fr_error err;
    if (proto_parse_args(argc, argv, &req, &err) < 0) {
        fprintf(stderr, "franja-worker: %s\n", err.msg);
        return 2;
    }
    if (req.mode == PROTO_HELP) {
        fputs(usage, stdout);
        return 0;
    }
    /* The BVH walk: the fastest this processor runs, or the one FRANJA_WALK
     * names (all give the same bits; trace.h). */
    if (trace_walk_choose(getenv("FRANJA_WALK"), &err) < 0) {
        fprintf(stderr, "franja-worker: %s\n", err.msg);
        return 2;
    }
    if (req.mode == PROTO_VERSION) {
        char line[128];
        proto_version_line("franja-worker", line, sizeof line);
        printf("%s\n", line);
        proto_walk_line(line, sizeof line);
        printf("%s\n", line);
        return 0;
    }
    if (req.mode == PROTO_FEATURES) {
        printf("%s%s\n", unpack_available() ? PROTO_FEATURE_UNPACK " " UNPACK_FEATURE " " : "", FPATCH_FEATURE);
        return 0;
    }
    if (req.mode == PROTO_UNPACK) {
        uint64_t hash;
        if ((fpatch_is(req.unpack) ? fpatch_file(req.unpack, req.slab.scene, &hash, &err)
                                   : unpack_file(req.unpack, req.slab.scene, &hash, &err)) < 0) {
            fprintf(stderr, "franja-worker: %s\n", err.msg);
            return 1;
        }
        char hx[17];
        fbin_hash_hex(hash, hx);
        printf("%s\n", hx);
        return 0;
    }
    const proto_slab *sl = &req.slab;
    const char *out = sl->out;
    uint32_t y0 = sl->y0, y1 = sl->y1;

    fr_scene scene;
    if (load_scene(sl->scene, &scene, &err) < 0) {
        fprintf(stderr, "franja-worker: %s\n", err.msg);
        return 1;
    }
    char hex[17];
    fbin_hash_hex(scene.hash, hex);
    if (req.mode == PROTO_CHECK) {
        printf("%s\n", hex);
        scn_free(&scene);
        return 0;
    }
    if (sl->width) {
        scene.settings.width = sl->width;
        scene.settings.height = sl->height;
    }
    if (sl->spp)
        scene.settings.spp = sl->spp;
    if (sl->noise_threshold > 0.0f)
        scene.settings.noise_threshold = sl->noise_threshold;
    if (quick_spp(&scene.settings.spp, &err) < 0) {
        fprintf(stderr, "franja-worker: %s\n", err.msg);
        scn_free(&scene);
        return 2;
    }
    if (y0 >= y1 || y1 > scene.settings.height) {
        fprintf(stderr, "franja-worker: --rows %u:%u: need 0 <= Y0 < Y1 <= %u (the image height)\n", y0, y1,
                scene.settings.height);
        scn_free(&scene);
        return 2;
    }
    scn_bvh_large_pages(&scene);   /* fewer TLB misses in the walk of a large tree; same bits */
    int to_stdout = !strcmp(out, "-");
    if (to_stdout && isatty(STDOUT_FILENO)) {
        fprintf(stderr, "franja-worker: refusing to write an image to a terminal; use -o FILE or a pipe\n");
        scn_free(&scene);
        return 2;
    }
    uint32_t width = scene.settings.width, height = scene.settings.height, spp = scene.settings.spp;
    uint32_t integ = sl->integrator ? (uint32_t)sl->integrator - 1 : scene.settings.integrator;
    int bdpt = fr_integrator_splats(integ), mlt = integ == FR_INTEGRATOR_MLT;
    if (bdpt && (mlt ? mlt_supported(&scene, &err) : bd_supported(&scene, &err)) < 0) {
        fprintf(stderr, "franja-worker: %s: %s\n", mlt ? "Metropolis light transport" : "bidirectional path tracing",
                err.msg);
        scn_free(&scene);
        return sl->integrator ? 2 : 1;
    }
    if (sl->mlt_norm && (!mlt || sl->mlt_depths != scene.settings.max_depth + 1)) {
        fprintf(stderr, "franja-worker: --mlt-norm: %u values for %s, expected %u (max_depth + 1) with the mlt "
                        "integrator\n", sl->mlt_depths, mlt ? "mlt" : "another integrator than mlt",
                scene.settings.max_depth + 1);
        scn_free(&scene);
        return 2;
    }
    if (bdpt && sl->format != IMG_PF && (y0 != 0 || y1 != height)) {
        fprintf(stderr, "franja-worker: --format %s with the %s integrator needs the whole image (--rows 0:%u): "
                        "%s adds light to every row; use --format pf for a slab\n",
                sl->format == IMG_PPM16 ? "ppm16" : "ppm8", mlt ? "mlt" : "bdpt", height,
                mlt ? "every Metropolis chain" : "light tracing");
        scn_free(&scene);
        return 2;
    }
    int keep_sums = sl->sums || sl->continue_from;
    if (keep_sums && (bdpt || sl->format != IMG_PF || scene.settings.noise_threshold > 0.0f)) {
        fprintf(stderr, "franja-worker: --sums and --continue need the path integrator without adaptive sampling "
                        "and --format pf\n");
        scn_free(&scene);
        return 2;
    }
    uint32_t passes = sl->passes;
    if (passes && (mlt || (bdpt && (passes & ~BD_PASSES)) || keep_sums || sl->format != IMG_PF)) {
        fprintf(stderr, "franja-worker: --passes needs the path integrator (or bdpt, for the passes of its camera "
                        "subpaths) and --format pf, without --sums or --continue (this render %s)\n",
                mlt ? "is Metropolis" : bdpt ? "is bidirectional, with light passes" : keep_sums ? "keeps sample sums"
                                                                                      : "is not --format pf");
        scn_free(&scene);
        return 2;
    }
    /* The coordinator gone, the slab is wasted work: stop (lifeline.h). */
    lifeline_start(to_stdout, sl->lifeline);
    size_t n = (size_t)width * (y1 - y0) * 3;
    float *rgb = malloc(n * sizeof *rgb);
    uint64_t *splat = bdpt ? calloc((size_t)width * height * 3, sizeof *splat) : NULL;
    double *sums = keep_sums ? calloc(n, sizeof *sums) : NULL;
    float *pass = passes ? malloc(n / 3 * pass_channels(passes) * sizeof *pass) : NULL;
    if (!rgb || (bdpt && !splat) || (keep_sums && !sums) || (passes && !pass)) {
        fprintf(stderr, "franja-worker: out of memory for %zu pixels\n", bdpt ? (size_t)width * height : n / 3);
        free(rgb);
        free(splat);
        free(sums);
        free(pass);
        lifeline_stop();
        scn_free(&scene);
        return 1;
    }
    uint32_t first = 0;
    if (sl->continue_from && cont_load(sl->continue_from, &scene, y0, y1, sums, &first, &err) < 0) {
        fprintf(stderr, "franja-worker: %s\n", err.msg);
        free(rgb);
        free(sums);
        lifeline_stop();
        scn_free(&scene);
        return 2;
    }
    img_partial_info info = {scene.hash, y0, y1, spp, width, height, 0, 0, 0, 0, passes, 0};
    /* The coordinator's normalisation (mlt_path.h), else the worker's own. */
    mlt_boot norm = {0};
    int norm_failed = sl->mlt_norm && mlt_boot_set(&norm, sl->mlt_norm, sl->mlt_depths, &err) < 0;
    if (bdpt) {
        int failed = norm_failed || (mlt ? mlt_render_rows(&scene, sl->mlt_norm ? &norm : NULL, y0, y1, rgb, splat, &err)
                                         : bd_render_rows_passes(&scene, y0, y1, rgb, splat, passes, pass, &err)) < 0;
        mlt_boot_free(&norm);
        if (failed) {
            fprintf(stderr, "franja-worker: %s\n", err.msg);
            free(rgb);
            free(splat);
            free(pass);
            lifeline_stop();
            scn_free(&scene);
            return 1;
        }
        if (sl->format != IMG_PF) {
            /* The whole image: its own splats are all there are. */
            spl_resolve(rgb, splat, width, 0, height, spp);
            free(splat);
            splat = NULL;
        } else {
            info.splat_paths = (uint64_t)width * (y1 - y0) * spp;
        }
    } else if (keep_sums) {
        pt_render_rows_sums(&scene, PT_MIS, y0, y1, first, sums, rgb);
    } else {
        pt_render_rows_passes(&scene, PT_MIS, y0, y1, rgb, passes, pass);
    }
    lifeline_stop();

    /* A file is written beside its target and renamed over it whole
     * (file.h), so a reader never sees half a partial and a failed write
     * leaves what was there; a device or FIFO is written in place. */
    file_out o = {.fd = -1};
    FILE *f = stdout;
    int rc = 0;
    if (!to_stdout) {
        int fd = -1;
        if (file_out_open(out, &o, &err) || (fd = dup(o.fd)) < 0 || !(f = fdopen(fd, "wb"))) {
            int e = errno;
            if (fd >= 0)
                close(fd);
            errno = e;
            if (o.fd < 0)
                fprintf(stderr, "franja-worker: %s\n", err.msg);
            else
                fprintf(stderr, "franja-worker: %s: %s\n", out, strerror(errno));
            f = NULL;
            rc = 1;
        }
    }
    if (f && (sl->sums     ? img_write_sums(f, &info, rgb, sums, &err)
              : passes && splat ? img_write_splat_passes(f, &info, rgb, splat, pass, &err)
              : passes ? img_write_passes(f, &info, rgb, pass, &err)
                       : img_write(f, sl->format, &info, rgb, splat, &err)) < 0) {
        fprintf(stderr, "franja-worker: %s: %s\n", to_stdout ? "standard output" : out, err.msg);
        rc = 1;
    }
    if (f && !to_stdout && fclose(f) != 0 && rc == 0) {
        fprintf(stderr, "franja-worker: %s: %s\n", out, strerror(errno));
        rc = 1;
    }
    if (!to_stdout && o.fd >= 0) {
        if (rc)
            file_out_abort(&o);
        else if (file_out_commit(&o, out, &err)) {
            fprintf(stderr, "franja-worker: %s\n", err.msg);
            rc = 1;
        }
    }
    free(rgb);
    free(splat);
    free(sums);
    free(pass);
    scn_free(&scene);
    return rc;
}
