/** @file mlt_path.h
 * Metropolis light transport over Franja's bidirectional path space:
 * primary-sample-space Metropolis (mlt.h; Kelemen et al. 2002) whose
 * target is one bidirectional strategy of one path at a time, chosen by a
 * primary sample (multiplexed MLT: Hachisuka, Kaplanyan and Dachsbacher
 * 2014, "Multiplexed Metropolis light transport").
 *
 * A state is (depth d, numbers u).  Its first number of stream 2 picks one
 * of the n_d strategies (s, t) with s + t = d + 2 that bidirectional path
 * tracing uses (n_0 = 1: (0, 2); else d + 2, t = 1..d + 2), stream 0 feeds
 * the camera subpath and stream 1 the light subpath (bd_path).  Its value
 * is C = n_d * w_st * C_st (the strategy's contribution times its MIS
 * weight, over the probability 1 / n_d of picking it) at the raster
 * position the path lands on, and the target is f = luminance(C).  The
 * depth stays fixed along a chain, as in Hachisuka et al.
 *
 * Normalisation (b) and start: b_d, the integral of f over depth d's
 * states, is the mean luminance of depth d's paths over the image, which
 * bidirectional path tracing estimates (bd_depth_means, about
 * MLT_BOOTSTRAP_BDPT samples with all strategies); b = sum of b_d.  A
 * bootstrap of n independent states (state i: depth i mod (max_depth + 1),
 * numbers from seed i) gives the chains' starts.  Chain k starts from bootstrap
 * sample j picked with probability f_j / sum f (its depth so has
 * probability b_d / b, and its state is distributed about as f is: little
 * start-up bias), and from there mutates with its own generator, seed k.
 * The picks are systematic resampling: chain k of K takes the state at
 * (k + u_k) / K of the cumulative f, so that each depth gets its share
 * b_d / b of the chains to within one chain (independent picks would
 * leave a few chains' worth of noise in each depth's brightness).
 *
 * Estimate: each mutation splats, expected-value style, the proposal y
 * with weight a and the current state x with weight 1 - a (a, the
 * acceptance probability; Veach 1997, sec. 11.5), each as C / f * b; a
 * pixel's value is the sum of its splats over the mutations per pixel.
 *
 * Determinism: a chain is a pure function of the scene, its index and
 * the bootstrap, which is itself a pure function of the scene; splats are
 * 64-bit fixed-point sums (splat.h).  So any set of chains rendered
 * anywhere, added in any order, gives the same bits.
 */
#ifndef FRANJA_MLT_PATH_H
#define FRANJA_MLT_PATH_H

#include <stdint.h>

#include "error.h"
#include "scene.h"

/** Bootstrap states of a render: 16 per pixel, at least 2^15 and at most
 * MLT_BOOTSTRAP (2^18: b within about 1 % on the Cornell box, 0.2 s). */
#define MLT_BOOTSTRAP 262144u
#define MLT_BOOTSTRAP_MIN 32768u
/** Bidirectional samples that estimate b_d (bd_depth_means). */
#define MLT_BOOTSTRAP_BDPT 32768u
/** Probability of a large step (Kelemen et al.'s suggestion is 0.1-0.5). */
#define MLT_P_LARGE 0.3f

/** The bootstrap: b and the cumulative f of its states. */
typedef struct {
    double b;                  /**< sum over depths of the mean f: the integral of the target */
    double *bd;                /**< nd entries: b_d, the integral of f over depth d (owned) */
    uint32_t nd;               /**< depths, max_depth + 1 */
    uint32_t *off;             /**< nd + 1 entries: depth d's states are cdf positions off[d]..off[d+1]-1 (owned) */
    uint32_t n;                /**< states */
    double *cdf;               /**< n + 1 entries, the states ordered by depth: cdf[p] = sum of f over those before p (owned) */
} mlt_boot;

/** 0 when Metropolis light transport can render scene s (what bd_supported
 * accepts, and no motion blur); otherwise -1 with err saying why. */
int mlt_supported(const fr_scene *s, fr_error *err);

/** Run the bootstrap of scene s into *bt (n states); -1 with err when out
 * of memory.  Free with mlt_boot_free. */
int mlt_bootstrap(const fr_scene *s, uint32_t n, mlt_boot *bt, fr_error *err);
void mlt_boot_free(mlt_boot *bt);

/** Run chains [k0, k1) of n_chains, each of `mutations` mutations, adding their
 * splats to splat (3 fixed-point sums per pixel of the whole image,
 * caller-owned) as values that make the image when divided by the
 * mutations per pixel, total mutations / (width * height) (spl_value's
 * spp).  -1 with err when out of memory. */
int mlt_chains(const fr_scene *s, const mlt_boot *bt, uint32_t k0, uint32_t k1, uint32_t n_chains, uint64_t mutations,
               uint64_t *splat, fr_error *err);

/** Render rows [y0, y1) of scene s by MLT, as franja-worker does: row y
 * stands for chain y, of width * spp mutations (so a whole image has spp
 * mutations per pixel); rgb (the rows' own pixels) is zeroed and splat
 * receives the chains' splats over the whole image (bd_render_rows'
 * contract: the image is rgb plus spl_resolve with spp).  -1 with err when
 * unsupported or out of memory. */
int mlt_render_rows(const fr_scene *s, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat, fr_error *err);

#endif
