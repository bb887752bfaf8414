/** @file protocol.h
 * The worker protocol: everything franja (the coordinator) and
 * franja-worker must agree on, written once and used by both.
 *
 * - The limits of a render (image size, samples per pixel, path depth):
 *   proto_limits.h, included here.
 * - The slab command line: the coordinator builds it (proto_slab_argv),
 *   the worker reads it (proto_parse_args), so the two cannot drift apart.
 * - The `--version` line, which names the release and the binary scene
 *   format a worker reads, and its parser (the coordinator refuses hosts
 *   whose workers differ).
 * - `--check`: the worker validates a scene file and prints its content
 *   hash; the coordinator trusts a cached copy only when the hash matches.
 * - The probe: one POSIX shell command that reports a host's architecture,
 *   OS, processor count and worker version, and its parser.
 *
 * Nothing here touches a file, a process or the network: these are
 * strings, parsers and constants.
 */
#ifndef FRANJA_PROTOCOL_H
#define FRANJA_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"
#include "image.h"
#include "proto_limits.h"

/** The release of this source tree, in every `--version` line. */
#define FRANJA_VERSION "0.1.0"

/** One slab as the coordinator asks a worker for it. */
typedef struct {
    const char *scene;         /**< the binary scene's path on the host */
    uint32_t y0, y1;           /**< rows [y0, y1) of the full image */
    uint32_t width, height;    /**< full image size; both 0 = the scene's */
    uint32_t spp;              /**< samples per pixel; 0 = the scene's */
    img_format format;         /**< output format */
    const char *out;           /**< output file; "-" = standard output */
    int lifeline;              /**< --lifeline: standard input is the coordinator's line; the worker ends
                                    when it reaches its end (worker/lifeline.h) */
    int integrator;            /**< 1 + FR_INTEGRATOR_* (scene.h); 0 = the scene's (no --integrator) */
    float noise_threshold;     /**< adaptive sampling threshold in (0, 1]; 0 = the scene's */
    int sums;                  /**< --sums: the PF partial carries its sample sums (image.h) */
    const char *continue_from; /**< --continue FILE: a partial with sums of the same slab and fewer samples,
                                    whose samples are not rendered again; NULL = none */
    uint32_t passes;           /**< --passes LIST: render passes (passes.h mask) in the PF partial; 0 = none */
    const float *mlt_norm;     /**< --mlt-norm LIST: Metropolis light transport's b_d per depth (mlt_path.h),
                                    mlt_depths entries, computed once by the coordinator; NULL = none (the
                                    worker computes it) */
    uint32_t mlt_depths;       /**< entries of mlt_norm, 1..PROTO_MLT_DEPTHS */
} proto_slab;

/** The most depths (max_depth + 1) whose Metropolis normalisation travels
 * on a worker's command line: 8 hex digits and a comma each, well inside
 * a remote command's bounds.  Deeper scenes' workers compute their own. */
#define PROTO_MLT_DEPTHS 128u

/** A worker command line built by proto_slab_argv: argv points into the
 * struct's own buffers (and at the caller's strings), NULL-terminated,
 * without the program name. */
typedef struct {
    const char *argv[24];
    char rows[32], size[32], spp[16], noise[32], passes[400], mlt_norm[PROTO_MLT_DEPTHS * 9];
} proto_argv;

/** Builds the worker arguments that ask for slab s.  Fails when a number
 * is out of the protocol's limits or the rows are empty. */
int proto_slab_argv(const proto_slab *s, proto_argv *a, fr_error *err);

/** What a worker command line asks for. */
typedef enum {
    PROTO_RENDER = 0,          /**< render the slab */
    PROTO_CHECK,               /**< --check: validate the scene, print its hash */
    PROTO_VERSION,             /**< --version */
    PROTO_HELP,                /**< --help / -h */
    PROTO_FEATURES,            /**< --features: print what this build can do besides rendering */
    PROTO_UNPACK               /**< --unpack IN --scene OUT: a compressed scene into the cache */
} proto_mode;

/** A parsed worker command line. */
typedef struct {
    proto_mode mode;
    proto_slab slab;           /**< scene, rows, size, spp, format, out */
    int have_rows;             /**< --rows was given */
    const char *unpack;        /**< --unpack: the compressed scene (the output is slab.scene) */
    float mlt_norm[PROTO_MLT_DEPTHS]; /**< --mlt-norm's values (slab.mlt_norm points here) */
} proto_request;

