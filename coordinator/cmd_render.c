/* cmd_render.c -- `franja render`: compile if needed, get the hosts ready,
 * schedule the slabs, stitch, tone-map once and write the image. */
#include "cmd.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bdpt.h"
#include "cli.h"
#include "opt.h"
#include "clock.h"
#include "cmd_frames.h"
#include "cluster.h"
#include "compile.h"
#include "compile_child.h"
#include "crop.h"
#include "fbin.h"
#include "jobdir.h"
#include "joblock.h"
#include "monitor.h"
#include "output.h"
#include "preview.h"
#include "progress.h"
#include "protocol.h"
#include "quick.h"
#include "sched.h"
#include "statusline.h"
#include "tonemap.h"

static const char usage[] =
    "usage: franja render SCENE(.json|.gltf|.glb|.fbin) [-o OUT] [options]\n"
    "\n"
    "Renders SCENE on this machine's cores, on the hosts of a host table over SSH,\n"
    "or on the CPUs of a Slurm allocation, and writes OUT (.png .exr .tif .jpg .hdr\n"
    ".ppm .bmp .pfm, by extension).\n"
    "\n"
    "  -o OUT               output image (written atomically, only when complete;\n"
    "                       without -o, SCENE.png in the current directory)\n"
    "  --hosts FILE         host table (franja-hosts(5)); default: this machine\n"
    "  -j N                 worker processes (local: default one per core;\n"
    "                       with --hosts or --slurm: at most N per host)\n"
    "  --spp N              samples per pixel (default: the scene's)\n"
    "  --size WxH           image size (default: the scene's)\n"
    "  --scale S            image size as a fraction of the scene's: 50% or 0.5,\n"
    "                       above 0 and at most 400%; each side rounded to the\n"
    "                       nearest pixel, at least 1 (not with --size)\n"
    "  --crop X0:Y0:X1:Y1   render only the window [X0,X1) x [Y0,Y1) (pixels, y down\n"
    "                       from the top); the rest of the image is black\n"
    "  --crop-output        with --crop: write the window alone\n"
    "  --frames LIST        render the frames LIST (1-240, 1-240:2, 1,5,9) of an\n"
    "                       animation: # in SCENE, -o, --job and --preview stands\n"
    "                       for the zero-padded frame number (f.####.json)\n"
    "  --overwrite          with --frames: render frames whose output exists\n"
    "  --camera NAME        glTF scenes: the camera to use, by its node's or its\n"
    "                       own name (default: the first in the scene)\n"
    "  --integrator I       path or bdpt (default: the scene's, else path)\n"
    "  --noise-threshold E  adaptive sampling (path tracing): each pixel stops once\n"
    "                       the relative error of its mean is below E, in (0, 1]\n"
    "                       (default: the scene's, else off)\n"
    "  --exposure E         scale LDR outputs by 2^E before the sRGB curve\n"
    "                       (default: the scene's tonemap; HDR outputs .exr\n"
    "                       .hdr .pfm keep linear radiance)\n"
    "  --exr-half           .exr output: half floats (default: 32-bit floats)\n"
    "  --exr-compression C  .exr output: none, rle, zips, zip, piz, pxr24, b44, b44a,\n"
    "                       dwaa or dwab (default zip)\n"
    "  --jpeg-quality Q     .jpg output: quality 1..100 (default 98)\n"
    "  --reproducible       leave the render time and the hosts out of the\n"
    "                       output's metadata: equal pixels, equal files\n"
    "  --tonemap CURVE      none or filmic (default: the scene's, else none)\n"
    "  --time-limit T       render in passes over the whole image, each doubling\n"
    "                       the samples per pixel (1, 2, 4 ... up to --spp), and\n"
    "                       stop at T (90s, 10m, 1.5h; from the start of the\n"
    "                       command), writing the last complete pass\n"
    "  --resume             keep the finished slabs of an interrupted render; with\n"
    "                       a larger --spp, add samples to a job kept by --keep-job\n"
    "  --fresh              discard the finished slabs of an earlier render\n"
    "  --job DIR            job directory (default OUT.franja-job)\n"
    "  --keep-job           keep the job directory after success (with each\n"
    "                       pixel's sample sums, to add samples later)\n"
    "  --no-lock            use a job directory on a file system without locks\n"
    "  --slab-rows N        rows per slab (default: shrinking toward the end)\n"
    "  --retries N          attempts per slab before giving up (default 5)\n"
    "  --preview FILE       write the image so far to FILE (any output type) while\n"
    "                       rendering, rows not yet done as a grey checkerboard\n"
    "  --preview-every S    seconds between preview images (default 5)\n"
    "  --progress MODE      auto (a live line on a terminal, else plain lines) or\n"
    "                       json (also one JSON object a line on stdout, for\n"
    "                       wrapper tools) (default auto)\n"
    "  --monitor PORT       serve a live page of the render (image so far, hosts,\n"
    "                       ETA) on http://127.0.0.1:PORT/ (0: a free port, said\n"
    "                       on stderr); from another machine: ssh -L\n"
    CLI_SLURM_HELP;

static volatile sig_atomic_t stop_flag;

static void on_signal(int sig)
{
    (void)sig;
    stop_flag = 1;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && !strcasecmp(s + a - b, suffix);
}

typedef struct {
    const char *scene, *out, *hosts, *jobdir, *camera;
    uint32_t jobs, spp, width, height, slab_rows, retries;
    float exposure;
    int exposure_set;          /* --exposure given: overrides the scene's */
    const char *curve;         /* --tonemap, or NULL for the scene's */
    char out_buf[4096];        /* out when -o is omitted */
    const char *preview;       /* --preview FILE, or NULL */
    uint32_t preview_every;    /* seconds */
    int integrator;            /* 1 + FR_INTEGRATOR_*, 0 for the scene's */
    float noise_threshold;     /* --noise-threshold, 0 for the scene's */
    int json;                  /* --progress json */
    int crop, crop_output;     /* --crop given, --crop-output */
    iio_options io;            /* --exr-half, --exr-compression, --jpeg-quality */
    double scale;              /* --scale, 0 when not given */
    crop_window win;
    int monitor;               /* --monitor given */
    uint32_t monitor_port;
    int resume, keep_job, fresh, no_lock;
    const char *frames;        /* --frames LIST, or NULL */
    int overwrite;             /* --overwrite */
    int reproducible;          /* --reproducible: no render time or hosts in the metadata */
    double time_limit;         /* --time-limit, seconds; 0 when not given */
    tr_options tr;
    cli_slurm slurm;
} render_args;

/* render's own options (getopt_long values). */
enum {
    OPT_SPP = CLI_OPT_OWN, OPT_SIZE, OPT_CAMERA, OPT_EXPOSURE, OPT_TONEMAP, OPT_RESUME, OPT_FRESH, OPT_JOB,
    OPT_KEEP_JOB, OPT_NO_LOCK, OPT_SLAB_ROWS, OPT_RETRIES, OPT_PREVIEW, OPT_PREVIEW_EVERY,
    OPT_INTEGRATOR, OPT_PROGRESS, OPT_NOISE, OPT_MONITOR, OPT_CROP, OPT_CROP_OUTPUT,
    OPT_EXR_HALF, OPT_EXR_COMPRESSION, OPT_JPEG_QUALITY, OPT_SCALE, OPT_FRAMES, OPT_OVERWRITE, OPT_TIME_LIMIT,
    OPT_REPRODUCIBLE
};

/* --reproducible's DateTime: SOURCE_DATE_EPOCH when it is a number of
 * seconds (the convention of reproducible builds), else 0 (1970). */
static long long reproducible_epoch(void)
{
    const char *v = getenv("SOURCE_DATE_EPOCH");
    char *end;
    long long e = v && *v ? strtoll(v, &end, 10) : 0;
    return v && *v && !*end ? e : 0;
}

