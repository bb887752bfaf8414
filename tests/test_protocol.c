/* test_protocol.c -- the worker protocol (common/protocol.h): a slab
 * command line built by the coordinator reads back as the same slab in the
 * worker's parser; the limits hold on both sides; the version, --check and
 * probe answers are parsed strictly. */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "fbin.h"
#include "passes.h"
#include "protocol.h"
#include "scene.h"
#include "trace.h"

/* argv as a worker gets it: the program, then the built arguments. */
static int reparse(const proto_argv *a, proto_request *r, fr_error *err)
{
    char *argv[20] = {"franja-worker"};
    int argc = 1;
    for (int i = 0; a->argv[i]; i++)
        argv[argc++] = (char *)a->argv[i];
    return proto_parse_args(argc, argv, r, err);
}

static void test_round_trip(void)
{
    /* Metropolis normalisations: zeros, a subnormal, the largest float. */
    static const float norm[5] = {0.0f, 1e-40f, 0.00203f, 3.4028235e38f, 1.0f};
    static float deep[PROTO_MLT_DEPTHS];
    for (uint32_t d = 0; d < PROTO_MLT_DEPTHS; d++)
        deep[d] = 1.0f / (float)(d + 1);
    const proto_slab cases[] = {
        /* lifeline, integrator (1 + FR_INTEGRATOR_*, 0 for the scene's), noise threshold, sums, continue */
        {"scenes/a.fbin", 0, 1, 1, 1, 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},
        {"/x y/'quoted'.fbin", 17, 4096, 640, 4096, 64, IMG_PPM16, "out.ppm", 0, 1 + FR_INTEGRATOR_PATH, 0.0123f, 0, NULL, 0, NULL, 0},
        {"s.fbin", PROTO_MAX_SIZE - 1, PROTO_MAX_SIZE, PROTO_MAX_SIZE, PROTO_MAX_SIZE, PROTO_MAX_SPP, IMG_PPM8, "-", 0,
         1 + FR_INTEGRATOR_BDPT, 1.0f, 0, NULL, 0, NULL, 0},
        {"s.fbin", 3, 9, 0, 0, 0, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0}, /* the scene's size, samples, integrator, threshold */
        {"s.fbin", 3, 9, 0, 0, 0, IMG_PF, "-", 1, 2, 0.05f, 0, NULL, 0, NULL, 0}, /* --lifeline, --integrator bdpt, a threshold */
        {"s.fbin", 3, 9, 0, 0, 20, IMG_PF, "-", 1, 0, 0.0f, 1, "job dir/rows-3-9.pf", 0, NULL, 0}, /* --sums, --continue */
        {"s.fbin", 0, 4, 0, 0, 0, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, PASS_ALL, NULL, 0},                /* --passes, every one */
        {"s.fbin", 0, 4, 0, 0, 0, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 1u << PASS_NORMAL | 1u << PASS_MATERIAL_ID, NULL, 0},
        {"s.fbin", 0, 4, 0, 0, 0, IMG_PF, "-", 0, 3, 0.0f, 0, NULL, 0, norm, 5},         /* --mlt-norm */
        {"s.fbin", 0, 4, 0, 0, 0, IMG_PF, "-", 0, 3, 0.0f, 0, NULL, 0, deep, PROTO_MLT_DEPTHS}, /* the most depths */
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        const proto_slab *s = &cases[k];
        proto_argv a;
        proto_request r;
        fr_error err;
        int ok = proto_slab_argv(s, &a, &err) == 0;
        CHECK(ok, "case %zu: not built: %s", k, err.msg);
        if (!ok)
            continue;
        ok = reparse(&a, &r, &err) == 0;
        CHECK(ok, "case %zu: not parsed back: %s", k, err.msg);
        if (!ok)
            continue;
        CHECK(r.mode == PROTO_RENDER && r.have_rows, "case %zu: mode %d", k, (int)r.mode);
        CHECK(!strcmp(r.slab.scene, s->scene) && !strcmp(r.slab.out, s->out), "case %zu: scene or output changed", k);
        CHECK(r.slab.y0 == s->y0 && r.slab.y1 == s->y1, "case %zu: rows %u:%u", k, r.slab.y0, r.slab.y1);
        CHECK(r.slab.width == s->width && r.slab.height == s->height, "case %zu: size %ux%u", k, r.slab.width,
              r.slab.height);
        CHECK(r.slab.spp == s->spp && r.slab.format == s->format, "case %zu: spp %u format %d", k, r.slab.spp,
              (int)r.slab.format);
        CHECK(r.slab.lifeline == s->lifeline, "case %zu: lifeline %d", k, r.slab.lifeline);
        CHECK(r.slab.integrator == s->integrator, "case %zu: integrator %d, expected %d", k, r.slab.integrator,
              s->integrator);
        CHECK(r.slab.noise_threshold == s->noise_threshold, "case %zu: noise threshold %.9g", k,
              (double)r.slab.noise_threshold);
        CHECK(r.slab.sums == s->sums && (s->continue_from ? r.slab.continue_from &&
                                                               !strcmp(r.slab.continue_from, s->continue_from)
                                                         : !r.slab.continue_from),
              "case %zu: sums %d, continue %s", k, r.slab.sums, r.slab.continue_from ? r.slab.continue_from : "-");
        CHECK(r.slab.passes == s->passes, "case %zu: passes %#x, expected %#x", k, r.slab.passes, s->passes);
        CHECK(r.slab.mlt_depths == s->mlt_depths && !r.slab.mlt_norm == !s->mlt_norm &&
                  (!s->mlt_norm || !memcmp(r.slab.mlt_norm, s->mlt_norm, s->mlt_depths * sizeof *s->mlt_norm)),
              "case %zu: Metropolis normalisation of %u depths, expected the same bits of %u", k, r.slab.mlt_depths,
              s->mlt_depths);
    }
}