/** Reads a worker command line (argv[0] is the program).  Checks the syntax
 * and the limits; whether the rows fit the image is the worker's to check
 * once the scene is loaded.  A usage error returns -1 with err saying which
 * option is wrong and what was expected (the text a worker prints after
 * "franja-worker: "). */
int proto_parse_args(int argc, char *const *argv, proto_request *r, fr_error *err);

/** Parses an integrator name, "path", "bdpt" or "mlt", into FR_INTEGRATOR_*; -1
 * if it is neither. */
int proto_integrator_parse(const char *name, int *out);

/** The name of integrator i (FR_INTEGRATOR_*), as --integrator takes it. */
const char *proto_integrator_name(int i);

/** Parses "WxH" with 1 <= W, H <= PROTO_MAX_SIZE; -1 if it is not that. */
int proto_parse_size(const char *s, uint32_t *w, uint32_t *h);

/** Writes "PROGRAM VERSION scene-format N" (this build's version and
 * binary scene format) into out[cap]. */
void proto_version_line(const char *program, char *out, size_t cap);

/** Writes the second line of a worker's `--version`: "walk NAME", the BVH
 * walk this process runs (trace.h: portable, avx2 or avx512), then the
 * walks the processor can run in brackets. */
void proto_walk_line(char *out, size_t cap);

/** A parsed `--version` line. */
typedef struct {
    char program[32];          /**< "franja-worker" */
    char version[32];          /**< "0.1.0" */
    int scene_format;          /**< the binary scene format it reads */
} proto_version;

/** Parses a `--version` line ("PROGRAM VERSION scene-format N").  Fails,
 * quoting the line, when it has another shape. */
int proto_parse_version(const char *line, proto_version *v, fr_error *err);

/** The arguments (no program name) that make a worker check the scene at
 * path and print its content hash: write them to argv[4]. */
void proto_check_argv(const char *path, const char *argv[4]);

/** The word `--features` prints when the worker can unpack a scene sent
 * compressed with zstd (`--unpack`). */
#define PROTO_FEATURE_UNPACK "unpack-zstd"

/** Fills argv (NULL-terminated) with the worker arguments (after the program) that
 * unpack the compressed scene `in` into `out`: the scene is written under
 * a temporary name beside `out`, checked (its content hash, as --check)
 * and renamed to `out`; `in` is removed whatever happens.  Prints the
 * hash as --check does. */
void proto_unpack_argv(const char *in, const char *out, const char *argv[6]);

/** Whether a `--features` answer (len bytes: words separated by blanks)
 * has the word `feature`. */
int proto_has_feature(const char *out, size_t len, const char *feature);

/** Reads the output of `--check` (len bytes): one line of 16 hex digits.
 * Fails if it is anything else. */
int proto_parse_check(const char *out, size_t len, uint64_t *hash, fr_error *err);

/** The probe, as a command for a POSIX shell run as
 * `sh -c PROTO_PROBE_SCRIPT WORKER`: four lines, uname -m, uname -s, the
 * number of online processors and the worker's `--version` line, then the
 * rest of `--version` (its walk line, from workers that print one).  The
 * worker path travels as $0, never inside the script. */
extern const char PROTO_PROBE_SCRIPT[];

/** The most processors a probe's answer is believed to report: a host
 * saying more is taken to have this many (proto_host.cores_reported keeps
 * what it said, so that the caller can tell the person). */
#define PROTO_MAX_CORES 4096

/** What a host says about itself (the probe's answer).  Its text fields
 * hold no control characters (proto_printable). */
typedef struct {
    char arch[32];             /**< uname -m */
    char os[64];               /**< uname -s */
    int cores;                 /**< online processors, at most PROTO_MAX_CORES */
    uint32_t cores_reported;   /**< the number the host gave (may exceed PROTO_MAX_CORES) */
    char version[128];         /**< the worker's --version line */
    char walk[16];             /**< the BVH walk its --version names; "" from a worker that names none */
} proto_host;

/** Parses the probe's output (len bytes).  Fails if a line is missing, too
 * long, or the processor count is not a positive number below 2^32.
 * Control characters in the lines become '?'. */
int proto_parse_probe(const char *out, size_t len, proto_host *h, fr_error *err);

/** Replaces every ASCII control character (below 0x20, and 0x7f) of the
 * NUL-terminated s with '?', in place, so that text from another machine
 * cannot drive the terminal it is printed on.  Returns s. */
char *proto_printable(char *s);

#endif