/* Returns 0 to go on, 1 when done (help), 2 on a usage error. */
static int parse(int argc, char **argv, render_args *a)
{
    static const struct option longopts[] = {
        CLI_COMMON_LONGOPTS,
        CLI_SLURM_LONGOPTS,
        {"spp", required_argument, NULL, OPT_SPP},
        {"size", required_argument, NULL, OPT_SIZE},
        {"camera", required_argument, NULL, OPT_CAMERA},
        {"exposure", required_argument, NULL, OPT_EXPOSURE},
        {"tonemap", required_argument, NULL, OPT_TONEMAP},
        {"resume", no_argument, NULL, OPT_RESUME},
        {"fresh", no_argument, NULL, OPT_FRESH},
        {"job", required_argument, NULL, OPT_JOB},
        {"keep-job", no_argument, NULL, OPT_KEEP_JOB},
        {"no-lock", no_argument, NULL, OPT_NO_LOCK},
        {"slab-rows", required_argument, NULL, OPT_SLAB_ROWS},
        {"retries", required_argument, NULL, OPT_RETRIES},
        {"preview", required_argument, NULL, OPT_PREVIEW},
        {"preview-every", required_argument, NULL, OPT_PREVIEW_EVERY},
        {"integrator", required_argument, NULL, OPT_INTEGRATOR},
        {"progress", required_argument, NULL, OPT_PROGRESS},
        {"noise-threshold", required_argument, NULL, OPT_NOISE},
        {"monitor", required_argument, NULL, OPT_MONITOR},
        {"crop", required_argument, NULL, OPT_CROP},
        {"crop-output", no_argument, NULL, OPT_CROP_OUTPUT},
        {"exr-half", no_argument, NULL, OPT_EXR_HALF},
        {"exr-compression", required_argument, NULL, OPT_EXR_COMPRESSION},
        {"jpeg-quality", required_argument, NULL, OPT_JPEG_QUALITY},
        {"scale", required_argument, NULL, OPT_SCALE},
        {"reproducible", no_argument, NULL, OPT_REPRODUCIBLE},
        {"frames", required_argument, NULL, OPT_FRAMES},
        {"overwrite", no_argument, NULL, OPT_OVERWRITE},
        {"time-limit", required_argument, NULL, OPT_TIME_LIMIT},
        {NULL, 0, NULL, 0},
    };
    static const char *const curves[] = {"none", "filmic", NULL};
    static const char *const progress[] = {"auto", "json", NULL};
    static const char cmd[] = "render";
    memset(a, 0, sizeof *a);
    a->retries = 5;
    a->preview_every = 5;
    cli_transport_defaults(&a->tr);
    int c, bad = 0;
    optind = 0;
    while (!bad && (c = opt_next(cmd, argc, argv, "ho:j:", longopts)) != -1) {
        const char *v = optarg;
        switch (c) {
        case '?':
            return 2;
        case 'o':
            a->out = v;
            break;
        case 'j':
            bad = opt_uint(cmd, "-j", v, 1, HOSTS_MAX_CORES, &a->jobs);
            break;
        case OPT_SPP:
            bad = opt_uint(cmd, "--spp", v, 1, PROTO_MAX_SPP, &a->spp);
            break;
        case OPT_SIZE:
            bad = opt_size(cmd, "--size", v, &a->width, &a->height);
            break;
        case OPT_SCALE:
            bad = opt_scale(cmd, "--scale", v, &a->scale);
            break;
        case OPT_CAMERA:
            a->camera = v;
            break;
        case OPT_EXPOSURE:
            bad = opt_float(cmd, "--exposure", v, -64, 64, &a->exposure);
            a->exposure_set = 1;
            break;
        case OPT_TONEMAP:
            bad = opt_choice(cmd, "--tonemap", v, curves) < 0;
            a->curve = v;
            break;
        case OPT_RESUME:
            a->resume = 1;
            break;
        case OPT_FRESH:
            a->fresh = 1;
            break;
        case OPT_JOB:
            a->jobdir = v;
            break;
        case OPT_KEEP_JOB:
            a->keep_job = 1;
            break;
        case OPT_NO_LOCK:
            a->no_lock = 1;
            break;
        case OPT_REPRODUCIBLE:
            a->reproducible = 1;
            break;
        case OPT_SLAB_ROWS:
            bad = opt_uint(cmd, "--slab-rows", v, 1, PROTO_MAX_SIZE, &a->slab_rows);
            break;
        case OPT_RETRIES:
            bad = opt_uint(cmd, "--retries", v, 1, 1000, &a->retries);
            break;
        case OPT_PREVIEW:
            a->preview = v;
            break;
        case OPT_INTEGRATOR: {
            static const char *const integrators[] = {"path", "bdpt", NULL};
            int k = opt_choice(cmd, "--integrator", v, integrators);
            bad = k < 0 || proto_integrator_parse(v, &k) < 0;
            a->integrator = 1 + k;
            break;
        }
        case OPT_NOISE:
            bad = opt_fraction(cmd, "--noise-threshold", v, &a->noise_threshold);
            break;
        case OPT_PROGRESS: {
            int k = opt_choice(cmd, "--progress", v, progress);
            bad = k < 0;
            a->json = k == 1;
            break;
        }
        case OPT_MONITOR:
            bad = opt_uint(cmd, "--monitor", v, 0, 65535, &a->monitor_port);
            a->monitor = 1;
            break;
        case OPT_CROP: {
            fr_error e;
            bad = crop_parse(v, &a->win, &e);
            if (bad)
                fprintf(stderr, "franja render: --crop: %s\n", e.msg);
            a->crop = 1;
            break;
        }
        case OPT_CROP_OUTPUT:
            a->crop_output = 1;
            break;
        case OPT_EXR_HALF:
            a->io.half = 1;
            break;
        case OPT_EXR_COMPRESSION: {
            static const char *const kinds[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a",
                                                "dwaa", "dwab", NULL};
            bad = opt_choice(cmd, "--exr-compression", v, kinds) < 0;
            a->io.compression = v;
            break;
        }
        case OPT_JPEG_QUALITY: {
            uint32_t q = 0;
            bad = opt_uint(cmd, "--jpeg-quality", v, 1, 100, &q);
            a->io.quality = (int)q;
            break;
        }
        case OPT_FRAMES:
            a->frames = v;
            break;
        case OPT_OVERWRITE:
            a->overwrite = 1;
            break;
        case OPT_TIME_LIMIT:
            bad = opt_duration(cmd, "--time-limit", v, &a->time_limit);
            break;
        case OPT_PREVIEW_EVERY:
            bad = opt_uint(cmd, "--preview-every", v, 1, 3600, &a->preview_every);
            break;
        default: {
            int r = cli_slurm_opt(cmd, c, v, &a->slurm);
            if (r == CLI_OTHER)
                r = cli_common_opt(cmd, c, v, usage, &a->tr, &a->hosts);
            if (r == CLI_HELP)
                return 1;
            bad = r != CLI_TAKEN;
        }
        }
    }
    if (bad)
        return 2;
    if (argc - optind > 1) {
        fprintf(stderr, "franja render: more than one scene ('%s' and '%s')\n", argv[optind], argv[optind + 1]);
        return 2;
    }
    a->scene = optind < argc ? argv[optind] : NULL;
    if (!a->scene) {
        fprintf(stderr, "franja render: a SCENE is required (see franja render --help)\n");
        return 2;
    }
    if (!a->out) {
        if (opt_default_output(a->scene, ".png", a->out_buf, sizeof a->out_buf)) {
            fprintf(stderr, "franja render: %s: cannot make an output name from it; give -o OUT\n", a->scene);
            return 2;
        }
        a->out = a->out_buf;
    }
    if (a->preview && !strcmp(a->preview, a->out)) {
        fprintf(stderr, "franja render: --preview %s is the output itself; name another file\n", a->preview);
        return 2;
    }
    if (a->scale > 0 && a->width) {
        fprintf(stderr, "franja render: --scale and --size exclude each other (one image size at a time)\n");
        return 2;
    }
    if (a->crop_output && !a->crop) {
        fprintf(stderr, "franja render: --crop-output needs --crop X0:Y0:X1:Y1\n");
        return 2;
    }
    if (a->overwrite && !a->frames) {
        fprintf(stderr, "franja render: --overwrite is for --frames (a single render always writes its output)\n");
        return 2;
    }
    if (a->resume && a->fresh) {
        fprintf(stderr, "franja render: --resume and --fresh exclude each other\n");
        return 2;
    }
    return cli_slurm_check("render", &a->slurm, a->hosts) ? 2 : 0;
}

static void print_warning(void *user, const char *msg)
{
    fprintf(stderr, "%s: warning: %s\n", (const char *)user, msg);
}

/* Gets the binary scene: loads an .fbin, or compiles a JSON scene into the
 * job directory.  *path receives the .fbin to ship. */