static void test_build_refuses(void)
{
    static const float one[PROTO_MLT_DEPTHS + 1] = {1.0f};
    const proto_slab bad[] = {
        {"s", 5, 5, 8, 8, 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},                     /* empty rows */
        {"s", 0, 9, 8, 8, 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},                     /* rows past the height */
        {"s", 0, 1, PROTO_MAX_SIZE + 1, 8, 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},    /* too wide */
        {"s", 0, 1, 8, 8, PROTO_MAX_SPP + 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},     /* too many samples */
        {"s", 0, 1, 8, 0, 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},                     /* half a size */
        {NULL, 0, 1, 8, 8, 1, IMG_PF, "-", 0, 0, 0.0f, 0, NULL, 0, NULL, 0},                    /* no scene */
        {"s", 0, 1, 8, 8, 1, IMG_PF, "-", 0, 1 + FR_INTEGRATORS, 0.0f, 0, NULL, 0, NULL, 0},   /* no such integrator */
        {"s", 0, 1, 8, 8, 1, IMG_PF, "-", 0, -1, 0.0f, 0, NULL, 0, NULL, 0},                   /* no such integrator */
        {"s", 0, 1, 8, 8, 1, IMG_PF, "-", 0, 0, 1.5f, 0, NULL, 0, NULL, 0},                     /* threshold above 1 */
        {"s", 0, 1, 8, 8, 1, IMG_PF, "-", 0, 0, -0.5f, 0, NULL, 0, NULL, 0},                    /* negative threshold */
        {"s", 0, 1, 8, 8, 1, IMG_PF, "-", 0, 3, 0.0f, 0, NULL, 0, one, 0},                     /* no depths */
        {"s", 0, 1, 8, 8, 1, IMG_PF, "-", 0, 3, 0.0f, 0, NULL, 0, one, PROTO_MLT_DEPTHS + 1},  /* too many */
    };
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        proto_argv a;
        fr_error err;
        CHECK(proto_slab_argv(&bad[k], &a, &err) < 0, "bad slab %zu was built", k);
    }
}

