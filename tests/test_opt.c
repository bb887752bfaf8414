/* test_opt.c -- the command-line helpers of coordinator/opt.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "opt.h"

static void default_output(const char *scene, const char *ext, const char *want)
{
    char buf[64];
    int rc = opt_default_output(scene, ext, buf, sizeof buf);
    if (!want)
        CHECK(rc == -1, "%s + %s: accepted as '%s'", scene, ext, rc ? "" : buf);
    else
        CHECK(rc == 0 && !strcmp(buf, want), "%s + %s: got '%s' (rc %d), want '%s'", scene, ext, rc ? "" : buf, rc,
              want);
}

static const struct option longopts[] = {
    {"spp", required_argument, NULL, 's'},      {"size", required_argument, NULL, 'S'},
    {"slab-rows", required_argument, NULL, 'r'}, {"resume", no_argument, NULL, 'R'},
    {"tonemap", required_argument, NULL, 't'},  {"help", no_argument, NULL, 'h'},
    {NULL, 0, NULL, 0},
};

static void suggest(const char *typed, const char *want)
{
    char buf[32];
    int rc = opt_suggest(typed, "o:j:h", longopts, buf, sizeof buf);
    if (!want)
        CHECK(rc == -1, "%s: suggested %s", typed, rc ? "" : buf);
    else
        CHECK(rc == 0 && !strcmp(buf, want), "%s: suggested '%s' (rc %d), want %s", typed, rc ? "" : buf, rc, want);
}

/* Runs opt_next over words (NULL-terminated) until it ends or fails; the
 * options it returned go to got ("s=8 R ..."), its messages to msg. */
static int parse(char **words, char *got, size_t cap, char *msg, size_t mcap, int *first_operand)
{
    int argc = 0;
    while (words[argc])
        argc++;
    fflush(stderr);
    int saved = dup(2);
    FILE *tmp = tmpfile();
    dup2(fileno(tmp), 2);
    got[0] = 0;
    optind = 0;
    int c, rc = 0;
    while ((c = opt_next("test", argc, words, "o:j:h", longopts)) != -1) {
        if (c == '?') {
            rc = -1;
            break;
        }
        size_t n = strlen(got);
        snprintf(got + n, cap - n, "%s%c%s%s", n ? " " : "", c, optarg ? "=" : "", optarg ? optarg : "");
    }
    *first_operand = optind;
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rewind(tmp);
    size_t k = fread(msg, 1, mcap - 1, tmp);
    msg[k] = 0;
    fclose(tmp);
    return rc;
}

static void options(void)
{
    char got[256], msg[512];
    int first;
    char *a[] = {"render", "--spp=8", "scene.json", "--size", "4x4", "-j2", "-o", "x.png", "--res", "--",
                 "--odd.json", NULL};
    CHECK(parse(a, got, sizeof got, msg, sizeof msg, &first) == 0, "parse failed: %s", msg);
    CHECK(!strcmp(got, "s=8 S=4x4 j=2 o=x.png R"), "options: got '%s'", got);
    /* The operands, after the options: -- ends them, even before a dash. */
    CHECK(first == 9 && !strcmp(a[9], "scene.json") && !strcmp(a[10], "--odd.json"), "operands from %d: %s %s",
          first, a[9], a[10]);

    char *b[] = {"render", "scene.json", "--samples", "8", NULL};
    CHECK(parse(b, got, sizeof got, msg, sizeof msg, &first) == -1, "--samples accepted");
    CHECK(strstr(msg, "unknown option '--samples'; did you mean --spp?") != NULL, "--samples: '%s'", msg);
    char *c[] = {"render", "--spp", NULL};
    CHECK(parse(c, got, sizeof got, msg, sizeof msg, &first) == -1, "--spp without a value accepted");
    CHECK(strstr(msg, "--spp needs a value") != NULL, "--spp alone: '%s'", msg);
    char *d[] = {"render", "--s", "1", NULL};
    CHECK(parse(d, got, sizeof got, msg, sizeof msg, &first) == -1, "--s accepted");
    CHECK(strstr(msg, "--s is ambiguous: --spp, --size, --slab-rows") != NULL, "--s: '%s'", msg);
    char *e[] = {"render", "-x", NULL};
    CHECK(parse(e, got, sizeof got, msg, sizeof msg, &first) == -1, "-x accepted");
    CHECK(strstr(msg, "unknown option '-x'") != NULL, "-x: '%s'", msg);
    char *f[] = {"render", "--tonemap=filmic", "--resume=yes", NULL};
    CHECK(parse(f, got, sizeof got, msg, sizeof msg, &first) == -1, "--resume=yes accepted");
    CHECK(strstr(msg, "--resume takes no value") != NULL, "--resume=yes: '%s'", msg);
}

