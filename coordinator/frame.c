/* frame.c -- one image of a render from its job lock to its output (see
 * frame.h). */
#include "frame.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bdpt.h"
#include "mlt_path.h"
#include "clock.h"
#include "compile/compile.h"
#include "compile/compile_child.h"
#include "compile/gltf_anim.h"
#include "fbin.h"
#include "opt.h"
#include "protocol.h"
#include "passes.h"
#include "passout.h"
#include "quick.h"

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && !strcasecmp(s + a - b, suffix);
}

/* --reproducible's DateTime: SOURCE_DATE_EPOCH when it is a number of
 * seconds (the convention of reproducible builds), else 0 (1970). */
static long long reproducible_epoch(void)
{
    const char *v = getenv("SOURCE_DATE_EPOCH");
    char *end;
    long long e = v && *v ? strtoll(v, &end, 10) : 0;
    return v && *v && !*end ? e : 0;
}

static void print_warning(void *user, const char *msg)
{
    fprintf(stderr, "%s: warning: %s\n", (const char *)user, msg);
}

/* Gets the binary scene: loads an .fbin, or compiles a JSON scene into the
 * job directory.  *path receives the .fbin to ship; an animation's frame
 * (im->reuse) is compiled by reuse.h, which may leave a scene patch in
 * im->patch. */
static int scene_binary(frame_image *im, char *path, size_t cap, fr_scene *sc, fr_error *err)
{
    const frame_settings *a = &im->a;
    const char *jobdir = im->jobdir;
    volatile sig_atomic_t *stop = im->stop;
    im->patch[0] = 0;
    if (!ends_with(a->scene, ".json") && !compile_is_gltf(a->scene)) {
        if (a->camera)
            return fr_fail(err, "%s: --camera applies to glTF scenes (a compiled scene has its camera)", a->scene);
        snprintf(path, cap, "%s", a->scene);
        if (im->reuse) {
            /* The patch goes into the job directory, made for it. */
            if (mkdir(jobdir, 0755) && errno != EEXIST)
                return fr_fail(err, "%s: cannot create job directory: %s", jobdir, strerror(errno));
            snprintf(im->patch, sizeof im->patch, "%s/scene.patch", jobdir);
            if (reuse_loaded(im->reuse, path, im->patch, &im->reused, err))
                return -1;
            if (!im->reused.base)
                im->patch[0] = 0;
        }
        return fbin_load(path, sc, err);
    }
    if (mkdir(jobdir, 0755) && errno != EEXIST)
        return fr_fail(err, "%s: cannot create job directory: %s", jobdir, strerror(errno));
    snprintf(path, cap, "%s/scene.fbin", jobdir);
    /* What a compile of a render killed by SIGKILL left; the job lock
     * keeps any other compile out of this directory. */
    compile_child_sweep(path);
    /* In a child process, so that Ctrl-C stops a long compile at once. */
    compile_opts co = {a->camera, print_warning, (void *)"franja", a->allow, a->n_allow, &a->limits, NULL,
                       a->timed, a->frame, a->fps > 0 ? a->fps : GANIM_FPS, a->timed ? a->shutter : 0.0,
                       0, NULL, NULL, NULL, 0, NULL};
    if (im->reuse) {
        snprintf(im->patch, sizeof im->patch, "%s/scene.patch", jobdir);
        if (reuse_compile(im->reuse, a->scene, &co, path, im->patch, stop, &im->reused, err))
            return -1;
        if (!im->reused.base)
            im->patch[0] = 0;
    } else if (compile_child(a->scene, &co, path, stop, NULL, err))
        return -1;
    return fbin_load(path, sc, err);
}
/* After a failure: a job directory with no finished slab holds nothing
 * worth keeping (a compiled scene at most), so it goes; one with slabs
 * stays for --resume.  Then the lock is given up.  Returns rc. */
static int unlock_with(joblock *lk, int rc)
{
    if (lk->fd >= 0 && job_rows_present(lk->dir) == 0) {
        job_remove(lk->dir);
        joblock_release(lk, 1);
    }
    joblock_release(lk, 0);
    return rc;
}

/* The window's rows from the job directory into rgb (the other rows are
 * left as they are); fails naming the window's rows that are missing.
 * have (height bytes) is scratch. */