static int scene_binary(const render_args *a, const char *jobdir, char *path, size_t cap, fr_scene *sc,
                        fr_error *err)
{
    if (!ends_with(a->scene, ".json") && !compile_is_gltf(a->scene)) {
        if (a->camera)
            return fr_fail(err, "%s: --camera applies to glTF scenes (a compiled scene has its camera)", a->scene);
        snprintf(path, cap, "%s", a->scene);
        return fbin_load(path, sc, err);
    }
    if (mkdir(jobdir, 0755) && errno != EEXIST)
        return fr_fail(err, "%s: cannot create job directory: %s", jobdir, strerror(errno));
    snprintf(path, cap, "%s/scene.fbin", jobdir);
    /* What a compile of a render killed by SIGKILL left; the job lock
     * keeps any other compile out of this directory. */
    compile_child_sweep(path);
    /* In a child process, so that Ctrl-C stops a long compile at once. */
    compile_opts co = {a->camera, print_warning, (void *)"franja"};
    if (compile_child(a->scene, &co, path, &stop_flag, NULL, err))
        return -1;
    return fbin_load(path, sc, err);
}

/* The end of a run: how it ended first when it did not finish (ended:
 * "interrupted", "failed"), then what was rendered (rows_done of the
 * rows_asked this run had to render; samples/s over those rows), the
 * slabs, retries and second copies, and each host's share. */
static void summary(const sched_host *hs, int n, const job_spec *spec, const sched_stats *st, int rows_done,
                    int rows_asked, double wall, const char *ended)
{
    double samples = st->samples;
    double rate = wall > 0 ? samples / wall / 1e6 : 0.0;
    int slabs = 0;
    for (int i = 0; i < n; i++)
        slabs += hs[i].slabs;
    if (ended)
        fprintf(stderr, "franja: %s after %.2f s: %d of %d rows rendered (%ux%u at %u spp), %.2f Msamples/s over "
                "them; %d of %d slabs, %d retries", ended, wall, rows_done, rows_asked, spec->width, spec->height,
                spec->spp, rate, slabs, st->slabs, st->retries);
    else
        fprintf(stderr, "franja: %ux%u at %u spp in %.2f s: %.2f Msamples/s; %d slabs, %d retries", spec->width,
                spec->height, spec->spp, wall, rate, st->slabs, st->retries);
    /* Second copies of slow slabs run on idle slots only; the first
     * result wins.  Not failures: said only when there were some. */
    if (st->duplicates)
        fprintf(stderr, ", %d second cop%s of slow slabs on idle slots", st->duplicates,
                st->duplicates == 1 ? "y" : "ies");
    if (st->continued)
        fprintf(stderr, "; %d slab%s went on from kept sample sums", st->continued, st->continued == 1 ? "" : "s");
    if (st->fresh_instead)
        fprintf(stderr, " (%d attempt%s rendered every sample: the sums could not be sent)", st->fresh_instead,
                st->fresh_instead == 1 ? "" : "s");
    fputc('\n', stderr);
    if (n == 0)
        return;
    fprintf(stderr, "  %-16s %5s %6s %6s %8s %6s %8s  %s\n", "host", "slots", "slabs", "rows", "failures", "copies",
            "busy s", "state");
    for (int i = 0; i < n; i++) {
        const sched_host *h = &hs[i];
        if (!h->tr)
            continue; /* never ready: said when it was given up */
        fprintf(stderr, "  %-16s %5d %6d %6d %8d %6d %8.2f  %s%s\n", h->name, h->slots, h->slabs, h->rows,
                h->failures, h->duplicates, h->busy_s, h->dropped ? "dropped: " : "ok",
                h->dropped ? h->drop_reason : "");
    }
}

/* The scheduler's reports on stderr.  Progress: on a terminal a live line
 * four times a second; otherwise (a batch job's log) a plain line every
 * LOG_EVERY seconds and one at the end.  Events are log lines, except
 * accepted slabs (the progress shows them) and, on a terminal, second
 * copies. */
enum { LOG_EVERY = 10 };

typedef struct {
    int tty;
    const sched_host *hosts;
    int nhosts;
    const job_spec *spec;
    double last_draw;
    double t;                  /* the latest progress report */
    int done, total;
    int drawn;                 /* a live line is on screen */
    struct joiner *join;       /* hosts joining the render */
    pg_reporter *pg;           /* --progress json, or NULL */
    mon_server *mon;           /* --monitor, or NULL */
    int rows_before;           /* rows done before this run (resumed) */
    mon_host *mh;              /* nhosts entries for the monitor */
    char (*mstate)[320];       /* their state strings */
    struct anim_run *fx;     /* the frames of an animation run together, or NULL */
} reporter;

/* The frames of an animation run over one set of hosts (render_frames);
 * the scheduler's frame hooks. */
typedef struct anim_run anim_run;
static int rf_next(void *ctx, int frame, sched_frame *next, fr_error *err);
static int rf_stage(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                    size_t lease_cap, fr_error *err);
static int rf_done(void *ctx, int frame, fr_error *err);
static void rf_rendered(anim_run *fx, int frame, int host);

/* A host's event to the JSON stream and the monitor. */
static void host_event(reporter *r, const char *what, const char *host, uint32_t y0, uint32_t y1, double t,
                       const char *text)
{
    pg_event(r->pg, what, host, y0, y1, text);
    mon_event(r->mon, t, host, what, text);
}

static void clear_line(reporter *r)
{
    if (r->drawn) {
        fputs("\r\033[K", stderr);
        r->drawn = 0;
    }
}

static void on_event(void *ctx, const sched_event *ev)
{
    reporter *r = ctx;
    static const char *const what[] = {
        [SCHED_SLAB_DONE] = "done", [SCHED_SLAB_FAILED] = "failed", [SCHED_COPY] = "copy",
        [SCHED_HOST_DROPPED] = "dropped", [SCHED_HOST_SHRUNK] = "shrunk", [SCHED_HOST_RETRY] = "retry",
    };
    if (ev->kind != SCHED_SLAB_DONE && ev->host >= 0 && ev->host < r->nhosts)
        host_event(r, what[ev->kind], r->hosts[ev->host].name, ev->y0, ev->y1, ev->t, ev->text);
    if (ev->kind == SCHED_SLAB_DONE && r->fx)
        rf_rendered(r->fx, ev->frame, ev->host);
    if (ev->kind == SCHED_SLAB_DONE || (r->tty && ev->kind == SCHED_COPY))
        return;
    clear_line(r);
    fprintf(stderr, "franja: [%6.1fs] %s\n", ev->t, ev->text);
}

static void draw(reporter *r, int force)
{
    if (!force && r->t - r->last_draw < (r->tty ? 0.25 : LOG_EVERY))
        return;
    r->last_draw = r->t;
    char line[1024];
    sl_figures f = {r->t, r->done, r->total, (double)r->spec->width * r->spec->spp};
    sl_format(line, sizeof line, r->tty ? sl_columns(2) : 0, &f, r->hosts, r->nhosts);
    if (r->tty) {
        fprintf(stderr, "\r\033[K%s", line);
        fflush(stderr);
        r->drawn = 1;
    } else {
        fprintf(stderr, "franja: [%6.1fs] %s\n", r->t, line);
    }
}

/* The hosts' state for the monitor. */
static void monitor_update(reporter *r)
{
    if (!r->mon)
        return;
    for (int i = 0; i < r->nhosts; i++) {
        const sched_host *h = &r->hosts[i];
        if (h->pending)
            snprintf(r->mstate[i], sizeof r->mstate[i], "starting");
        else if (h->dropped)
            snprintf(r->mstate[i], sizeof r->mstate[i], "dropped: %s", h->drop_reason);
        else
            snprintf(r->mstate[i], sizeof r->mstate[i], "%s", h->running ? "rendering" : "idle");
        r->mh[i] = (mon_host){h->name, r->mstate[i], h->running, h->slots, h->rows, h->failures};
    }
    mon_progress(r->mon, r->t, r->rows_before + r->done, r->rows_before + r->total, r->rows_before, r->mh, r->nhosts);
}

static void on_progress(void *ctx, double t, int done, int total)
{
    reporter *r = ctx;
    r->t = t;
    r->done = done;
    r->total = total;
    draw(r, 0);
    monitor_update(r);
}

/* Hosts joining the render as they become ready (the scheduler's admit
 * hook): each is checked (version), given its slots and announced. */
typedef struct joiner {
    const render_args *a;
    cl_group *g;
    cl_host *cl;
    reporter *rep;
    int ready;                 /* hosts handed over ready */
} joiner;

