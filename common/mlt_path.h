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
 * bidirectional path tracing estimates (bd_depth_means, with all
 * strategies); b = sum of b_d.  It is computed once per render (by the
 * coordinator, which hands it to every worker: protocol.h's --mlt-norm)
 * from mlt_norm_samples samples.  The chains are shared out among the
 * depths in proportion to b_d (largest remainders, at least one for each
 * lit depth), so each depth gets its share of the mutations to within one
 * chain.  Chain k starts from a state of its own, picked among
 * MLT_START_CANDIDATES independent states of its depth in proportion to
 * f (importance resampling: distributed about as f is, so little
 * start-up bias), and from there mutates with its own generator.
 *
 * Estimate: each mutation splats, expected-value style, the proposal y
 * with weight a and the current state x with weight 1 - a (a, the
 * acceptance probability; Veach 1997, sec. 11.5), each as C / f * b; a
 * pixel's value is the sum of its splats over the mutations per pixel.
 *
 * Determinism: a chain is a pure function of the scene, its index and
 * the normalisation, which is itself a pure function of the scene; splats are
 * 64-bit fixed-point sums (splat.h).  So any set of chains rendered
 * anywhere, added in any order, gives the same bits.
 */
#ifndef FRANJA_MLT_PATH_H
#define FRANJA_MLT_PATH_H

#include <stdint.h>

#include "error.h"
#include "scene.h"

/** Mutations per bidirectional sample that estimates b_d
 * (mlt_norm_samples: one sample for every MLT_NORM_SHARE mutations of
 * the render, about a sixth of its time, so that b's error shrinks with
 * the render's), at least MLT_NORM_MIN and at most MLT_NORM_MAX. */
#define MLT_NORM_SHARE 16u
#define MLT_NORM_MIN 65536u
#define MLT_NORM_MAX 4194304u
/** Candidate states a chain's start is picked from; at most MLT_START_MAX
 * when they are all black. */
#define MLT_START_CANDIDATES 1024u
#define MLT_START_MAX 65536u
/** Probability of a large step (Kelemen et al.'s suggestion is 0.1-0.5). */
#define MLT_P_LARGE 0.3f

/** Veach's split (1997, sec. 11.4): paths of at most MLT_SHORT_DEPTH
 * bounces (emission seen directly and direct lighting) are rendered by
 * bidirectional path tracing at spp * MLT_SHORT_MUL / MLT_SHORT_DIV
 * samples per pixel (at least 1; bd_render_short), the chains cover only
 * the longer ones.  One sample per mutation: a quarter of that left 1.05
 * to 2.6 times more noise at equal time, twice that no less
 * (tests/bench/README.md). */
#ifndef MLT_SHORT_DEPTH
#define MLT_SHORT_DEPTH 1
#endif
#ifndef MLT_SHORT_MUL
#define MLT_SHORT_MUL 1u
#endif
#ifndef MLT_SHORT_DIV
#define MLT_SHORT_DIV 1u
#endif

/** The normalisation: b and b_d. */
typedef struct {
    double b;                  /**< sum over depths of the mean f: the integral of the target */
    double *bd;                /**< nd entries: b_d, the integral of f over depth d (owned) */
    uint32_t nd;               /**< depths, max_depth + 1 */
} mlt_boot;

/** 0 when Metropolis light transport can render scene s (what bd_supported
 * accepts, and no motion blur); otherwise -1 with err saying why. */
int mlt_supported(const fr_scene *s, fr_error *err);

/** Estimate b_d of scene s into *bt from n bidirectional samples
 * (bd_depth_means); -1 with err when out of memory.  Free with
 * mlt_boot_free. */
int mlt_bootstrap(const fr_scene *s, uint32_t n, mlt_boot *bt, fr_error *err);
void mlt_boot_free(mlt_boot *bt);

/** The bidirectional samples a render's normalisation takes: one for
 * every MLT_NORM_SHARE mutations of scene s's image (its size and spp),
 * within [MLT_NORM_MIN, MLT_NORM_MAX]. */
uint32_t mlt_norm_samples(const fr_scene *s);

/** *bt with b_d = bd[d] for d < nd (a normalisation handed over by the
 * coordinator); -1 with err when out of memory.  Free with mlt_boot_free. */
int mlt_boot_set(mlt_boot *bt, const float *bd, uint32_t nd, fr_error *err);

/** Run chains [k0, k1) of n_chains, each of `mutations` mutations, adding their
 * splats to splat (3 fixed-point sums per pixel of the whole image,
 * caller-owned) as values that make the image when divided by the
 * mutations per pixel, total mutations / (width * height) (spl_value's
 * spp).  -1 with err when out of memory. */
int mlt_chains(const fr_scene *s, const mlt_boot *bt, uint32_t k0, uint32_t k1, uint32_t n_chains, uint64_t mutations,
               uint64_t *splat, fr_error *err);

/** What the mutations of one path length did (mlt_chains_counted): [0]
 * small steps, [1] large steps. */
typedef struct {
    uint64_t proposed[2];
    uint64_t accepted[2];
} mlt_counts;

/** mlt_chains, also adding to counts[d] (bt->nd entries, caller-owned;
 * NULL: not counted) each mutation of path length d, by kind, and whether
 * it was accepted: the same splats, bit for bit.  For measurements
 * (tests/bench/mltstats.c). */
int mlt_chains_counted(const fr_scene *s, const mlt_boot *bt, uint32_t k0, uint32_t k1, uint32_t n_chains,
                       uint64_t mutations, uint64_t *splat, mlt_counts *counts, fr_error *err);

/** *out: bt with b_d = 0 for d <= short_depth (what the chains cover when
 * bidirectional path tracing renders those depths); -1 with err when out
 * of memory.  Free with mlt_boot_free. */
int mlt_boot_long(const mlt_boot *bt, int short_depth, mlt_boot *out, fr_error *err);

/** Render rows [y0, y1) of scene s by MLT, as franja-worker does: the
 * paths of at most MLT_SHORT_DEPTH bounces by bd_render_short of the
 * rows (spp * MLT_SHORT_MUL / MLT_SHORT_DIV samples per pixel), the
 * longer ones by chains (mlt_boot_long): row y stands for chain y, of
 * width * spp mutations (so a whole image has spp mutations per pixel),
 * normalised by bt (NULL: computed here, as the
 * coordinator does, mlt_bootstrap of mlt_norm_samples); rgb (the rows' own
 * pixels) receives the short paths' own radiance and splat their
 * light-tracing splats and the chains' splats over the whole image
 * (bd_render_rows' contract: the image is rgb plus spl_resolve with
 * spp).  -1 with err when unsupported, bt has another number of depths
 * than the scene, or out of memory. */
int mlt_render_rows(const fr_scene *s, const mlt_boot *bt, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat,
                    fr_error *err);

#endif