static int crop_stitch(const char *jobdir, const job_spec *spec, const crop_window *win, float *rgb,
                       float *passes, unsigned char *have, fr_error *err)
{
    if (job_gather_passes(jobdir, spec, rgb, passes, have, NULL, err) < 0)
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


/* Whether the render needs row y (a crop needs its window's). */
static int needed(const frame_passes *ps, uint32_t y)
{
    return !ps->crop_rows || (y >= ps->a->win.y0 && y < ps->a->win.y1);
}

/* What a pass to spp samples per pixel renders: the rows the job
 * directory does not hold with spp samples, each from the most samples
 * kept for it with their sums. */
int frame_plan(frame_passes *ps, uint32_t spp, fr_error *err)
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
static void kept_range(const frame_passes *ps, uint32_t *lo, uint32_t *hi)
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
int frame_next_pass(frame_passes *ps, uint32_t *spp, fr_error *err)
{
    if (frame_plan(ps, ps->cap, err))
        return -1;
    uint32_t lo, hi;
    kept_range(ps, &lo, &hi);
    *spp = 0;
    if (lo >= ps->cap)
        return 0;
    if (!job_sums(&ps->spec)) {
        /* Slabs with render passes and Metropolis chains: each pass
         * renders from the first sample (first, at most ps->first). */
        lo = ps->reached;
        hi = ps->reached ? ps->reached : ps->first;
    }
    uint32_t twice = lo == 0 ? 1 : lo > ps->cap / 2 ? ps->cap : 2 * lo;
    *spp = twice > hi ? twice : hi;
    return 0;
}

/* The image of the pass just planned and complete into ps->rgb.  A
 * Metropolis pass's whole image makes the slabs of fewer mutations
 * useless (a resume goes on from it): they go. */
int frame_pass_image(frame_passes *ps, fr_error *err)
{
    if (ps->crop_rows)
        return crop_stitch(ps->jobdir, &ps->spec, &ps->a->win, ps->rgb, ps->passes, ps->scratch, err);
    if (job_stitch_passes(ps->jobdir, &ps->spec, ps->rgb, ps->passes, &ps->a->tr.notes, err))
        return -1;
    if (ps->spec.integrator == FR_INTEGRATOR_MLT)
        job_prune(ps->jobdir, &ps->spec);
    return 0;
}

/* Metropolis, resumed (no sums: each pass renders every chain from its
 * start): where the passes start.  *whole: the most mutations per pixel
 * below ps->cap at which the job directory holds every chain (the image
 * of the last complete pass), else 0; ps->first: the most it holds for a
 * chain, which the first pass renders to when there is no such image (a
 * pass's slab has the name of the last pass's of the same rows).  From a
 * plan to ps->cap, and leaves one. */
static int kept_passes(frame_passes *ps, uint32_t *whole, fr_error *err)
{
    *whole = 0;
    if (job_scan(ps->jobdir, &ps->spec, ps->have, ps->base, &ps->a->tr.notes, err) < 0)
        return -1;
    uint32_t lo, hi;
    kept_range(ps, &lo, &hi);
    ps->first = hi;
    if (lo == 0 || lo >= ps->cap)
        return 0;
    if (frame_plan(ps, lo, err))
        return -1;
    *whole = ps->rows_missing ? 0 : lo;
    return frame_plan(ps, ps->cap, err);
}

/* Takes the image's job lock and checks what its job directory holds
 * against --resume and --fresh.  0, or the exit status (said). */
int frame_lock(frame_image *im)
{
    frame_settings *a = &im->a;
    fr_error err;
    if (a->jobdir)
        snprintf(im->jobdir, sizeof im->jobdir, "%s", a->jobdir);
    else if (!strncmp(a->out, "/dev/", 5) || !strncmp(a->out, "/proc/", 6))
        /* /dev/null, /dev/stdout: no job directory beside them, but one
         * in the current directory, named after them. */
        snprintf(im->jobdir, sizeof im->jobdir, "%s.franja-job", strrchr(a->out, '/') + 1);
    else
        snprintf(im->jobdir, sizeof im->jobdir, "%s.franja-job", a->out);

    /* One writer per job directory, before anything is read or written
     * there (joblock.h). */
    char cmdline[4096];
    size_t cl = (size_t)snprintf(cmdline, sizeof cmdline, "franja");
    for (int i = 0; i < im->argc && cl < sizeof cmdline; i++)
        cl += (size_t)snprintf(cmdline + cl, sizeof cmdline - cl, " %s", im->argv[i]);
    int lr = joblock_acquire(im->jobdir, a->out, cmdline, a->no_lock, &im->lk, &err);
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
            joblock_release(&im->lk, 0);
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

/* What stops a normalisation: SIGINT (stop), or --time-limit's deadline
 * (stop_at, clock_now() time; 0 = none). */
typedef struct {
    volatile sig_atomic_t *stop;
    double stop_at;
} norm_stop;

static int norm_stopped(void *ctx)
{
    const norm_stop *ns = ctx;
    return *ns->stop || (ns->stop_at > 0 && clock_now() >= ns->stop_at);
}

/* Metropolis light transport's normalisation (mlt_path.h) for spec's
 * image size and samples (mlt_norm_samples of them): into norm (at least
 * PROTO_MLT_DEPTHS floats), handed to every worker by spec.  A scene
 * deeper than the command line carries leaves it to each worker (the same
 * numbers, computed per slab) and spec without it.  Computed on every
 * core, the bits of a worker's own (bd_depth_means_mt), and given up
 * between blocks when ns says: -1 with err on SIGINT or out of memory, 1
 * at the deadline (norm and spec unchanged). */
static int normalise(fr_scene *sc, job_spec *spec, float *norm, norm_stop *ns, fr_error *err)
{
    sc->settings.width = spec->width;
    sc->settings.height = spec->height;
    sc->settings.spp = spec->spp;
    uint32_t nd = sc->settings.max_depth + 1, n = mlt_norm_samples(sc);
    if (nd > PROTO_MLT_DEPTHS) {
        fprintf(stderr, "franja: Metropolis light transport: max_depth %u: each worker computes its own "
                "normalisation (%u bidirectional samples a slab)\n", nd - 1, n);
        return 0;
    }
    /* mlt_bootstrap's numbers, rounded to float as it does. */
    double t0 = clock_now(), bd[PROTO_MLT_DEPTHS], b = 0.0;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int threads = cores < 1 ? 1 : cores > 256 ? 256 : (int)cores;
    int rc = bd_depth_means_mt(sc, n, threads, norm_stopped, ns, bd);
    if (rc > 0 && !*ns->stop)
        return 1;
    if (rc)
        return fr_fail(err, rc > 0 ? "Metropolis normalisation: interrupted"
                                   : "out of memory for the Metropolis normalisation");
    for (uint32_t d = 0; d < nd; d++)
        b += norm[d] = (float)bd[d];
    fprintf(stderr, "franja: Metropolis normalisation: b = %.6g from %u bidirectional samples on %d threads "
            "(%.1f s)\n", b, n, threads, clock_now() - t0);
    spec->mlt_norm = norm;
    spec->mlt_depths = nd;
    return 0;
}

int frame_normalise(frame_passes *ps, fr_error *err)
{
    if (!ps->mlt_scene)
        return 0;
    ps->mlt_scene->settings.width = ps->spec.width;
    ps->mlt_scene->settings.height = ps->spec.height;
    ps->mlt_scene->settings.spp = ps->spec.spp;
    uint32_t n = mlt_norm_samples(ps->mlt_scene);
    if (n == ps->mlt_samples)
        return 0;              /* the same samples give the same numbers */
    /* The first pass always ends (frame_passes), so does its normalisation. */
    norm_stop ns = {ps->stop, ps->reached ? ps->deadline : 0};
    int rc = normalise(ps->mlt_scene, &ps->spec, ps->mlt_norm, &ns, err);
    if (rc)
        return rc;
    ps->mlt_samples = n;
    return 0;
}

/* Gets the image's scene (compiled into its job directory when needed),
 * works out what to render and opens the job directory: the rows it
 * holds, the passes of --time-limit.  0, or the exit status (said). */
int frame_open(frame_image *im)
{
    frame_settings *a = &im->a;
    fr_error err;
    im->t0 = clock_now();
    fr_scene sc;
    if (scene_binary(im, im->fbin, sizeof im->fbin, &sc, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return *im->stop ? 130 : 1;
    }
    job_spec spec = {sc.hash, a->width ? a->width : sc.settings.width, a->height ? a->height : sc.settings.height,
                     a->spp ? a->spp : sc.settings.spp,
                     a->integrator ? (uint32_t)(a->integrator - 1) : sc.settings.integrator,
                     a->noise_threshold > 0.0f ? a->noise_threshold : sc.settings.noise_threshold,
                     a->passes_set ? a->passes : sc.settings.passes, NULL, 0};
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
    } else if (fr_integrator_splats(spec.integrator) && a->noise_threshold > 0.0f) {
        fprintf(stderr, "franja render: --noise-threshold: adaptive sampling is for path tracing, not %s\n",
                proto_integrator_name((int)spec.integrator));
        rc = 2;
    }
    int mlt = spec.integrator == FR_INTEGRATOR_MLT;
    if (!rc && fr_integrator_splats(spec.integrator))
        spec.noise_threshold = 0.0f; /* bidirectional and Metropolis workers take every sample */
    if (!rc && spec.passes && mlt) {
        fprintf(stderr, "franja render: %s: render passes are made by the path integrator and bdpt, not %s (use "
                "--integrator path or bdpt, or --passes none)\n", a->passes_set ? "--passes" : a->scene,
                proto_integrator_name((int)spec.integrator));
        rc = 2;
    } else if (!rc && spec.integrator == FR_INTEGRATOR_BDPT && (spec.passes & ~BD_PASSES)) {
        char names[400];
        pass_format(spec.passes & ~BD_PASSES, names, sizeof names);
        fprintf(stderr, "franja render: %s: bdpt fills the passes of its camera subpaths (albedo, normal, depth, "
                "position, material_id, crypto_material, object_id, crypto_object), not %s: light tracing's "
                "splats land on other pixels (use --integrator path for them)\n",
                a->passes_set ? "--passes" : a->scene, names);
        rc = 2;
    } else if (!rc && fr_integrator_splats(spec.integrator) && (mlt ? mlt_supported(&sc, &err) : bd_supported(&sc, &err))) {
        fprintf(stderr, "franja render: %s: %s: %s\n", a->scene,
                mlt ? "Metropolis light transport" : "bidirectional path tracing", err.msg);
        rc = a->integrator ? 2 : 1;
    } else if (!rc && a->time_limit > 0 && !job_sums(&spec) && !mlt &&
               !(spec.passes && spec.integrator == FR_INTEGRATOR_PATH)) {
        fprintf(stderr, "franja render: --time-limit: its passes add samples to each pixel's kept sample sums, which "
                "only path tracing without adaptive sampling keeps (this render %s)\n",
                spec.integrator == FR_INTEGRATOR_BDPT ? "is bidirectional"
                : a->noise_threshold > 0.0f             ? "has --noise-threshold"
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
    int crop_rows = im->crop_rows = a->crop && !fr_integrator_splats(spec.integrator);
    if (a->crop && mlt)
        fprintf(stderr, "franja: --crop with --integrator mlt renders every row (every chain splats over the whole "
                "image)\n");
    else if (a->crop && !crop_rows)
        fprintf(stderr, "franja: --crop with --integrator bdpt renders every row (light traced from the whole "
                "image reaches the window)\n");
    uint32_t asked = spec.spp;
    if (quick_spp(&spec.spp, &err) > 0)
        fprintf(stderr, "franja render: %s: %u samples per pixel instead of %u\n", QUICK_ENV, spec.spp, asked);
    /* --time-limit: each pass's own normalisation (frame_normalise), from
     * the scene kept until the render ends; else the render's, now. */
    int per_pass = mlt && a->time_limit > 0 && sc.settings.max_depth < PROTO_MLT_DEPTHS;
    fr_scene *keep = per_pass ? malloc(sizeof *keep) : NULL;
    if (per_pass && !keep) {
        fprintf(stderr, "franja render: out of memory for the scene\n");
        scn_free(&sc);
        return 1;
    } else if (per_pass) {
        spec.mlt_norm = im->mlt_norm;
        spec.mlt_depths = sc.settings.max_depth + 1;
    } else if (mlt && normalise(&sc, &spec, im->mlt_norm, &(norm_stop){im->stop, 0}, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        scn_free(&sc);
        return *im->stop ? 130 : 1;
    }
    /* Tone mapping: the scene's defaults, overridden by the command line. */
    im->tm = sc.tonemap;
    if (a->exposure_set)
        im->tm.exposure = a->exposure;
    if (a->curve)
        tm_curve_parse(a->curve, &im->tm.curve);
    /* The materials' names, for the metadata of material_id and
     * crypto_material. */
    im->n_materials = sc.n_materials;
    if (spec.passes && sc.n_material_names && (im->mat_names = malloc(sc.n_material_names * sizeof *im->mat_names)))
        memcpy(im->mat_names, sc.material_names, (im->n_mat_names = sc.n_material_names) * sizeof *im->mat_names);
    if (spec.passes && sc.n_object_names && (im->obj_names = malloc(sc.n_object_names * sizeof *im->obj_names)))
        memcpy(im->obj_names, sc.object_names, (im->n_obj_names = sc.n_object_names) * sizeof *im->obj_names);
    if (spec.passes && sc.n_group_names && (im->group_names = malloc(sc.n_group_names * sizeof *im->group_names)))
        memcpy(im->group_names, sc.group_names, (im->n_group_names = sc.n_group_names) * sizeof *im->group_names);
    if (keep)
        *keep = sc;            /* the scene moves: its arrays stay where they are */
    else
        scn_free(&sc);
    im->spec = spec;
    if ((spec.passes & (1u << PASS_CRYPTO_MATERIAL | 1u << PASS_CRYPTO_OBJECT)) && !out_has_ext(a->out, "exr"))
        fprintf(stderr, "franja render: warning: crypto_material and crypto_object are written to .exr outputs "
                "only; %s gets the other passes\n", a->out);

    im->have = calloc(spec.height, 1);
    im->base = calloc(spec.height, sizeof *im->base);
    im->rgb = calloc((size_t)spec.width * spec.height * 3, sizeof *im->rgb);
    frame_passes *ps = &im->ps;
    *ps = (frame_passes){.a = a, .jobdir = im->jobdir, .spec = spec, .cap = spec.spp, .crop_rows = crop_rows,
                   .have = im->have, .base = im->base, .rgb = im->rgb, .scratch = NULL,
                   .mlt_scene = keep, .mlt_norm = im->mlt_norm, .stop = im->stop};
    /* --time-limit keeps the passes of its last complete pass beside rgb. */
    if (spec.passes && a->time_limit > 0)
        im->passes = ps->passes = calloc((size_t)spec.width * spec.height * pass_channels(spec.passes),
                                         sizeof *im->passes);
    if (!im->have || !im->base || !im->rgb || !(ps->scratch = calloc(spec.height, 1)) ||
        (spec.passes && a->time_limit > 0 && !im->passes)) {
        fprintf(stderr, "franja render: out of memory for a %ux%u image\n", spec.width, spec.height);
        return 1;
    }
    int jr = job_open(im->jobdir, &spec, a->resume, &err);
    if (jr) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return jr == JOB_REFUSED ? 2 : 1;
    }
    /* What the job directory holds toward the samples asked for. */
    if (frame_plan(ps, spec.spp, &err)) {
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
        uint32_t from = lo == hi && lo > 0 && lo < spec.spp ? lo : 0;
        if (mlt && kept_passes(ps, &from, &err)) {
            fprintf(stderr, "franja render: %s\n", err.msg);
            return 1;
        }
        if (from) {
            if (frame_plan(ps, from, &err) || frame_pass_image(ps, &err)) {
                fprintf(stderr, "franja render: %s\n", err.msg);
                return 1;
            }
            ps->reached = from;
            fprintf(stderr, "franja: the job holds a whole image with %u samples per pixel; passes go on from it\n",
                    from);
            if (frame_plan(ps, spec.spp, &err)) {
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
int frame_write(frame_image *im, const char *used)
{
    frame_settings *a = &im->a;
    frame_passes *ps = &im->ps;
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
    } else if (spec.passes && !im->passes && !(im->passes = malloc((size_t)spec.width * spec.height *
                                                    pass_channels(spec.passes) * sizeof *im->passes))) {
        fprintf(stderr, "franja render: out of memory for the render passes of a %ux%u image\n", spec.width,
                spec.height);
        return 1;
    } else if (im->crop_rows ? crop_stitch(im->jobdir, &spec, &a->win, im->rgb, im->passes, im->have, &err)
                             : job_stitch_passes(im->jobdir, &spec, im->rgb, im->passes, &a->tr.notes, &err)) {
        fprintf(stderr, "franja render: %s\n", err.msg);
        return 1;
    }
    job_spec out_spec = spec;
    float *rgb = im->rgb;
    uint32_t nch = pass_channels(spec.passes);
    if (a->crop) {
        crop_black(&a->win, rgb, spec.width, spec.height);
        if (im->passes)
            crop_black_n(&a->win, im->passes, spec.width, spec.height, nch);
        if (a->crop_output) {
            /* The window moves to the start of the buffer. */
            size_t wn = (size_t)(a->win.x1 - a->win.x0) * (a->win.y1 - a->win.y0);
            float *w = malloc(wn * 3 * sizeof *w), *wp = im->passes ? malloc(wn * nch * sizeof *wp) : NULL;
            if (!w || (im->passes && !wp)) {
                free(w);
                free(wp);
                fprintf(stderr, "franja render: out of memory for the window\n");
                return 1;
            }
            crop_extract(&a->win, rgb, spec.width, w);
            free(rgb);
            rgb = im->rgb = ps->rgb = w;
            if (wp) {
                crop_extract_n(&a->win, im->passes, spec.width, nch, wp);
                free(im->passes);
                im->passes = ps->passes = wp;
            }
            out_spec.width = a->win.x1 - a->win.x0;
            out_spec.height = a->win.y1 - a->win.y0;
        }
    }
    out_meta meta;
    out_meta_make(&meta, &spec, a->reproducible ? -1 : clock_now() - im->t0, a->reproducible ? NULL : used);
    if (a->reproducible)
        out_meta_set_time(&meta, reproducible_epoch());
    a->io.attrs = meta.attrs;
    crypto_names names = {im->mat_names, im->n_mat_names, NULL}, objects = {im->obj_names, im->n_obj_names, "object"},
                 groups = {im->group_names, im->n_group_names, "group"};
    if (passout_write(a->out, rgb, &im->passes, &out_spec, &im->tm, &a->io, &names, im->n_materials, &objects,
                      &groups, &err)) {
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
    progress_stop(im->pg, "ok", spec.spp);
    im->pg = NULL;
    mon_status(im->mon, "done");
    mon_stop(im->mon);
    im->mon = NULL;
    if (!a->keep_job)
        job_remove(im->jobdir);
    else if (job_sums(&spec))
        job_prune(im->jobdir, &spec); /* rows kept with more samples make the fewer useless */
    joblock_release(&im->lk, !a->keep_job);
    im->locked = 0;
    fprintf(stderr, "franja: wrote %s (%ux%u, %u spp) in %.2f s\n", a->out, out_spec.width, out_spec.height, spec.spp,
            clock_now() - im->t0);
    return 0;
}

/* Ends the image: after a failure (rc not 0) its job directory stays for
 * --resume if it holds rows and the lock is given up; frees it. */
void frame_close(frame_image *im, int rc)
{
    progress_stop(im->pg, *im->stop ? "interrupted" : "failed", im->spec.spp);
    mon_stop(im->mon);
    if (rc && im->locked)
        unlock_with(&im->lk, rc);
    free(im->have);
    free(im->base);
    free(im->ps.scratch);
    free(im->rgb);
    free(im->passes);
    free(im->mat_names);
    free(im->obj_names);
    free(im->group_names);
    if (im->ps.mlt_scene)
        scn_free(im->ps.mlt_scene);
    free(im->ps.mlt_scene);
    free(im);
}

/* Frees what an image holds but its settings (a frame that is written). */
void frame_shrink(frame_image *im)
{
    free(im->have);
    free(im->base);
    free(im->ps.scratch);
    free(im->rgb);
    free(im->passes);
    im->passes = im->ps.passes = NULL;
    im->have = NULL;
    im->base = NULL;
    im->ps.scratch = NULL;
    im->rgb = im->ps.rgb = NULL;
    im->ps.have = NULL;
    im->ps.base = NULL;
    if (im->ps.mlt_scene)
        scn_free(im->ps.mlt_scene);
    free(im->ps.mlt_scene);
    im->ps.mlt_scene = NULL;
}