/* Takes every host whose preparation has ended, waiting up to ms for the
 * first one. */
static void join_hosts(joiner *j, sched_host *sh, int ms)
{
    cl_host h;
    int i;
    while ((i = cl_next_ready(j->g, &h, ms)) >= 0) {
        ms = 0;
        j->cl[i] = h;
        sched_host *s = &sh[i];
        s->pending = 0;
        if (j->rep)
            clear_line(j->rep);
        if (j->cl[i].tr)
            cl_check_version(&j->cl[i]);
        if (!j->cl[i].tr) {
            fprintf(stderr, "franja: host %s is not used: %s\n", h.entry->name, j->cl[i].err.msg);
            if (j->rep) {
                char line[1200];
                snprintf(line, sizeof line, "host %s is not used: %s", h.entry->name, j->cl[i].err.msg);
                host_event(j->rep, "unused", h.entry->name, 0, 0, j->rep->t, line);
            }
            s->dropped = 1;
            snprintf(s->drop_reason, sizeof s->drop_reason, "%s", j->cl[i].err.msg);
            continue;
        }
        j->ready++;
        const render_args *a = j->a;
        int slots = h.entry->cores ? h.entry->cores : h.info.cores;
        if (!h.entry->cores && h.info.cores_reported > (uint32_t)h.info.cores)
            fprintf(stderr, "franja: host %s reports %u processors; using %d (give its cores in the host table "
                    "if it has more)\n", h.entry->name, h.info.cores_reported, h.info.cores);
        int table = a->hosts || a->slurm.on;
        if (a->jobs && (!table || slots > (int)a->jobs))
            slots = (int)a->jobs;
        s->tr = h.tr;
        s->slots = slots > 0 ? slots : 1;
        snprintf(s->scene, sizeof s->scene, "%s", h.scene);
        snprintf(s->lease, sizeof s->lease, "%s", h.lease);
        s->lease_t = clk_now();
        if ((table || !isatty(2)) && j->rep && j->rep->fx) /* each frame's scene is said as it is staged */
            fprintf(stderr, "franja: host %s: %s %s, %d slots, %s (%.2f s)\n", s->name, h.info.os, h.info.arch,
                    s->slots, h.info.version, h.ready_s);
        else if (table || !isatty(2))
            fprintf(stderr, "franja: host %s: %s %s, %d slots, %s, scene %s (%.2f s)\n", s->name, h.info.os,
                    h.info.arch, s->slots, h.info.version,
                    hosts_is_local(h.entry) ? "local" : h.uploaded ? "uploaded" : "already there", h.ready_s);
        if (j->rep) {
            char line[600];
            snprintf(line, sizeof line, "host %s ready: %s %s, %d slots (%.2f s)", s->name, h.info.os, h.info.arch,
                     s->slots, h.ready_s);
            host_event(j->rep, "ready", s->name, 0, 0, j->rep->t, line);
        }
    }
}

static void on_admit(void *ctx, sched_host *hosts, int nhosts)
{
    (void)nhosts;
    reporter *r = ctx;
    join_hosts(r->join, hosts, 0);
}

/* The passes of a render.  Without --time-limit there is one, to the
 * samples asked for.  With it, each pass brings every row the render needs
 * to twice the fewest samples kept for a row (1 at first; never fewer than
 * the most kept for a row; at most the samples asked for), adding samples
 * to the kept sums, and the image of each complete pass is kept in memory:
 * when the limit stops a pass, that image is written. */
typedef struct {
    const render_args *a;
    const char *jobdir;
    job_spec spec;             /* the pass being planned or run (spp) */
    uint32_t cap;              /* the samples per pixel asked for */
    int crop_rows;             /* only the rows of a's --crop window */
    unsigned char *have;       /* rows the pass does not render (done, or outside a crop) */
    uint32_t *base;            /* samples with sums that each row goes on from (job_scan) */
    int rows_job, rows_missing;
    int rows_kept;             /* rows the job directory holds at spec.spp, needed or not */
    double deadline;           /* clk_now() time of --time-limit; 0 = none */
    float *rgb;                /* --time-limit: the image of the last complete pass */
    unsigned char *scratch;    /* height bytes */
    uint32_t reached;          /* the samples per pixel of rgb; 0 = none yet */
    int npass;                 /* passes run */
    uint32_t stopped;          /* the samples per pixel of the pass the limit stopped; 0 = none */
    sched_stats total;         /* over the passes */
    const char *label;         /* an animation's frame: "frame N"; NULL otherwise */
} passes;

static int crop_stitch(const char *jobdir, const job_spec *spec, const crop_window *win, float *rgb,
                       unsigned char *have, fr_error *err);

/* Whether the render needs row y (a crop needs its window's). */
static int needed(const passes *ps, uint32_t y)
{
    return !ps->crop_rows || (y >= ps->a->win.y0 && y < ps->a->win.y1);
}

/* What a pass to spp samples per pixel renders: the rows the job
 * directory does not hold with spp samples, each from the most samples
 * kept for it with their sums. */
static int plan(passes *ps, uint32_t spp, fr_error *err)
{
    ps->spec.spp = spp;
    int sums = job_sums(&ps->spec);
    ps->rows_kept = job_scan(ps->jobdir, &ps->spec, ps->have, sums ? ps->base : NULL, &ps->a->tr.notes, err);
    if (ps->rows_kept < 0)
        return -1;
    if (!sums)
        memset(ps->base, 0, ps->spec.height * sizeof *ps->base);
    ps->rows_missing = 0;
    for (uint32_t y = 0; y < ps->spec.height; y++) {
        if (!needed(ps, y))
            ps->have[y] = 1; /* not rendered */
        ps->rows_missing += !ps->have[y];
    }
    return 0;
}

/* The fewest and the most samples per pixel kept for a needed row (with
 * their sums, or the samples asked for), from a plan to ps->cap. */
static void kept_range(const passes *ps, uint32_t *lo, uint32_t *hi)
{
    *lo = UINT32_MAX;
    *hi = 0;
    for (uint32_t y = 0; y < ps->spec.height; y++) {
        if (!needed(ps, y))
            continue;
        uint32_t k = ps->have[y] ? ps->cap : ps->base[y];
        *lo = k < *lo ? k : *lo;
        *hi = k > *hi ? k : *hi;
    }
    if (*lo == UINT32_MAX)
        *lo = ps->cap;
}

/* The samples per pixel of the next pass of a --time-limit render, 0 when
 * every needed row has the samples asked for. */
static int next_pass(passes *ps, uint32_t *spp, fr_error *err)
{
    if (plan(ps, ps->cap, err))
        return -1;
    uint32_t lo, hi;
    kept_range(ps, &lo, &hi);
    *spp = 0;
    if (lo >= ps->cap)
        return 0;
    uint32_t twice = lo == 0 ? 1 : lo > ps->cap / 2 ? ps->cap : 2 * lo;
    *spp = twice > hi ? twice : hi;
    return 0;
}

/* The image of the pass just planned and complete into ps->rgb. */
static int pass_image(passes *ps, fr_error *err)
{
    if (ps->crop_rows)
        return crop_stitch(ps->jobdir, &ps->spec, &ps->a->win, ps->rgb, ps->scratch, err);
    return job_stitch(ps->jobdir, &ps->spec, ps->rgb, &ps->a->tr.notes, err);
}

static void add_stats(sched_stats *to, const sched_stats *st)
{
    to->slabs += st->slabs;
    to->retries += st->retries;
    to->duplicates += st->duplicates;
    to->wall_s += st->wall_s;
    to->samples += st->samples;
    to->continued += st->continued;
    to->fresh_instead += st->fresh_instead;
    to->timed_out |= st->timed_out;
}

/* Connects the hosts and runs the slabs not yet in the job directory.  The
 * render starts as soon as one host is ready; the others join when they
 * are (a host that accepts a connection and never answers costs nothing
 * unless it is the only one).  With fx, ps is the first frame of an
 * animation, and the next frames follow over the same hosts (fx's hooks
 * stage each frame's scene and write each frame); fbin is then not used. */
