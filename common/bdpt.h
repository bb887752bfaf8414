/** @file bdpt.h
 * Bidirectional path tracing (Veach 1997, ch. 10; in the formulation of
 * pbrt-v3, ch. 16.3).
 *
 * Each pixel sample traces a camera subpath x0 (a lens point) x1 x2 ...
 * and a light subpath y0 (a point on a light) y1 y2 ..., and forms every
 * path of at most max_depth bounces by joining the first s light vertices
 * to the first t camera vertices (a strategy (s, t)): s = 0 is the camera
 * subpath hitting an emitter, s = 1 samples a light point for a camera
 * vertex (next-event estimation), t = 1 joins a light vertex to a point
 * sampled on the lens (light tracing: its light lands on another pixel, a
 * splat), the others join two subpath vertices by a shadow ray.  Every
 * strategy is weighted by the power heuristic against all the others that
 * could have made the same path, with the pdfs of both directions kept at
 * each vertex in area measure and the ratios of neighbouring strategies
 * multiplied out (no pdf is recomputed beyond the two vertices at each end
 * of the connection).  (1, 1), a light point joined to a lens point, is
 * left out: it only renders lights seen directly, which the camera
 * subpath hitting the light (0, 2) renders without noise beyond the
 * pixel's own (it gets weight 1), and it would add a shadow ray and a
 * splat to every sample.
 *
 * Vertices reached by a delta lobe (mirror, smooth glass) are never
 * connection ends; a chain of them between two other vertices counts as
 * one step whose density is the direction's at the end that sampled it
 * times the cosine at the other end (the chain's geometry term, common to
 * both directions, cancels from the ratios), so that caustics seen through
 * glass weigh light tracing against camera paths that hit the lamp by the
 * true ratio of their densities.  Light subpaths carry importance: refraction does not
 * scale it by eta^2 as it does radiance, and shading normals get Veach's
 * adjoint correction |wo.ns||wi.ng| / (|wo.ng||wi.ns|).
 *
 * Random numbers: the camera subpath of sample i of pixel (x, y) uses the
 * pixel's sampler from dimension 0 in path tracing's order (pathtrace.h),
 * the light subpath the same pixel sample's numbers from dimension pair
 * 65536 on: light pick and side, light point, direction, then per vertex
 * the lobe, the direction, the lens point for its light-tracing splat, and
 * Russian roulette.  So each light subpath belongs to one pixel sample, and
 * a split of the image into rows traces every light subpath once.
 *
 * Motion blur: a sample draws its time across the shutter after the
 * camera's lens pair (as the path tracer does; scenes without motion draw
 * none); its light subpath, connections and shadow rays all see the
 * scene at that time, and its camera rays, lens points and light-tracing
 * splats use the camera at that time (camera.h's cam_at).  Scenes that
 * use participating media (fog, a medium inside a shape) are refused
 * (bd_supported).
 */
#ifndef FRANJA_BDPT_H
#define FRANJA_BDPT_H

#include "error.h"
#include "passes.h"
#include "scene.h"

/** Which strategies to use.  {-1, -1, -1}: all of them with MIS weights
 * (what images use).  s, t >= 0: that strategy alone with weight 1, an
 * unbiased estimator of the paths of depth s + t - 2 (tests).  depth >= 0
 * (with s = t = -1): only paths of that many bounces, MIS-weighted. */
typedef struct {
    int s, t;
    int depth;
} bd_strategy;

/** Where light tracing sends its splats: called with a pixel of the image
 * and the radiance to add to its sum (the pixel's value gains L / spp). */
typedef void (*bd_splat_fn)(void *ctx, uint32_t x, uint32_t y, float r, float g, float b);

/** A caller's source of numbers in [0, 1) for bd_path: next(ctx) is the
 * next number of the stream. */
typedef struct {
    float (*next)(void *ctx);
    void *ctx;
} bd_stream;

/** Working memory for one thread: the two subpaths. */
typedef struct bd_work bd_work;

/** 0 when bidirectional path tracing can render scene s; otherwise -1
 * with err saying why (participating media). */
int bd_supported(const fr_scene *s, fr_error *err);

/** Allocate working memory for scene s (subpaths of max_depth + 2
 * vertices); NULL when out of memory.  Free with bd_work_free. */
bd_work *bd_work_new(const fr_scene *s);
void bd_work_free(bd_work *w);

/** Sample `index` of pixel (x, y): returns the radiance of the strategies
 * with t >= 2 (their light arrives at this pixel) and sends each t = 1
 * contribution to splat(ctx, ...).  Non-finite results are dropped (0, no
 * splat) the same way everywhere.  The scene must pass bd_supported. */
vec3 bd_sample(const fr_scene *s, bd_work *w, const bd_strategy *st, uint32_t x, uint32_t y, uint32_t index,
               bd_splat_fn splat, void *ctx);