/* The worker's parser: usage errors name the option and the limit. */
static void test_parse_errors(void)
{
    struct {
        const char *args[8];
        const char *want;
    } cases[] = {
        {{"--scene", "s", "--rows", "0:1", "--spp", "0"}, "--spp: expected an integer in [1, 1048576]"},
        {{"--scene", "s", "--rows", "0:1", "--spp", "1048577"}, "--spp"},
        {{"--scene", "s", "--rows", "0:1", "--size", "65537x2"}, "--size: expected WxH with 1 <= W,H <= 65536"},
        {{"--scene", "s", "--rows", "0:1", "--size", "-2x2"}, "--size"},
        {{"--scene", "s", "--rows", "1-2"}, "--rows: expected Y0:Y1"},
        {{"--scene", "s", "--rows", "0:1", "--format", "png"}, "--format"},
        {{"--rows", "0:1"}, "--scene is required"},
        {{"--scene", "s"}, "--rows is required"},
        {{"--scene"}, "--scene needs a value"},
        {{"--scene", "s", "--rows", "0:1", "--bogus"}, "unknown argument '--bogus' (see --help)"},
        {{"--scene", "s", "--rows", "0:1", "--sp", "4"}, "unknown argument '--sp' (did you mean --spp? see --help)"},
        {{"--scene", "s", "--rows", "0:1", "--samples", "4"}, "'--samples' (did you mean --spp?"},
        {{"--scene", "s", "--rows", "0:1", "--output", "x"}, "'--output' (did you mean -o?"},
        {{"--scene", "s", "--rows", "0:1", "--integratr", "bdpt"}, "(did you mean --integrator?"},
        {{"--scene", "s", "--rows", "0:1", "--noise-treshold", "0.1"}, "(did you mean --noise-threshold?"},
        {{"--scene", "s", "--rows", "0:1", "--resume"}, "'--resume' (see --help)"},
        {{"--scene", "s", "--rows", "0:1", "stray"}, "unknown argument 'stray' (see --help)"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", ""}, "--mlt-norm: byte 0: expected a hex digit"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "3f80000"}, "--mlt-norm: byte 7: expected a hex digit"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "3F800000"}, "--mlt-norm: byte 1: expected a hex digit"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "3f800000;0"}, "--mlt-norm: byte 8: expected ',' or the end"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "3f800000,"}, "--mlt-norm: byte 9: expected a hex digit"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "00000000,bf800000"}, "--mlt-norm: byte 9: not a finite"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "7fc00000"}, "--mlt-norm: byte 0: not a finite value"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm", "7f800000"}, "--mlt-norm: byte 0: not a finite value"},
        {{"--scene", "s", "--rows", "0:1", "--mlt-norm"}, "--mlt-norm needs a value"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        char *argv[10] = {"franja-worker"};
        int argc = 1;
        for (int i = 0; cases[k].args[i]; i++)
            argv[argc++] = (char *)cases[k].args[i];
        proto_request r;
        fr_error err = {{0}};
        int rc = proto_parse_args(argc, argv, &r, &err);
        CHECK(rc < 0 && strstr(err.msg, cases[k].want), "case %zu: rc %d, message '%s', want '%s'", k, rc, err.msg,
              cases[k].want);
    }
    char *check[] = {"franja-worker", "--scene", "s.fbin", "--check"};
    proto_request r;
    fr_error err;
    CHECK(proto_parse_args(4, check, &r, &err) == 0 && r.mode == PROTO_CHECK && !r.have_rows, "--check not parsed");
    char *ver[] = {"franja-worker", "--bogus", "--version"};
    CHECK(proto_parse_args(3, ver, &r, &err) < 0, "an unknown option before --version was accepted");
    /* One value more than PROTO_MLT_DEPTHS: refused at the value past the last. */
    static char many[(PROTO_MLT_DEPTHS + 1) * 9];
    for (uint32_t d = 0; d <= PROTO_MLT_DEPTHS; d++)
        memcpy(many + 9 * d, d < PROTO_MLT_DEPTHS ? "3f800000," : "3f800000", 9);
    char *toomany[] = {"franja-worker", "--scene", "s", "--rows", "0:1", "--mlt-norm", many};
    CHECK(proto_parse_args(7, toomany, &r, &err) < 0 && strstr(err.msg, "byte 1152: more than 128 values"),
          "%u + 1 normalisation values: '%s'", PROTO_MLT_DEPTHS, err.msg);
    char *ver2[] = {"franja-worker", "--version", "--bogus"};
    CHECK(proto_parse_args(3, ver2, &r, &err) == 0 && r.mode == PROTO_VERSION, "--version first is not answered");
}