static int run_slabs(const render_args *a, const hosts_table *table, const char *fbin, passes *ps,
                     pg_reporter *pg, mon_server *mon, char *used, size_t used_cap, anim_run *fx, fr_error *err)
{
    const job_spec *spec = &ps->spec;
    const char *jobdir = ps->jobdir;
    int rows_job = ps->rows_job, rows_missing = ps->rows_missing;
    int n = table->n;
    cl_host *cl = calloc((size_t)n, sizeof *cl);
    sched_host *sh = calloc((size_t)n, sizeof *sh);
    mon_host *mh = calloc((size_t)n, sizeof *mh);
    char(*mstate)[320] = calloc((size_t)n, sizeof *mstate);
    cl_group *g = NULL;
    if (cl && sh && mh && mstate) {
        for (int i = 0; i < n; i++)
            cl[i].entry = &table->v[i];
        g = cl_start(cl, n, &a->tr, fx ? NULL : fbin, spec->hash);
    }
    if (!g) {
        free(cl);
        free(sh);
        free(mh);
        free(mstate);
        return fr_fail(err, "out of memory");
    }
    for (int i = 0; i < n; i++) {
        sh[i].name = table->v[i].name;
        sh[i].pending = 1;
        sh[i].slots = table->v[i].cores; /* a guess for the slab size until it is ready */
    }
    reporter rep = {.tty = isatty(2), .hosts = sh, .nhosts = n, .spec = spec, .pg = pg, .mon = mon,
                    .rows_before = rows_job - rows_missing, .mh = mh, .mstate = mstate, .total = rows_missing,
                    .fx = fx};
    joiner j = {a, g, cl, &rep, 0};
    rep.join = &j;
    monitor_update(&rep);
    /* The first host (or the end of them all). */
    while (!j.ready && cl_pending(g)) {
        join_hosts(&j, sh, 1000);
        monitor_update(&rep);
    }
    int rc = 0;
    if (!j.ready)
        rc = fr_fail(err, "no host could be used (see the messages above)");
    if (rc == 0) {
        /* Hosts not ready yet count in the slab size with the slots of the
         * first ready one, unless the table says. */
        int guess = 1;
        for (int i = 0; i < n; i++)
            if (!sh[i].pending && !sh[i].dropped && sh[i].slots > guess)
                guess = sh[i].slots;
        for (int i = 0; i < n; i++)
            if (sh[i].pending && sh[i].slots < 1)
                sh[i].slots = guess;
        double t0 = clk_now();
        sched_stats st;
        memset(&ps->total, 0, sizeof ps->total);
        for (;;) {
            uint32_t spp = ps->cap;
            if (ps->deadline > 0) {
                if (next_pass(ps, &spp, err)) {
                    rc = -1;
                    break;
                }
                if (spp == 0)
                    break;
                if (ps->reached && clk_now() >= ps->deadline) {
                    ps->stopped = spp;
                    break;
                }
                if (plan(ps, spp, err)) {
                    rc = -1;
                    break;
                }
                ps->npass++;
                clear_line(&rep);
                fprintf(stderr, "franja: pass %d: %u samples per pixel, %d rows to render\n", ps->npass, spp,
                        ps->rows_missing);
                pg_pass(pg, ps->npass, spp);
            } else if (ps->npass++ > 0) {
                break;
            }
            rows_missing = ps->rows_missing;
            rep.total = rows_missing;
            rep.done = 0;
            rep.rows_before = rows_job - rows_missing;
            sched_params p = {.spec = *spec,
                              .jobdir = jobdir,
                              .have = ps->have,
                              .base = ps->base,
                              .sums = job_sums(spec),
                              /* The first pass of a --time-limit render
                               * always ends: it is the least image there is. */
                              .stop_at = ps->deadline > 0 && ps->reached ? ps->deadline : 0,
                              .slab_rows = (int)a->slab_rows,
                              .max_attempts = (int)a->retries,
                              .max_host_failures = 3,
                              .stop = &stop_flag,
                              /* An SSH channel closed (a losing copy, a dropped
                               * host, this process gone) ends the worker, even
                               * where signals do not reach it (worker/lifeline.h). */
                              .lifeline = !a->slurm.on,
                              .hooks = {.event = on_event, .progress = on_progress, .admit = on_admit, .ctx = &rep}};
            if (fx) {
                p.label = ps->label;
                p.hooks.next_frame = rf_next;
                p.hooks.stage = rf_stage;
                p.hooks.frame_done = rf_done;
            }
            rc = sched_run(&p, sh, n, &st, err);
            add_stats(&ps->total, &st);
            if (rc && st.timed_out && !stop_flag) {
                /* The pass in flight is given up; its finished slabs stay. */
                ps->stopped = spp;
                rc = 0;
                break;
            }
            if (rc || ps->deadline <= 0)
                break;
            if (pass_image(ps, err)) {
                rc = -1;
                break;
            }
            ps->reached = spp;
            draw(&rep, 1);
            clear_line(&rep);
            fprintf(stderr, "franja: pass %d done: %u samples per pixel at %.2f s\n", ps->npass, spp,
                    clk_now() - t0);
        }
        draw(&rep, 1);
        if (rep.drawn)
            fputc('\n', stderr);
        job_spec shown = *spec;
        if (ps->deadline > 0 && ps->reached)
            shown.spp = ps->reached;
        summary(sh, n, &shown, &ps->total, rep.done, rows_missing, clk_now() - t0,
                rc == 0 ? NULL : stop_flag ? "interrupted" : "failed");
        /* The hosts that rendered rows, for the image's metadata. */
        for (int i = 0, k = 0; i < n && used_cap; i++)
            if (sh[i].rows > 0 && k >= 0 && (size_t)k < used_cap)
                k += snprintf(used + k, used_cap - (size_t)k, "%s%s", k ? "," : "", sh[i].name);
    }
    for (int i = 0; i < n; i++)
        if (sh[i].pending)
            fprintf(stderr, "franja: host %s was not ready before the render ended\n", table->v[i].name);
    /* The render no longer needs its scenes: other renders may evict them. */
    for (int i = 0; i < n; i++)
        if (cl[i].tr && cl[i].lease[0]) {
            fr_error e;
            tr_remove(cl[i].tr, cl[i].lease, &e);
        }
    cl_close(cl, n);
    /* A host still being prepared is not waited for (its time-out would
     * add to the render), except under Slurm, whose shared state goes with
     * the allocation. */
    cl_end(g, a->slurm.on);
    free(cl);
    free(sh);
    free(mh);
    free(mstate);
    return rc;
}

/* After a failure: a job directory with no finished slab holds nothing
 * worth keeping (a compiled scene at most), so it goes; one with slabs
 * stays for --resume.  Then the lock is given up.  Returns rc. */
static int unlock_with(job_lock *lk, int rc)
{
    if (lk->fd >= 0 && job_rows_present(lk->dir) == 0) {
        job_remove(lk->dir);
        jlk_release(lk, 1);
    }
    jlk_release(lk, 0);
    return rc;
}

/* The window's rows from the job directory into rgb (the other rows are
 * left as they are); fails naming the window's rows that are missing.
 * have (height bytes) is scratch. */
static int crop_stitch(const char *jobdir, const job_spec *spec, const crop_window *win, float *rgb,
                       unsigned char *have, fr_error *err)
{
    if (job_gather(jobdir, spec, rgb, have, NULL, err) < 0)
        return -1;
    int missing = 0;
    for (uint32_t y = 0; y < spec->height; y++) {
        if (y < win->y0 || y >= win->y1)
            have[y] = 1;
        missing += !have[y];
    }
    if (missing) {
        char rows[512];
        job_missing_rows(have, spec->height, rows, sizeof rows);
        return fr_fail(err, "%s: rows %s of the window are missing", jobdir, rows);
    }
    return 0;
}

/* One image of a render, from its job lock to its output: the render of
 * one scene, or one frame of an animation. */
typedef struct {
    render_args a;
    int argc;
    char **argv;               /* as typed, for the lock file (not owned) */
    char jobdir[4096], fbin[4200];
    job_lock lk;
    int locked;
    job_spec spec;
    fr_tonemap tm;
    int crop_rows;
    unsigned char *have;
    uint32_t *base;
    float *rgb;
    passes ps;
    int rows_job, rows_have;
    double t0;
    pg_reporter *pg;           /* --progress json, or NULL */
    mon_server *mon;           /* --monitor, or NULL */
} image;

/* Takes the image's job lock and checks what its job directory holds
 * against --resume and --fresh.  0, or the exit status (said). */
