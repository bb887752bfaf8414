/* fuzz_args.c -- libFuzzer target for the readers of command-line and
 * environment values.  The input's first byte picks the reader, the rest
 * is the value (up to its first NUL), or for 5 and 6 a command line (its
 * words separated by NUL bytes):
 *
 *   0  --frames (framelist_parse), then the frames put into a '#' pattern
 *   1  a '#' file-name pattern (framelist_subst) into buffers of many sizes
 *   2  --crop (crop_parse, crop_check against a few image sizes)
 *   3  the option values of opt.h (opt_uint, opt_float, opt_fraction,
 *      opt_size, opt_scale, opt_duration, opt_choice) and the scaled size
 *      and aspect note made from them
 *   4  an unknown option (opt_suggest) and a scene's name (opt_default_output)
 *   5  a worker's command line (proto_parse_args)
 *   6  a franja subcommand's options (opt_next with render-like options)
 *   7  SLURM_JOB_CPUS_PER_NODE (slurm_parse_cpus; the value's first byte
 *      gives the node count), --size (proto_parse_size), a format and an
 *      integrator name, a cache= size (hosts_parse_size)
 *
 * Messages that the readers print go to /dev/null. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crop.h"
#include "framelist.h"
#include "transport/hosts.h"
#include "opt.h"
#include "protocol.h"
#include "transport/slurm.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static FILE *devnull;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    devnull = fopen("/dev/null", "w");
    if (!devnull) {
        fprintf(stderr, "fuzz_args: cannot open /dev/null\n");
        exit(1);
    }
    return 0;
}

static void frames(const char *v)
{
    frame_list l;
    fr_error err;
    if (framelist_parse(v, &l, &err) == 0) {
        if (l.n == 0 || l.n > FRAMES_MAX)
            abort();
        char name[64];
        for (size_t i = 0; i < l.n; i++) {
            if (l.v[i] > FRAMES_MAX_NUMBER)
                abort();
            if (i < 16 && framelist_subst("f.####.json", l.v[i], name, sizeof name))
                abort();
        }
        framelist_free(&l);
    } else if (l.v || l.n) {
        abort();
    }
}

static void pattern(const char *v)
{
    static const uint32_t numbers[] = {0, 7, 4096, FRAMES_MAX_NUMBER};
    char buf[300];
    for (size_t cap = 1; cap <= sizeof buf; cap += cap < 40 ? 1 : 37)
        for (size_t k = 0; k < sizeof numbers / sizeof *numbers; k++)
            if (framelist_subst(v, numbers[k], buf, cap) == 0 && strlen(buf) >= cap)
                abort();
    (void)framelist_is_pattern(v);
}

static void crop(const char *v)
{
    crop_window c;
    fr_error err;
    if (crop_parse(v, &c, &err) == 0) {
        if (c.x0 >= c.x1 || c.y0 >= c.y1)
            abort();
        static const uint32_t sizes[][2] = {{1, 1}, {64, 48}, {65536, 65536}};
        for (size_t i = 0; i < 3; i++)
            if (crop_check(&c, sizes[i][0], sizes[i][1], &err) == 0 &&
                (c.x1 > sizes[i][0] || c.y1 > sizes[i][1]))
                abort();
    }
}

static void values(const char *v)
{
    uint32_t u, w, h;
    float f;
    double scale = 0, secs;
    static const char *const choices[] = {"none", "filmic", NULL};
    (void)opt_uint("fuzz", "--n", v, 1, 1000000, &u);
    if (opt_float("fuzz", "--x", v, -64, 64, &f) == 0 && !(f >= -64 && f <= 64))
        abort();
    if (opt_fraction("fuzz", "--e", v, &f) == 0 && !(f > 0 && f <= 1))
        abort();
    if (opt_scale("fuzz", "--scale", v, &scale) == 0 && !(scale > 0 && scale <= OPT_SCALE_MAX))
        abort();
    if (opt_duration("fuzz", "--t", v, &secs) == 0 && !(secs > 0 && secs <= OPT_DURATION_MAX))
        abort();
    (void)opt_choice("fuzz", "--c", v, choices);
    if (opt_size("fuzz", "--size", v, &w, &h) == 0) {
        char note[512];
        (void)opt_aspect_note(w, h, 640, 480, note, sizeof note);
        if (scale > 0 && (opt_scaled(w, scale) < 1 || opt_scaled(h, scale) < 1))
            abort();
    }
}

static void names(const char *v)
{
    static const struct option longopts[] = {
        {"spp", required_argument, NULL, 's'},      {"size", required_argument, NULL, 'S'},
        {"hosts", required_argument, NULL, 'H'},    {"tonemap", required_argument, NULL, 'T'},
        {"exposure", required_argument, NULL, 'E'}, {"resume", no_argument, NULL, 'r'},
        {"fresh", no_argument, NULL, 'f'},          {NULL, 0, NULL, 0},
    };
    char near[80], out[64];
    if (opt_suggest(v, "ho:j:", longopts, near, sizeof near) == 0 && strlen(near) >= sizeof near)
        abort();
    if (opt_default_output(v, ".png", out, sizeof out) == 0 && (strlen(out) < 5 || strchr(out, '/')))
        abort();
}

/* Splits text[0..len) at NUL bytes into argv[1..], argv[0] "prog". */
static int words(char *text, size_t len, char **argv, int max)
{
    int argc = 0;
    argv[argc++] = "prog";
    for (size_t i = 0; i < len && argc < max - 1;) {
        argv[argc++] = text + i;
        i += strlen(text + i) + 1;
    }
    argv[argc] = NULL;
    return argc;
}