/** One strategy (s_, t) of one path, for primary-sample-space Metropolis
 * (mlt_path.h): the camera subpath of t vertices from the numbers of cam
 * (its first two place the camera ray anywhere in the image: raster x =
 * u0 * width, y = u1 * height, the pixel's lens and subpath numbers after
 * them in bd_sample's order), the light subpath of s_ vertices from light
 * (bd_sample's order from dimension pair 65536), joined as bd_sample joins
 * them.  Returns the contribution times its MIS weight (the one bd_sample
 * gives it among all strategies), and in *rx, *ry the raster position
 * (continuous, in [0, width) x [0, height)) where it lands.  0 when the
 * subpaths end before t or s_ vertices, the strategy is out of range
 * ((1, 1), a depth s_ + t - 2 beyond max_depth) or the result is not
 * finite.  The scene must pass bd_supported. */
vec3 bd_path(const fr_scene *s, bd_work *w, int s_, int t, const bd_stream *cam, const bd_stream *light, float *rx,
             float *ry);

/** The mean luminance over the image of the paths of each depth
 * (by_depth: max_depth + 1 entries, caller-owned), from about n samples
 * with all strategies, splats included: each depth's share of the image.
 * Samples 0..spp-1 of every pixel (spp = n / pixels rounded up) when n is
 * over the pixel count, else sample 0 of n pixels spread evenly over the
 * image.  -1 when out of memory. */
int bd_depth_means(const fr_scene *s, uint32_t n, double *by_depth);

/** Asked between blocks of bd_depth_means_mt, from any of its threads at
 * once: non-zero to stop. */
typedef int (*bd_stop_fn)(void *ctx);

/** bd_depth_means on `threads` threads (below 1 counts as 1) with the
 * same bits for any number of them: the samples, in the order above, are
 * cut into blocks of 4096 (the boundaries a function of n alone), each
 * block summed per depth in double from zero, and the blocks' sums added
 * in block order.  stop(ctx) (stop NULL: never) is asked before each
 * block; once it says stop, 1 with by_depth undefined (no partial means).
 * -1 when out of memory.  A thread that cannot start leaves its share to
 * the others. */
int bd_depth_means_mt(const fr_scene *s, uint32_t n, int threads, bd_stop_fn stop, void *ctx, double *by_depth);

/** Render rows [y0, y1) of s->settings' size and spp with all strategies:
 * rgb (3 floats per pixel, row y0 first, width*(y1-y0)*3) receives the
 * mean of the samples' own radiance, and splat (3 sums per pixel of the
 * whole image, caller-owned and zeroed, width*height*3) the fixed-point
 * sums of their light-tracing splats (splat.h).  The finished rows are
 * rgb plus spl_resolve of the splats of every slab.  Returns -1 with err
 * set when the scene is not supported or memory runs out. */
int bd_render_rows(const fr_scene *s, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat, fr_error *err);

/** bd_render_rows restricted to the paths of fewer than `below` bounces
 * (below >= 1; the subpaths are traced only as far as those need), at
 * spp samples per pixel (0: 1) whatever the scene's: rgb receives their
 * mean, and splat their light-tracing splats scaled by the scene's spp
 * over spp, so that the image is still rgb plus spl_resolve with the
 * scene's spp (the short paths of Metropolis light transport,
 * mlt_path.h).  -1 with err as bd_render_rows. */
int bd_render_short(const fr_scene *s, uint32_t y0, uint32_t y1, int below, uint32_t spp, float *rgb,
                    uint64_t *splat, fr_error *err);

/** The render passes bidirectional path tracing fills (passes.h), from
 * each sample's camera subpath: the first hit's depth, position,
 * material_id, object_id and Cryptomatte, and albedo and normal at the
 * first surface that is not a perfect mirror or smooth glass (through
 * those, as the path tracer).  The light passes, light groups and
 * variance are not filled: light tracing's splats land on other pixels
 * than the sample's own. */
#define BD_PASSES                                                                                                  \
    (1u << PASS_ALBEDO | 1u << PASS_NORMAL | 1u << PASS_DEPTH | 1u << PASS_POSITION | 1u << PASS_MATERIAL_ID |     \
     1u << PASS_CRYPTO_MATERIAL | 1u << PASS_OBJECT_ID | 1u << PASS_CRYPTO_OBJECT)

/** bd_render_rows, with the render passes `passes` (a subset of
 * BD_PASSES, else -1 with err set) of the rows into out
 * (width*(y1-y0)*pass_channels(passes) floats, top row first; NULL when
 * passes is 0). */
int bd_render_rows_passes(const fr_scene *s, uint32_t y0, uint32_t y1, float *rgb, uint64_t *splat, uint32_t passes,
                          float *out, fr_error *err);

#endif