static int image_lock(image *im)
{
    render_args *a = &im->a;
    fr_error err;
    if (a->jobdir)
        snprintf(im->jobdir, sizeof im->jobdir, "%s", a->jobdir);
    else
        snprintf(im->jobdir, sizeof im->jobdir, "%s.franja-job", a->out);

    /* One writer per job directory, before anything is read or written
     * there (joblock.h). */
    char cmdline[4096];
    size_t cl = (size_t)snprintf(cmdline, sizeof cmdline, "franja");
    for (int i = 0; i < im->argc && cl < sizeof cmdline; i++)
        cl += (size_t)snprintf(cmdline + cl, sizeof cmdline - cl, " %s", im->argv[i]);
    int lr = jlk_acquire(im->jobdir, a->out, cmdline, a->no_lock, &im->lk, &err);
    if (lr) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return lr == JLK_BUSY || lr == JLK_NOLOCKS ? 2 : 1;
    }
    im->locked = 1;
    if (im->lk.unlocked)
        fprintf(stderr, "franja render: warning: %s is not locked (--no-lock): nothing keeps another render "
                "of %s out of it\n", im->jobdir, a->out);
    if (!a->resume && !a->fresh) {
        int rows = job_rows_present(im->jobdir);
        if (rows > 0) {
            fprintf(stderr, "franja render: %s holds %d finished rows of an earlier render of %s; rerun with "
                    "--resume to finish it, or with --fresh to discard them\n", im->jobdir, rows, a->out);
            jlk_release(&im->lk, 0);
            im->locked = 0;
            return 2;
        }
    }

    if (a->resume && !a->frames) {
        /* Nothing to go on from: the render finished and its job
         * directory went with it. */
        char jf[4200];
        struct stat st;
        snprintf(jf, sizeof jf, "%s/job", im->jobdir);
        if (stat(jf, &st) != 0 && stat(a->out, &st) == 0) {
            fprintf(stderr, "franja render: --resume: nothing to resume: %s is finished and its job directory %s "
                    "is gone (a render removes it when done, unless --keep-job); render again without --resume "
                    "(from the first sample), and with --keep-job to add samples to it later\n", a->out,
                    im->jobdir);
            return 2;
        }
    }
    return 0;
}

/* Gets the image's scene (compiled into its job directory when needed),
 * works out what to render and opens the job directory: the rows it
 * holds, the passes of --time-limit.  0, or the exit status (said). */