static void values(void)
{
    uint32_t u, w, h;
    float x;
    static const char *const curves[] = {"none", "filmic", NULL};
    FILE *null = freopen("/dev/null", "w", stderr);
    CHECK(opt_uint("t", "--spp", "8", 1, 10, &u) == 0 && u == 8, "8 in 1..10");
    CHECK(opt_uint("t", "--spp", "0", 1, 10, &u) == -1, "0 in 1..10");
    CHECK(opt_uint("t", "--spp", "11", 1, 10, &u) == -1, "11 in 1..10");
    CHECK(opt_uint("t", "--spp", "-1", 1, 10, &u) == -1, "-1 in 1..10");
    CHECK(opt_uint("t", "--spp", "8x", 1, 10, &u) == -1, "8x in 1..10");
    CHECK(opt_float("t", "--exposure", "-1.5", -64, 64, &x) == 0 && x == -1.5f, "-1.5 in -64..64");
    CHECK(opt_float("t", "--exposure", "65", -64, 64, &x) == -1, "65 in -64..64");
    CHECK(opt_float("t", "--exposure", "nan", -64, 64, &x) == -1, "nan in -64..64");
    CHECK(opt_float("t", "--exposure", "", -64, 64, &x) == -1, "empty number");
    CHECK(opt_size("t", "--size", "640x480", &w, &h) == 0 && w == 640 && h == 480, "640x480");
    CHECK(opt_size("t", "--size", "64", &w, &h) == -1, "64 as a size");
    CHECK(opt_choice("t", "--tonemap", "filmic", curves) == 1, "filmic");
    CHECK(opt_choice("t", "--tonemap", "aces", curves) == -1, "aces");
    CHECK(opt_fraction("t", "--noise-threshold", "0.05", &x) == 0 && x == 0.05f, "0.05 in (0, 1]");
    CHECK(opt_fraction("t", "--noise-threshold", "1", &x) == 0 && x == 1.0f, "1 in (0, 1]");
    CHECK(opt_fraction("t", "--noise-threshold", "0", &x) == -1, "0 in (0, 1]");
    CHECK(opt_fraction("t", "--noise-threshold", "1.5", &x) == -1, "1.5 in (0, 1]");
    CHECK(opt_fraction("t", "--noise-threshold", "nan", &x) == -1, "nan in (0, 1]");
    CHECK(opt_fraction("t", "--noise-threshold", "2E-144", &x) == -1, "2E-144 (0 as a float: not given) in (0, 1]");
    CHECK(opt_fraction("t", "--noise-threshold", "1e-45", &x) == 0 && x > 0.0f, "1e-45 (the least float) in (0, 1]");
    double sc;
    CHECK(opt_scale("t", "--scale", "50%", &sc) == 0 && sc == 0.5, "50%%");
    CHECK(opt_scale("t", "--scale", "0.25", &sc) == 0 && sc == 0.25, "0.25");
    CHECK(opt_scale("t", "--scale", "400%", &sc) == 0 && sc == 4.0, "400%%");
    static const char *const bad_scales[] = {"0", "0%", "-10%", "401%", "4.01", "%", "50 %", "50%x", "x", "", "inf"};
    for (size_t i = 0; i < sizeof bad_scales / sizeof *bad_scales; i++)
        CHECK(opt_scale("t", "--scale", bad_scales[i], &sc) == -1, "scale '%s' accepted", bad_scales[i]);
    static const struct {
        const char *v;
        double s;
    } durations[] = {{"90", 90}, {"90s", 90}, {"10m", 600}, {"1.5h", 5400}, {"0.5s", 0.5}, {"168h", 604800}};
    for (size_t i = 0; i < sizeof durations / sizeof *durations; i++) {
        double d = -1;
        CHECK(opt_duration("t", "--time-limit", durations[i].v, &d) == 0 && d == durations[i].s,
              "duration '%s': %g, want %g", durations[i].v, d, durations[i].s);
    }
    static const char *const bad_durations[] = {"0", "0s", "-1m", "10x", "1e3", "m", "", "inf", "nan", "10 m",
                                                "10mm", "168.1h", "0x10", "1,5h"};
    for (size_t i = 0; i < sizeof bad_durations / sizeof *bad_durations; i++) {
        double d;
        CHECK(opt_duration("t", "--time-limit", bad_durations[i], &d) == -1, "duration '%s' accepted",
              bad_durations[i]);
    }
    CHECK(opt_scaled(255, 0.5) == 128 && opt_scaled(101, 0.5) == 51, "50%% of 255, 101 (halves up)");
    CHECK(opt_scaled(512, 0.333) == 170 && opt_scaled(4, 0.1) == 1 && opt_scaled(3, 0.0001) == 1,
          "rounding and the 1-pixel floor");
    char note[400];
    CHECK(opt_aspect_note(64, 32, 512, 512, note, sizeof note) == 1 && strstr(note, "64x32 is 2:1 (2.000)") &&
          strstr(note, "512x512 is 1:1 (1.000)"), "aspect note: '%s'", note);
    CHECK(opt_aspect_note(256, 128, 1024, 512, note, sizeof note) == 0 && note[0] == 0, "same ratio: '%s'", note);
    CHECK(opt_aspect_note(1920, 1080, 640, 480, note, sizeof note) == 1 && strstr(note, "16:9") &&
          strstr(note, "4:3"), "16:9 against 4:3: '%s'", note);
    (void)null;
}

int main(void)
{
    suggest("--samples", "--spp");
    suggest("--szie", "--size");
    suggest("--slab-row", "--slab-rows");
    suggest("--resum", "--resume");
    suggest("--threads", "-j");
    suggest("--output=x.png", "-o");
    suggest("--xyzzy", NULL);
    suggest("--hosts", NULL);       /* a synonym of nothing here, and far from everything */
    options();
    values();
    default_output("scenes/cornell.json", ".png", "cornell.png");
    default_output("cornell.json", ".fbin", "cornell.fbin");
    default_output("/a/b.c/shot.GLTF", ".png", "shot.png");
    default_output("x/courtyard.glb", ".png", "courtyard.png");
    default_output("big.fbin", ".png", "big.png");
    default_output("archive.tar", ".png", "archive.tar.png");       /* not a scene extension: kept */
    default_output("dir/noext", ".fbin", "noext.fbin");
    default_output("a.json.json", ".png", "a.json.png");            /* one extension goes */
    default_output("scenes/.json", ".png", NULL);                    /* nothing left */
    default_output("scenes/", ".png", NULL);
    default_output("..", ".png", NULL);
    default_output("", ".png", NULL);
    default_output("a-very-long-scene-name-that-fills-the-buffer-to-the-brim-and-beyond.json", ".png", NULL);
    return check_done();
}
