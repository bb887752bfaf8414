/* cmd_render.c -- `franja render`: the command line, the hosts made ready,
 * the scheduler's run and its reports, for one image or for the frames of
 * an animation run together; each image's lock, scene, job directory and
 * output are frame.c's. */
#include "cmd.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "opt.h"
#include "clock.h"
#include "cmd_frames.h"
#include "frame.h"
#include "cluster.h"
#include "crop.h"
#include "jobdir.h"
#include "monitor.h"
#include "output.h"
#include "preview.h"
#include "progress.h"
#include "protocol.h"
#include "quick.h"
#include "sched.h"
#include "statusline.h"

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
    "  --job DIR            job directory (default OUT.franja-job; for an OUT\n"
    "                       under /dev/ or /proc/, NAME.franja-job here)\n"
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

/* render's own options (getopt_long values). */
enum {
    OPT_SPP = CLI_OPT_OWN, OPT_SIZE, OPT_CAMERA, OPT_EXPOSURE, OPT_TONEMAP, OPT_RESUME, OPT_FRESH, OPT_JOB,
    OPT_KEEP_JOB, OPT_NO_LOCK, OPT_SLAB_ROWS, OPT_RETRIES, OPT_PREVIEW, OPT_PREVIEW_EVERY,
    OPT_INTEGRATOR, OPT_PROGRESS, OPT_NOISE, OPT_MONITOR, OPT_CROP, OPT_CROP_OUTPUT,
    OPT_EXR_HALF, OPT_EXR_COMPRESSION, OPT_JPEG_QUALITY, OPT_SCALE, OPT_FRAMES, OPT_OVERWRITE, OPT_TIME_LIMIT,
    OPT_REPRODUCIBLE
};

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
                if (frame_next_pass(ps, &spp, err)) {
                    rc = -1;
                    break;
                }
                if (spp == 0)
                    break;
                if (ps->reached && clk_now() >= ps->deadline) {
                    ps->stopped = spp;
                    break;
                }
                if (frame_plan(ps, spp, err)) {
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
            if (frame_pass_image(ps, err)) {
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

/* Parses argv into a new image; NULL with *status set (0 after --help, 2
 * on a usage error). */
static frame_image *image_parse(int argc, char **argv, int *status)
{
    frame_image *im = calloc(1, sizeof *im);
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
    im->stop = &stop_flag;
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
    frame_image *im = image_parse(argc, argv, &status);
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
    int rc = frame_lock(im);
    if (rc) {
        frame_close(im, rc);
        return rc;
    }
    on_signals();
    uint32_t probe = UINT32_MAX;
    if (quick_spp(&probe, &err) < 0) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        frame_close(im, 2);
        return 2;
    }
    hosts_table table;
    slurm_alloc alloc;
    if ((rc = load_hosts(a, argc, argv, &table, &alloc))) {
        frame_close(im, rc);
        return rc;
    }
    rc = frame_open(im);
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
    rc = frame_write(im, used);
done:
    if (rc && stop_flag)
        rc = 130;
    frame_close(im, rc);
    hosts_free(&table);
    slurm_close(&alloc);
    return rc;
}

/* One frame of an animation run together with the others. */
typedef struct {
    frames_one one;            /* its number, files and command line */
    frame_image *im;           /* NULL once closed */
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
        rc = frame_lock(fs->im);
    if (!rc)
        rc = frame_open(fs->im);
    if (rc) {
        if (fs->im)
            frame_close(fs->im, rc);
        fs->im = NULL;
        fs->failed = fx->failed = stop_flag ? 130 : rc;
        return -1;
    }
    frame_image *im = fs->im;
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
    if (frame_write(fs->im, used)) {
        fs->failed = fx->failed = 1;
        return fr_fail(err, "%s could not be written", fs->label);
    }
    fs->written = 1;
    frames_wrote(&fx->it);
    frame_shrink(fs->im); /* the settings stay: the scheduler's run may still read the first frame's */
    return 0;
}

/* `franja render PATTERN --frames LIST`: the frames run together over one
 * set of hosts, each written as soon as its rows are in; a frame-by-frame
 * run where an option works on one image at a time (--time-limit,
 * --preview, --monitor, --progress json). */
static int render_frames(int argc, char **argv, render_args *a)
{
    frames_job fj = {a->frames, a->overwrite, a->scene, a->out, a->jobdir, a->preview};
    if (a->time_limit > 0 || a->preview || a->monitor || a->json)
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
            frame_close(fs->im, fs->written ? 0 : rc ? rc : 1);
        frames_put(&fs->one);
        free(fs->rendered_on);
        free(fs);
    }
    free(fx.fr);
    hosts_free(&table);
    slurm_close(&alloc);
    return frames_end(&fx.it, rc);
}