static int image_open(image *im)
{
    render_args *a = &im->a;
    fr_error err;
    im->t0 = clk_now();
    fr_scene sc;
    if (scene_binary(a, im->jobdir, im->fbin, sizeof im->fbin, &sc, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return stop_flag ? 130 : 1;
    }
    job_spec spec = {sc.hash, a->width ? a->width : sc.settings.width, a->height ? a->height : sc.settings.height,
                     a->spp ? a->spp : sc.settings.spp,
                     a->integrator ? (uint32_t)(a->integrator - 1) : sc.settings.integrator,
                     a->noise_threshold > 0.0f ? a->noise_threshold : sc.settings.noise_threshold};
    if (a->scale > 0) {
        spec.width = opt_scaled(sc.settings.width, a->scale);
        spec.height = opt_scaled(sc.settings.height, a->scale);
    }
    char note[400];
    if (a->width && opt_aspect_note(spec.width, spec.height, sc.settings.width, sc.settings.height, note,
                                    sizeof note))
        fprintf(stderr, "franja render: warning: --size: %s\n", note);
    int rc = 0;
    if (spec.width > PROTO_MAX_SIZE || spec.height > PROTO_MAX_SIZE) {
        fprintf(stderr, "franja render: --scale: %ux%u is over the largest size, %u pixels a side\n", spec.width,
                spec.height, PROTO_MAX_SIZE);
        rc = 2;
    } else if (spec.integrator == FR_INTEGRATOR_BDPT && a->noise_threshold > 0.0f) {
        fprintf(stderr, "franja render: --noise-threshold: adaptive sampling is for path tracing, not bdpt\n");
        rc = 2;
    }
    if (!rc && spec.integrator == FR_INTEGRATOR_BDPT)
        spec.noise_threshold = 0.0f; /* bidirectional workers take every sample */
    if (!rc && spec.integrator == FR_INTEGRATOR_BDPT && bd_supported(&sc, &err)) {
        fprintf(stderr, "franja render: %s: bidirectional path tracing: %s\n", a->scene, err.msg);
        rc = a->integrator ? 2 : 1;
    } else if (!rc && a->time_limit > 0 && !job_sums(&spec)) {
        fprintf(stderr, "franja render: --time-limit: its passes add samples to each pixel's kept sample sums, which "
                "only path tracing without adaptive sampling keeps (this render %s)\n",
                spec.integrator == FR_INTEGRATOR_BDPT ? "is bidirectional"
                : a->noise_threshold > 0.0f       ? "has --noise-threshold"
                                                  : "has the scene's noise_threshold");
        rc = 2;
    } else if (!rc && a->crop && crop_check(&a->win, spec.width, spec.height, &err)) {
        fprintf(stderr, "franja render: --crop %s\n", err.msg);
        rc = 2;
    }
    if (rc) {
        scn_free(&sc);
        return rc;
    }
    /* A crop renders the window's rows only, except bidirectionally: light
     * paths started from every pixel of the image reach the window. */
    int crop_rows = im->crop_rows = a->crop && spec.integrator != FR_INTEGRATOR_BDPT;
    if (a->crop && !crop_rows)
        fprintf(stderr, "franja: --crop with --integrator bdpt renders every row (light traced from the whole "
                "image reaches the window)\n");
    uint32_t asked = spec.spp;
    if (quick_spp(&spec.spp, &err) > 0)
        fprintf(stderr, "franja render: %s: %u samples per pixel instead of %u\n", QUICK_ENV, spec.spp, asked);
    /* Tone mapping: the scene's defaults, overridden by the command line. */
    im->tm = sc.tonemap;
    if (a->exposure_set)
        im->tm.exposure = a->exposure;
    if (a->curve)
        tm_curve_parse(a->curve, &im->tm.curve);
    scn_free(&sc);
    im->spec = spec;

    im->have = calloc(spec.height, 1);
    im->base = calloc(spec.height, sizeof *im->base);
    im->rgb = calloc((size_t)spec.width * spec.height * 3, sizeof *im->rgb);
    passes *ps = &im->ps;
    *ps = (passes){.a = a, .jobdir = im->jobdir, .spec = spec, .cap = spec.spp, .crop_rows = crop_rows,
                   .have = im->have, .base = im->base, .rgb = im->rgb, .scratch = NULL};
    if (!im->have || !im->base || !im->rgb || !(ps->scratch = calloc(spec.height, 1))) {
        fprintf(stderr, "franja render: out of memory for a %ux%u image\n", spec.width, spec.height);
        return 1;
    }
    int jr = job_open(im->jobdir, &spec, a->resume, &err);
    if (jr) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return jr == JOB_REFUSED ? 2 : 1;
    }
    /* What the job directory holds toward the samples asked for. */
    if (plan(ps, spec.spp, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return 1;
    }
    int rows_have = 0, rows_base = 0;
    uint32_t lo, hi, blo = UINT32_MAX, bhi = 0;
    for (uint32_t y = 0; y < spec.height; y++) {
        rows_have += im->have[y] && needed(ps, y);
        if (im->base[y] > 0 && needed(ps, y)) {
            rows_base++;
            blo = im->base[y] < blo ? im->base[y] : blo;
            bhi = im->base[y] > bhi ? im->base[y] : bhi;
        }
    }
    kept_range(ps, &lo, &hi);
    if (a->resume)
        fprintf(stderr, "franja: resuming: %d of %u rows already done in %s\n", ps->rows_kept, spec.height,
                im->jobdir);
    if (rows_base && a->time_limit <= 0)
        fprintf(stderr, "franja: adding samples: %d rows go on from the %u%s samples per pixel kept with their sums to "
                "%u\n", rows_base, blo, blo != bhi ? " or more" : "", spec.spp);
    /* The rows this render needs (a crop's window). */
    int rows_job = crop_rows ? (int)(a->win.y1 - a->win.y0) : (int)spec.height;
    ps->rows_job = im->rows_job = rows_job;
    im->rows_have = rows_have;
    if (a->time_limit > 0) {
        ps->deadline = im->t0 + a->time_limit;
        /* A complete image kept at one sample count is where the passes
         * start, and what is written if the first of them does not end. */
        if (lo == hi && lo > 0 && lo < spec.spp) {
            if (plan(ps, lo, &err) || pass_image(ps, &err)) {
                fprintf(stderr, "franja render: %s\n", err.msg);
                return 1;
            }
            ps->reached = lo;
            fprintf(stderr, "franja: the job holds a whole image with %u samples per pixel; passes go on from it\n",
                    lo);
            if (plan(ps, spec.spp, &err)) {
                fprintf(stderr, "franja render: %s\n", err.msg);
                return 1;
            }
        }
    }
    return 0;
}

/* Every row the image needs is in its job directory (or, with
 * --time-limit, the last complete pass in memory): stitches, writes the
 * output, removes the job directory (unless --keep-job) and gives up the
 * lock.  used: the hosts that rendered rows, for the metadata.  0, or 1
 * (said). */
static int image_write(image *im, const char *used)
{
    render_args *a = &im->a;
    passes *ps = &im->ps;
    job_spec spec = im->spec;
    fr_error err;
    if (a->time_limit > 0 && ps->reached) {
        /* The image of the last complete pass is in rgb. */
        spec.spp = ps->reached;
        if (ps->stopped)
            fprintf(stderr, "franja: time limit of %g s reached: %u samples per pixel (the pass to %u was stopped)\n",
                    a->time_limit, ps->reached, ps->stopped);
        else
            fprintf(stderr, "franja: every %u samples per pixel within the time limit\n", ps->reached);
    } else if (im->crop_rows ? crop_stitch(im->jobdir, &spec, &a->win, im->rgb, im->have, &err)
                             : job_stitch(im->jobdir, &spec, im->rgb, &a->tr.notes, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return 1;
    }
    job_spec out_spec = spec;
    float *rgb = im->rgb;
    if (a->crop) {
        crop_black(&a->win, rgb, spec.width, spec.height);
        if (a->crop_output) {
            /* The window moves to the start of the buffer. */
            float *w = malloc((size_t)(a->win.x1 - a->win.x0) * (a->win.y1 - a->win.y0) * 3 * sizeof *w);
            if (!w) {
                fprintf(stderr, "franja render: out of memory for the window\n");
                return 1;
            }
            crop_extract(&a->win, rgb, spec.width, w);
            free(rgb);
            rgb = im->rgb = ps->rgb = w;
            out_spec.width = a->win.x1 - a->win.x0;
            out_spec.height = a->win.y1 - a->win.y0;
        }
    }
    out_meta meta;
    out_meta_make(&meta, &spec, a->reproducible ? -1 : clk_now() - im->t0, a->reproducible ? NULL : used);
    if (a->reproducible)
        out_meta_set_time(&meta, reproducible_epoch());
    a->io.attrs = meta.attrs;
    if (out_write_with(a->out, rgb, &out_spec, &im->tm, &a->io, &err)) {
        /* Said only once checked: the rows are still there. */
        if (job_rows_present(im->jobdir) >= im->rows_job) {
            fprintf(stderr, "franja render: %s\nfranja render: the rendered rows stay in %s: rerun with --resume "
                    "to write %s\n", err.msg, im->jobdir, a->out);
        } else {
            char kept[4400];
            job_kept_note(im->jobdir, kept, sizeof kept);
            fprintf(stderr, "franja render: %s\nfranja render: %s\n", err.msg, kept);
        }
        return 1;
    }
    pg_stop(im->pg, "ok", spec.spp);
    im->pg = NULL;
    mon_status(im->mon, "done");
    mon_stop(im->mon);
    im->mon = NULL;
    if (!a->keep_job)
        job_remove(im->jobdir);
    else if (job_sums(&spec))
        job_prune(im->jobdir, &spec); /* rows kept with more samples make the fewer useless */
    jlk_release(&im->lk, !a->keep_job);
    im->locked = 0;
    fprintf(stderr, "franja: wrote %s (%ux%u, %u spp) in %.2f s\n", a->out, out_spec.width, out_spec.height, spec.spp,
            clk_now() - im->t0);
    return 0;
}

/* Ends the image: after a failure (rc not 0) its job directory stays for
 * --resume if it holds rows and the lock is given up; frees it. */
static void image_close(image *im, int rc)
{
    pg_stop(im->pg, stop_flag ? "interrupted" : "failed", im->spec.spp);
    mon_stop(im->mon);
    if (rc && im->locked)
        unlock_with(&im->lk, rc);
    free(im->have);
    free(im->base);
    free(im->ps.scratch);
    free(im->rgb);
    free(im);
}

/* Parses argv into a new image; NULL with *status set (0 after --help, 2
 * on a usage error). */
static image *image_parse(int argc, char **argv, int *status)
{
    image *im = calloc(1, sizeof *im);
    /* Parsed in a copy: argv stays as typed, for the lock file's command
     * line and the salloc hint. */
    char **args = opt_copy(argc, argv);
    int pr = args && im ? parse(argc, args, &im->a) : 2;
    free(args);
    if (pr) {
        free(im);
        *status = pr == 1 ? 0 : 2;
        return NULL;
    }
    im->argc = argc;
    im->argv = argv;
    return im;
}

static void on_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
}

/* The hosts of the render: the table, a Slurm allocation or this
 * machine.  0, or 2 (said). */
static int load_hosts(render_args *a, int argc, char **argv, hosts_table *table, slurm_alloc *alloc)
{
    memset(alloc, 0, sizeof *alloc);
    if (a->slurm.on)
        return cli_slurm_hosts("render", &a->slurm, argc, argv, &a->tr, alloc, table) ? 2 : 0;
    if (a->hosts)
        return cli_load_hosts("render", a->hosts, table) ? 2 : 0;
    table->n = 1;
    table->v = calloc(1, sizeof *table->v);
    if (!table->v)
        return 1;
    snprintf(table->path, sizeof table->path, "(this machine)");
    strcpy(table->v[0].name, "local");
    strcpy(table->v[0].address, "local");
    return 0;
}

static int render_frames(int argc, char **argv, render_args *a);

int cmd_render(int argc, char **argv)
{
    int status;
    image *im = image_parse(argc, argv, &status);
    if (!im)
        return status;
    render_args *a = &im->a;
    static int in_frames; /* rendering one frame of --frames frame by frame */
    if (a->frames && !in_frames) {
        in_frames = 1;
        int rc = render_frames(argc, argv, a);
        in_frames = 0;
        free(im);
        return rc;
    }
    if (frames_check_plain(a->scene)) {
        free(im);
        return 2;
    }
    fr_error err;
    if (out_check(a->out, &err) || (a->preview && out_check_type(a->preview, &err))) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        free(im);
        return 2;
    }
    int rc = image_lock(im);
    if (rc) {
        image_close(im, rc);
        return rc;
    }
    on_signals();
    uint32_t probe = UINT32_MAX;
    if (quick_spp(&probe, &err) < 0) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        image_close(im, 2);
        return 2;
    }
    hosts_table table;
    slurm_alloc alloc;
    if ((rc = load_hosts(a, argc, argv, &table, &alloc))) {
        image_close(im, rc);
        return rc;
    }
    rc = image_open(im);
    if (rc)
        goto done;
    rc = 1;
    if (a->json && !(im->pg = pg_start(stdout, a->out, im->jobdir, &im->spec, (uint32_t)im->rows_job, &err))) {
        fprintf(stderr, "franja render: --progress json: %s\n", err.msg);
        goto done;
    }
    if (a->monitor) {
        if (!(im->mon = mon_start((uint16_t)a->monitor_port, a->out, im->jobdir, &im->spec, &im->tm, &err))) {
            fprintf(stderr, "franja render: --monitor: %s\n", err.msg);
            goto done;
        }
        mon_status(im->mon, "rendering");
        fprintf(stderr, "franja: monitor on http://127.0.0.1:%u/\n", mon_port(im->mon));
    }
    pv_writer *pv = NULL;
    if (a->preview && !(pv = pv_start(a->preview, im->jobdir, &im->spec, &im->tm, a->preview_every,
                                      (note_sink){cli_note_stderr, NULL}, &err))) {
        fprintf(stderr, "franja render: --preview: %s\n", err.msg);
        goto done;
    }
    char used[1024] = "";
    int slabs_rc = im->rows_have < im->rows_job
                       ? run_slabs(a, &table, im->fbin, &im->ps, im->pg, im->mon, used, sizeof used, NULL, &err)
                       : 0;
    pv_stop(pv);
    if (slabs_rc) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        goto done;
    }
    rc = image_write(im, used);
done:
    if (rc && stop_flag)
        rc = 130;
    image_close(im, rc);
    hosts_free(&table);
    slurm_close(&alloc);
    return rc;
}

