/* franja-worker -- render rows [y0, y1) of a scene and write them as a
 * partial image of the PPM family (see franja-worker(1)). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fbin.h"
#include "image.h"
#include "pathtrace.h"
#include "quick.h"
#ifndef FRANJA_NO_JSON
#include "scene_json.h"
#endif

#define FRANJA_VERSION "0.1.0"

static const char usage[] =
    "usage: franja-worker --scene FILE --rows Y0:Y1 [--spp N] [--size WxH]\n"
    "                     [--format pf|ppm16|ppm8] [-o FILE|-]\n"
    "       franja-worker --scene FILE --check\n"
    "       franja-worker --help | --version\n"
    "\n"
    "Renders rows Y0 (inclusive) to Y1 (exclusive) of a scene and writes them as a\n"
    "partial image: PF (linear float PFM, the default), or P6 16-bit / 8-bit sRGB.\n"
    "\n"
    "  --scene FILE   binary scene (.fbin, from `franja compile`) or JSON scene\n"
    "  --rows Y0:Y1   rows of the full image, 0 <= Y0 < Y1 <= height\n"
    "  --spp N        samples per pixel (default: the scene's)\n"
    "  --size WxH     image size (default: the scene's)\n"
    "  --format F     pf, ppm16 or ppm8 (default pf)\n"
    "  -o FILE        output file, or - for standard output (default -)\n"
    "  --check        validate the scene and print its content hash\n";

static int parse_u32(const char *s, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || v > 0xffffffffUL || s[0] == '-' || s[0] == '+')
        return -1;
    *out = (uint32_t)v;
    return 0;
}

/* "A:B" or "AxB" into two integers. */
static int parse_pair(const char *s, char sep, uint32_t *a, uint32_t *b)
{
    const char *p = strchr(s, sep);
    char first[32];
    if (!p || (size_t)(p - s) >= sizeof first)
        return -1;
    memcpy(first, s, (size_t)(p - s));
    first[p - s] = 0;
    return parse_u32(first, a) < 0 || parse_u32(p + 1, b) < 0 ? -1 : 0;
}

static int load_scene(const char *path, fr_scene *s, fr_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return fr_fail(err, "%s: %s", path, strerror(errno));
    unsigned char magic[2] = {0, 0};
    size_t n = fread(magic, 1, 2, f);
    fclose(f);
    if (n == 2 && magic[0] == 0x89 && magic[1] == 'F')
        return fbin_load(path, s, err);
#ifdef FRANJA_NO_JSON
    return fr_fail(err, "%s: this worker reads binary scenes only; run `franja compile` first", path);
#else
    return scn_load_json(path, NULL, s, err);
#endif
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *rows = NULL, *out = "-", *fmt_name = "pf";
    uint32_t spp = 0, w = 0, h = 0;
    int check = 0, have_size = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int has_arg = i + 1 < argc;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--version")) {
            printf("franja-worker %s scene-format %d\n", FRANJA_VERSION, FBIN_VERSION);
            return 0;
        } else if (!strcmp(a, "--check")) {
            check = 1;
        } else if (!has_arg && (!strcmp(a, "--scene") || !strcmp(a, "--rows") || !strcmp(a, "--spp") ||
                                !strcmp(a, "--size") || !strcmp(a, "--format") || !strcmp(a, "-o"))) {
            fprintf(stderr, "franja-worker: %s needs a value\n", a);
            return 2;
        } else if (!strcmp(a, "--scene")) {
            scene_path = argv[++i];
        } else if (!strcmp(a, "--rows")) {
            rows = argv[++i];
        } else if (!strcmp(a, "--spp")) {
            if (parse_u32(argv[++i], &spp) < 0 || spp == 0 || spp > (1u << 20)) {
                fprintf(stderr, "franja-worker: --spp: expected an integer in [1, 1048576], got '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--size")) {
            if (parse_pair(argv[++i], 'x', &w, &h) < 0 || w == 0 || h == 0 || w > 65536 || h > 65536) {
                fprintf(stderr, "franja-worker: --size: expected WxH with 1 <= W,H <= 65536, got '%s'\n", argv[i]);
                return 2;
            }
            have_size = 1;
        } else if (!strcmp(a, "--format")) {
            fmt_name = argv[++i];
        } else if (!strcmp(a, "-o")) {
            out = argv[++i];
        } else {
            fprintf(stderr, "franja-worker: unknown argument '%s' (see --help)\n", a);
            return 2;
        }
    }
    img_format fmt;
    if (img_format_parse(fmt_name, &fmt) < 0) {
        fprintf(stderr, "franja-worker: --format: expected pf, ppm16 or ppm8, got '%s'\n", fmt_name);
        return 2;
    }
    if (!scene_path) {
        fprintf(stderr, "franja-worker: --scene is required (see --help)\n");
        return 2;
    }
    if (!rows && !check) {
        fprintf(stderr, "franja-worker: --rows is required (see --help)\n");
        return 2;
    }
    uint32_t y0 = 0, y1 = 0;
    if (rows && parse_pair(rows, ':', &y0, &y1) < 0) {
        fprintf(stderr, "franja-worker: --rows: expected Y0:Y1 (two integers), got '%s'\n", rows);
        return 2;
    }

    fr_scene scene;
    fr_error err;
    if (load_scene(scene_path, &scene, &err) < 0) {
        fprintf(stderr, "franja-worker: %s\n", err.msg);
        return 1;
    }
    char hex[17];
    fbin_hash_hex(scene.hash, hex);
    if (check) {
        printf("%s\n", hex);
        scn_free(&scene);
        return 0;
    }
    if (have_size) {
        scene.settings.width = w;
        scene.settings.height = h;
    }
    if (spp)
        scene.settings.spp = spp;
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
    int to_stdout = !strcmp(out, "-");
    if (to_stdout && isatty(STDOUT_FILENO)) {
        fprintf(stderr, "franja-worker: refusing to write an image to a terminal; use -o FILE or a pipe\n");
        scn_free(&scene);
        return 2;
    }
    size_t n = (size_t)scene.settings.width * (y1 - y0) * 3;
    float *rgb = malloc(n * sizeof *rgb);
    if (!rgb) {
        fprintf(stderr, "franja-worker: out of memory for %zu pixels\n", n / 3);
        scn_free(&scene);
        return 1;
    }
    pt_render_rows(&scene, PT_MIS, y0, y1, rgb);

    img_partial_info info = {scene.hash, y0, y1, scene.settings.spp, scene.settings.width, scene.settings.height};
    FILE *f = to_stdout ? stdout : fopen(out, "wb");
    int rc = 0;
    if (!f) {
        fprintf(stderr, "franja-worker: %s: %s\n", out, strerror(errno));
        rc = 1;
    } else if (img_write(f, fmt, &info, rgb, &err) < 0) {
        fprintf(stderr, "franja-worker: %s: %s\n", to_stdout ? "standard output" : out, err.msg);
        rc = 1;
    }
    if (f && !to_stdout && fclose(f) != 0 && rc == 0) {
        fprintf(stderr, "franja-worker: %s: %s\n", out, strerror(errno));
        rc = 1;
    }
    if (rc && !to_stdout)
        remove(out);
    free(rgb);
    scn_free(&scene);
    return rc;
}