static void test_size(void)
{
    uint32_t w = 0, h = 0;
    CHECK(proto_parse_size("640x480", &w, &h) == 0 && w == 640 && h == 480, "640x480 read as %ux%u", w, h);
    CHECK(proto_parse_size("65536x1", &w, &h) == 0, "the largest width refused");
    const char *bad[] = {"0x4", "4x0", "65537x4", "4x", "x4", "4", "4x4x4", "+4x4", "4x-4", "", "99999999999x1"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
        CHECK(proto_parse_size(bad[k], &w, &h) < 0, "'%s' accepted as a size", bad[k]);
}

static void test_version(void)
{
    char line[128];
    proto_version_line("franja-worker", line, sizeof line);
    proto_version v;
    fr_error err;
    CHECK(proto_parse_version(line, &v, &err) == 0, "own line '%s' not parsed: %s", line, err.msg);
    CHECK(!strcmp(v.program, "franja-worker") && !strcmp(v.version, FRANJA_VERSION) && v.scene_format == FBIN_VERSION,
          "parsed '%s' as %s %s %d", line, v.program, v.version, v.scene_format);
    const char *bad[] = {"franja-worker 0.1.0", "franja-worker 0.1.0 scene-format", "franja-worker 0.1.0 scene-format x",
                         "franja-worker 0.1.0 scene-format 4 extra", "", "scene-format 4"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
        CHECK(proto_parse_version(bad[k], &v, &err) < 0, "'%s' accepted as a version line", bad[k]);
}

static void test_check_answer(void)
{
    uint64_t h = 0;
    fr_error err;
    CHECK(proto_parse_check("00ff00ff12345678\n", 17, &h, &err) == 0 && h == 0x00ff00ff12345678ull,
          "hash read as %016llx", (unsigned long long)h);
    const char *bad[] = {"00ff00ff1234567\n", "00ff00ff123456789\n", "00FF00FF12345678\n", "franja-worker: x\n",
                         "00ff00ff12345678\nmore\n", ""};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
        CHECK(proto_parse_check(bad[k], strlen(bad[k]), &h, &err) < 0, "'%s' accepted as a hash", bad[k]);
}

static void test_probe_answer(void)
{
    proto_host ph;
    fr_error err;
    const char ok[] = "x86_64\nLinux\n16\nfranja-worker 0.1.0 scene-format 4\n";
    CHECK(proto_parse_probe(ok, strlen(ok), &ph, &err) == 0, "probe answer refused: %s", err.msg);
    CHECK(!strcmp(ph.arch, "x86_64") && !strcmp(ph.os, "Linux") && ph.cores == 16 &&
              !strcmp(ph.version, "franja-worker 0.1.0 scene-format 4"),
          "probe read as %s %s %d '%s'", ph.arch, ph.os, ph.cores, ph.version);
    CHECK(ph.walk[0] == 0, "a walk read from an answer without one: '%s'", ph.walk);
    /* The walk line that follows the version line in a worker's --version. */
    char withwalk[256] = "x86_64\nLinux\n16\nfranja-worker 0.1.0 scene-format 4\n", line[128];
    proto_walk_line(line, sizeof line);
    snprintf(withwalk + strlen(withwalk), sizeof withwalk - strlen(withwalk), "%s\n", line);
    CHECK(proto_parse_probe(withwalk, strlen(withwalk), &ph, &err) == 0, "probe answer with '%s' refused: %s", line,
          err.msg);
    CHECK(!strcmp(ph.walk, trace_walk_name(trace_walk())) && !strcmp(ph.version, "franja-worker 0.1.0 scene-format 4"),
          "'%s' read as walk '%s', version '%s'", line, ph.walk, ph.version);
    CHECK(strstr(line, "portable") != NULL, "the walk line '%s' does not list the portable walk", line);
    const char *bad[] = {"x86_64\nLinux\n16\n", "x86_64\nLinux\n0\nv\n", "x86_64\nLinux\nmany\nv\n",
                         "a-very-long-architecture-name-beyond-32\nLinux\n2\nv\n"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
        CHECK(proto_parse_probe(bad[k], strlen(bad[k]), &ph, &err) < 0, "probe answer %zu accepted", k);
    CHECK(strstr(PROTO_PROBE_SCRIPT, "\"$0\" --version") != NULL, "the probe does not run its $0 --version");
    /* An absurd processor count is clamped, and what the host said kept. */
    const char many[] = "x86_64\nLinux\n2000000000\nv\n";
    CHECK(proto_parse_probe(many, strlen(many), &ph, &err) == 0, "2000000000 processors refused: %s", err.msg);
    CHECK(ph.cores == PROTO_MAX_CORES && ph.cores_reported == 2000000000u, "2000000000 processors read as %d (%u)",
          ph.cores, ph.cores_reported);
    /* Control characters from the host become '?'. */
    const char esc[] = "x86\033[2J\nLin\007ux\n2\nfranja-worker \033]0;t\a 1 scene-format 4\r\n";
    CHECK(proto_parse_probe(esc, strlen(esc), &ph, &err) == 0, "probe with escapes refused: %s", err.msg);
    CHECK(!strcmp(ph.arch, "x86?[2J") && !strcmp(ph.os, "Lin?ux") &&
              !strcmp(ph.version, "franja-worker ?]0;t? 1 scene-format 4?"),
          "escapes kept: '%s' '%s' '%s'", ph.arch, ph.os, ph.version);
}

int main(void)
{
    test_round_trip();
    test_build_refuses();
    test_parse_errors();
    test_size();
    test_version();
    test_check_answer();
    test_probe_answer();
    return check_done();
}