/* One frame of an animation run together with the others. */
typedef struct {
    frames_one one;            /* its number, files and command line */
    image *im;                 /* NULL once closed */
    int written;
    int failed;                /* the exit status it failed with (said when the run ends); 0 = none */
    char label[32];            /* "frame N" */
    unsigned char *rendered_on; /* per host: it rendered rows of this frame */
} frame_slot;

struct anim_run {
    frames_iter it;
    const hosts_table *table;
    frame_slot **fr;           /* by the scheduler's frame index */
    int nfr, capfr;
    int failed;                /* a frame failed: no frame is opened after it */
};

/* Frees what an image holds but its settings (a frame that is written). */
static void image_shrink(image *im)
{
    free(im->have);
    free(im->base);
    free(im->ps.scratch);
    free(im->rgb);
    im->have = NULL;
    im->base = NULL;
    im->ps.scratch = NULL;
    im->rgb = im->ps.rgb = NULL;
    im->ps.have = NULL;
    im->ps.base = NULL;
}

/* The next frame to render, locked, compiled and its job directory open:
 * 0 with *next (frame index fx->nfr - 1); 1 when no frame is left; -1
 * when a frame failed (its reason said; fx->failed set, and the frame
 * named when the run ends). */
static int rf_open(anim_run *fx, sched_frame *next)
{
    if (fx->failed)
        return 1;
    frame_slot *fs = calloc(1, sizeof *fs);
    if (fs && fx->nfr == fx->capfr) {
        int cap = fx->capfr ? 2 * fx->capfr : 8;
        frame_slot **v = realloc(fx->fr, (size_t)cap * sizeof *v);
        if (v) {
            fx->fr = v;
            fx->capfr = cap;
        }
    }
    if (!fs || fx->nfr == fx->capfr) {
        free(fs);
        fprintf(stderr, "franja render: out of memory\n");
        fx->failed = 1;
        return -1;
    }
    int r = frames_next(&fx->it, &fs->one);
    if (r) {
        free(fs);
        if (r == 1)
            return 1;
        fx->failed = r - 1; /* said, with the frame's number */
        return -1;
    }
    fx->fr[fx->nfr++] = fs;
    snprintf(fs->label, sizeof fs->label, "frame %u", fs->one.number);
    fs->rendered_on = calloc((size_t)fx->table->n, 1);
    int status = 1;
    fs->im = fs->rendered_on ? image_parse(fs->one.argc, fs->one.argv, &status) : NULL;
    int rc = fs->im ? 0 : status ? status : 2;
    fr_error e;
    if (!rc && out_check(fs->im->a.out, &e)) {
        fprintf(stderr, "franja render: %s\n", e.msg);
        rc = 2;
    }
    if (!rc)
        rc = image_lock(fs->im);
    if (!rc)
        rc = image_open(fs->im);
    if (rc) {
        if (fs->im)
            image_close(fs->im, rc);
        fs->im = NULL;
        fs->failed = fx->failed = stop_flag ? 130 : rc;
        return -1;
    }
    image *im = fs->im;
    im->ps.label = fs->label;
    *next = (sched_frame){im->ps.spec, im->jobdir, im->have, im->base, job_sums(&im->ps.spec), fs->label};
    return 0;
}

/* The scheduler asks for the next frame.  One that fails to open ends the
 * list: the frames in flight are finished first, then the run ends with
 * that frame's failure. */
static int rf_next(void *ctx, int frame, sched_frame *next, fr_error *err)
{
    (void)frame, (void)err; /* frames are opened in the scheduler's order: frame == fx->nfr */
    reporter *r = ctx;
    if (stop_flag)
        return 1; /* no new frame once interrupted */
    clear_line(r);
    return rf_open(r->fx, next) ? 1 : 0;
}

static int rf_stage(void *ctx, int frame, sched_host *h, int host_i, char *scene, size_t scene_cap, char *lease,
                    size_t lease_cap, fr_error *err)
{
    reporter *r = ctx;
    anim_run *fx = r->fx;
    frame_slot *fs = fx->fr[frame];
    const hosts_entry *e = &fx->table->v[host_i];
    double t0 = clk_now();
    int uploaded = 0;
    fr_error e2;
    if (cl_stage(h->tr, e, fs->im->fbin, fs->im->spec.hash, scene, scene_cap, lease, lease_cap, &uploaded, &e2))
        return fr_fail(err, "%s: %s", fs->label, e2.msg);
    if (fx->table->path[0] != '(' || !isatty(2)) {
        clear_line(r);
        fprintf(stderr, "franja: host %s: %s: scene %s (%.2f s)\n", h->name, fs->label,
                hosts_is_local(e) ? "local" : uploaded ? "uploaded" : "already there", clk_now() - t0);
    }
    return 0;
}

static void rf_rendered(anim_run *fx, int frame, int host)
{
    if (frame >= 0 && frame < fx->nfr && host >= 0 && host < fx->table->n && fx->fr[frame]->rendered_on)
        fx->fr[frame]->rendered_on[host] = 1;
}

static int rf_done(void *ctx, int frame, fr_error *err)
{
    reporter *r = ctx;
    anim_run *fx = r->fx;
    frame_slot *fs = fx->fr[frame];
    char used[1024] = "";
    for (int i = 0, k = 0; i < fx->table->n; i++)
        if (fs->rendered_on[i] && (size_t)k < sizeof used)
            k += snprintf(used + k, sizeof used - (size_t)k, "%s%s", k ? "," : "", fx->table->v[i].name);
    clear_line(r);
    if (image_write(fs->im, used)) {
        fs->failed = fx->failed = 1;
        return fr_fail(err, "%s could not be written", fs->label);
    }
    fs->written = 1;
    frames_wrote(&fx->it);
    image_shrink(fs->im); /* the settings stay: the scheduler's run may still read the first frame's */
    return 0;
}

/* `franja render PATTERN --frames LIST`: the frames run together over one
 * set of hosts, each written as soon as its rows are in; a frame-by-frame
 * run where an option works on one image at a time (--time-limit,
 * --preview, --monitor, --progress json) or the hosts are a Slurm
 * allocation. */
static int render_frames(int argc, char **argv, render_args *a)
{
    frames_job fj = {a->frames, a->overwrite, a->scene, a->out, a->jobdir, a->preview};
    if (a->time_limit > 0 || a->preview || a->monitor || a->json || a->slurm.on)
        return frames_run(argc, argv, &fj, cmd_render);
    anim_run fx;
    memset(&fx, 0, sizeof fx);
    if (frames_begin(&fx.it, argc, argv, &fj))
        return 2;
    on_signals();
    fr_error err;
    uint32_t probe = UINT32_MAX;
    if (quick_spp(&probe, &err) < 0) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return frames_end(&fx.it, 2);
    }
    hosts_table table;
    slurm_alloc alloc;
    int rc = load_hosts(a, argc, argv, &table, &alloc);
    if (rc)
        return frames_end(&fx.it, rc);
    fx.table = &table;
    sched_frame first;
    if (rf_open(&fx, &first) == 0) {
        char used[1024];
        if (run_slabs(a, &table, NULL, &fx.fr[0]->im->ps, NULL, NULL, used, sizeof used, &fx, &err)) {
            fprintf(stderr, "franja render: %s\n", err.msg);
            rc = 1;
        }
    }
    /* The frame to name: after an interrupt the first not written, else
     * the one that failed, else (the hosts failed) the first not written. */
    frame_slot *named = NULL;
    for (int i = 0; i < fx.nfr && !named; i++)
        if (fx.fr[i]->failed && !stop_flag)
            named = fx.fr[i];
    for (int i = 0; i < fx.nfr && !named; i++)
        if (!fx.fr[i]->written)
            named = fx.fr[i];
    if (stop_flag && (rc || fx.failed))
        rc = 130;
    else if (fx.failed)
        rc = fx.failed;
    if (rc && named)
        frames_failed(&fx.it, named->one.number, named->one.scene, named->one.out, rc);
    /* The frames still open are closed; their finished slabs stay for
     * --resume. */
    for (int i = 0; i < fx.nfr; i++) {
        frame_slot *fs = fx.fr[i];
        if (fs->im)
            image_close(fs->im, fs->written ? 0 : rc ? rc : 1);
        frames_put(&fs->one);
        free(fs->rendered_on);
        free(fs);
    }
    free(fx.fr);
    hosts_free(&table);
    slurm_close(&alloc);
    return frames_end(&fx.it, rc);
}
