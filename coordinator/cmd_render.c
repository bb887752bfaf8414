/* cmd_render.c -- `franja render`: the command line, and the render of one
 * image from its lock to its output with its reporters (--progress json,
 * --monitor, --preview).  The run over the hosts is render_run.c's, the
 * frames of an animation render_anim.c's, each image's lock, scene, job
 * directory and output frame.c's. */
#include "cmd.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "framewalk.h"
#include "compile/compile.h"
#include "crop.h"
#include "frame.h"
#include "monitor.h"
#include "opt.h"
#include "output.h"
#include "passes.h"
#include "preview.h"
#include "progress.h"
#include "protocol.h"
#include "quick.h"
#include "render_anim.h"
#include "render_run.h"

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
    "  --fps F              with --frames of one animated file (no # in SCENE):\n"
    "                       frames per second; frame N of a glTF file is posed at\n"
    "                       time N / F seconds, as Blender's glTF exporter writes\n"
    "                       key times (default 24)\n"
    "  --shutter S          with --frames of one animated file: motion blur over a\n"
    "                       shutter open S of a frame (0 to 1), centred on the\n"
    "                       frame's time as Blender's; the motion of the camera\n"
    "                       and of meshes is blurred (without it: a JSON\n"
    "                       camera's shutter key)\n"
    "  --camera NAME        glTF scenes: the camera to use, by its node's or its\n"
    "                       own name (default: the first in the scene)\n"
    "  --allow-path DIR     let a JSON or glTF scene read files in DIR too\n"
    "                       (repeatable); without it, a scene reads only files\n"
    "                       in its own folder\n"
    COMPILE_LIMIT_HELP
    "  --integrator I       path, bdpt or mlt (default: the scene's, else path)\n"
    "  --noise-threshold E  adaptive sampling (path tracing): each pixel stops once\n"
    "                       the relative error of its mean is below E, in (0, 1]\n"
    "                       (default: the scene's, else off)\n"
    "  --passes LIST        render passes beside the image (path tracing; bdpt:\n"
    "                       albedo, normal, depth, position, the ids, crypto): albedo,\n"
    "                       normal, depth, position, emission, diffuse_direct,\n"
    "                       diffuse_indirect, glossy_direct, glossy_indirect,\n"
    "                       transmission_direct, transmission_indirect,\n"
    "                       material_id, crypto_material (Cryptomatte, .exr\n"
    "                       only), variance, object_id, crypto_object (.exr\n"
    "                       only), light_groups, shadow, or all, light, denoise,\n"
    "                       none;\n"
    "                       .exr: one\n"
    "                       multilayer file, other types: one file per pass\n"
    "                       beside OUT (OUT.albedo.png ...) (default: the scene's)\n"
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
    "                       command), writing the last complete pass; for an\n"
    "                       animation, the run stops at T, the frames in flight\n"
    "                       left for --resume (exit status 124)\n"
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
    "                       (an animation: each frame's FILE, or the newest\n"
    "                       frame's when FILE has no #)\n"
    "  --preview-every S    seconds between preview images (default 5)\n"
    "  --progress MODE      auto (a live line on a terminal, else plain lines) or\n"
    "                       json (also one JSON object a line on stdout, for\n"
    "                       wrapper tools; a frame's events carry \"frame\")\n"
    "                       (default auto)\n"
    "  --monitor PORT       serve a live page of the render (image so far, hosts,\n"
    "                       ETA) on http://127.0.0.1:PORT/?token=... (0: a free\n"
    "                       port; the address is said on stderr, its random token\n"
    "                       keeps other users out); from another machine: ssh -L\n"
    "  --monitor-open       serve the monitor without a token (any local user\n"
    "                       can watch)\n"
    CLI_SLURM_HELP;

/* render's own options (getopt_long values). */
enum {
    OPT_SPP = CLI_OPT_OWN, OPT_SIZE, OPT_CAMERA, OPT_EXPOSURE, OPT_TONEMAP, OPT_RESUME, OPT_FRESH, OPT_JOB,
    OPT_KEEP_JOB, OPT_NO_LOCK, OPT_SLAB_ROWS, OPT_RETRIES, OPT_PREVIEW, OPT_PREVIEW_EVERY,
    OPT_INTEGRATOR, OPT_PROGRESS, OPT_NOISE, OPT_MONITOR, OPT_CROP, OPT_CROP_OUTPUT,
    OPT_EXR_HALF, OPT_EXR_COMPRESSION, OPT_JPEG_QUALITY, OPT_SCALE, OPT_FRAMES, OPT_OVERWRITE, OPT_FPS, OPT_SHUTTER,
    OPT_TIME_LIMIT,
    OPT_REPRODUCIBLE, OPT_MONITOR_OPEN, OPT_ALLOW_PATH, OPT_LIMIT, OPT_PASSES
};