static void worker_line(char *text, size_t len)
{
    char *argv[34];
    int argc = words(text, len, argv, 34);
    proto_request r;
    fr_error err;
    if (proto_parse_args(argc, argv, &r, &err) == 0 && r.mode == PROTO_RENDER) {
        if (!r.slab.scene || (r.slab.spp > PROTO_MAX_SPP) || (r.slab.width > PROTO_MAX_SIZE))
            abort();
        /* What the coordinator would send for it. */
        proto_argv a;
        if (r.slab.y0 < r.slab.y1)
            (void)proto_slab_argv(&r.slab, &a, &err);
    }
}

static void command(char *text, size_t len)
{
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},          {"spp", required_argument, NULL, 's'},
        {"size", required_argument, NULL, 'S'},    {"spp-max", required_argument, NULL, 'M'},
        {"resume", no_argument, NULL, 'r'},        {"tonemap", required_argument, NULL, 'T'},
        {"overwrite", no_argument, NULL, 'w'},     {NULL, 0, NULL, 0},
    };
    char *argv[34];
    int argc = words(text, len, argv, 34);
    optind = 0;
    for (int guard = 0; guard < 64 && opt_next("fuzz", argc, argv, "ho:j:", longopts) != -1; guard++)
        ;
}

static void environment(const char *v)
{
    int cpus[256];
    fr_error err;
    int n = v[0] ? (unsigned char)v[0] % 256 : 1;
    if (n == 0)
        n = 1;
    if (slurm_parse_cpus(v + (v[0] != 0), n, cpus, &err) == 0)
        for (int i = 0; i < n; i++)
            if (cpus[i] < 1 || cpus[i] > HOSTS_MAX_CORES)
                abort();
    uint32_t w, h;
    if (proto_parse_size(v, &w, &h) == 0 && (w < 1 || h < 1 || w > PROTO_MAX_SIZE || h > PROTO_MAX_SIZE))
        abort();
    img_format fmt;
    int k;
    (void)img_format_parse(v, &fmt);
    (void)proto_integrator_parse(v, &k);
    uint64_t bytes;
    if (hosts_parse_size(v, &bytes) == 0 && (bytes < 1 || bytes > 1ull << 60))
        abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0)
        return 0;
    size_t len = size - 1;
    char *text = malloc(len + 1);
    if (!text)
        return 0;
    memcpy(text, data + 1, len);
    text[len] = 0;
    FILE *saved = stderr;
    stderr = devnull;
    switch (data[0] % 8) {
    case 0: frames(text); break;
    case 1: pattern(text); break;
    case 2: crop(text); break;
    case 3: values(text); break;
    case 4: names(text); break;
    case 5: worker_line(text, len); break;
    case 6: command(text, len); break;
    default: environment(text); break;
    }
    stderr = saved;
    free(text);
    return 0;
}