/* Returns 0 to go on, 1 when done (help), 2 on a usage error. */
static int parse(int argc, char **argv, frame_settings *a)
{
    static const struct option longopts[] = {
        CLI_COMMON_LONGOPTS,
        CLI_SLURM_LONGOPTS,
        {"spp", required_argument, NULL, OPT_SPP},
        {"size", required_argument, NULL, OPT_SIZE},
        {"camera", required_argument, NULL, OPT_CAMERA},
        {"allow-path", required_argument, NULL, OPT_ALLOW_PATH},
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
        {"monitor-open", no_argument, NULL, OPT_MONITOR_OPEN},
        {"crop", required_argument, NULL, OPT_CROP},
        {"crop-output", no_argument, NULL, OPT_CROP_OUTPUT},
        {"exr-half", no_argument, NULL, OPT_EXR_HALF},
        {"exr-compression", required_argument, NULL, OPT_EXR_COMPRESSION},
        {"jpeg-quality", required_argument, NULL, OPT_JPEG_QUALITY},
        {"scale", required_argument, NULL, OPT_SCALE},
        {"reproducible", no_argument, NULL, OPT_REPRODUCIBLE},
        {"frames", required_argument, NULL, OPT_FRAMES},
        {"overwrite", no_argument, NULL, OPT_OVERWRITE},
        {"fps", required_argument, NULL, OPT_FPS},
        {"shutter", required_argument, NULL, OPT_SHUTTER},
        {"time-limit", required_argument, NULL, OPT_TIME_LIMIT},
        {"limit", required_argument, NULL, OPT_LIMIT},
        {"passes", required_argument, NULL, OPT_PASSES},
        {NULL, 0, NULL, 0},
    };
    static const char *const curves[] = {"none", "filmic", NULL};
    static const char *const progress[] = {"auto", "json", NULL};
    static const char cmd[] = "render";
    memset(a, 0, sizeof *a);
    a->retries = 5;
    a->preview_every = 5;
    budget_init(&a->limits);
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
        case OPT_ALLOW_PATH:
            if (a->n_allow == CONFINE_MAX_ALLOW) {
                fprintf(stderr, "franja render: --allow-path: at most %d folders\n", CONFINE_MAX_ALLOW);
                return 2;
            }
            a->allow[a->n_allow++] = v;
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
            static const char *const integrators[] = {"path", "bdpt", "mlt", NULL};
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
        case OPT_MONITOR_OPEN:
            a->monitor_open = 1;
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
        case OPT_FPS: {
            float f = 0;
            bad = opt_float(cmd, "--fps", v, 0.001f, 1000.0f, &f);
            a->fps = f;
            break;
        }
        case OPT_SHUTTER: {
            float f = 0;
            bad = opt_float(cmd, "--shutter", v, 0.0f, 1.0f, &f);
            a->shutter = f;
            break;
        }
        case OPT_TIME_LIMIT:
            bad = opt_duration(cmd, "--time-limit", v, &a->time_limit);
            break;
        case OPT_LIMIT: {
            fr_error e;
            if ((bad = budget_set(&a->limits, v, &e)) < 0)
                fprintf(stderr, "franja %s: --limit %s\n", cmd, e.msg);
            break;
        }
        case OPT_PASSES: {
            fr_error e;
            if ((bad = pass_parse(v, &a->passes, &e)) < 0)
                fprintf(stderr, "franja %s: --passes: %s\n", cmd, e.msg);
            a->passes_set = 1;
            break;
        }
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
    if (a->monitor_open && !a->monitor) {
        fprintf(stderr, "franja render: --monitor-open needs --monitor PORT\n");
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
    if ((a->fps > 0 || a->shutter > 0) && (!a->frames || !framewalk_one_scene(a->scene))) {
        fprintf(stderr, "franja render: --%s is for --frames of one glTF or JSON file (posed per frame)\n",
                a->fps > 0 ? "fps" : "shutter");
        return 2;
    }
    if (a->resume && a->fresh) {
        fprintf(stderr, "franja render: --resume and --fresh exclude each other\n");
        return 2;
    }
    return cli_slurm_check("render", &a->slurm, a->hosts) ? 2 : 0;
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
    im->stop = &render_run_stop;
    return im;
}

int cmd_render(int argc, char **argv)
{
    int status;
    frame_image *im = image_parse(argc, argv, &status);
    if (!im)
        return status;
    frame_settings *a = &im->a;
    if (a->frames) {
        int rc = render_anim(argc, argv, a, image_parse);
        free(im);
        return rc;
    }
    if (framewalk_check_plain(a->scene)) {
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
    render_run_signals();
    uint32_t probe = UINT32_MAX;
    if (quick_spp(&probe, &err) < 0) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        frame_close(im, 2);
        return 2;
    }
    hosts_table table;
    slurm_alloc alloc;
    if ((rc = render_run_hosts(a, argc, argv, &table, &alloc))) {
        frame_close(im, rc);
        return rc;
    }
    rc = frame_open(im);
    if (rc)
        goto done;
    rc = 1;
    if (a->json && !(im->pg = progress_start(stdout, PG_NO_FRAME, a->out, im->jobdir, &im->spec, (uint32_t)im->rows_job, &err))) {
        fprintf(stderr, "franja render: --progress json: %s\n", err.msg);
        goto done;
    }
    if (a->monitor) {
        if (!(im->mon = mon_start((uint16_t)a->monitor_port, a->monitor_open, a->out, im->jobdir, &im->spec, &im->tm,
                                  &err))) {
            fprintf(stderr, "franja render: --monitor: %s\n", err.msg);
            goto done;
        }
        mon_status(im->mon, "rendering");
        fprintf(stderr, "franja: monitor on %s\n", mon_url(im->mon));
    }
    preview_writer *pv = NULL;
    if (a->preview && !(pv = preview_start(a->preview, im->jobdir, &im->spec, &im->tm, a->preview_every,
                                      (note_sink){cli_note_stderr, NULL}, &err))) {
        fprintf(stderr, "franja render: --preview: %s\n", err.msg);
        goto done;
    }
    char used[1024] = "";
    int slabs_rc = im->rows_have < im->rows_job
                       ? render_run(a, &table, im->fbin, &im->ps, im->pg, im->mon, used, sizeof used, NULL, &err)
                       : 0;
    preview_stop(pv);
    if (slabs_rc) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        goto done;
    }
    rc = frame_write(im, used);
done:
    if (rc && render_run_stop)
        rc = 130;
    frame_close(im, rc);
    hosts_free(&table);
    slurm_close(&alloc);
    return rc;
}
