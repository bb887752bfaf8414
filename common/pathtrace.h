/** @file pathtrace.h
 * The integrator: unidirectional path tracing with next-event estimation
 * and multiple importance sampling, through participating media, and the
 * camera.
 *
 * A path is built from the pieces in vertex.h: the next vertex along a ray
 * (through media), light sampling at each vertex, scattering onward, and
 * Russian roulette after a few bounces.  Radiance estimates are linear
 * RGB.  A pixel's value is the mean of its samples; each sample's random
 * numbers come from sampler.h in a fixed order (camera, then per vertex:
 * medium segments, light pick and lobe, light point, direction, roulette),
 * so any rows rendered anywhere give the same bits.
 */
#ifndef FRANJA_PATHTRACE_H
#define FRANJA_PATHTRACE_H

#include "error.h"
#include "scene.h"
#include "trace.h"

/** How direct light is estimated.  Only PT_MIS is used for images; the
 * others exist so tests can show they agree (MIS is unbiased) and measure
 * what each technique brings.  PT_MIS_DISTANCE is PT_MIS with media
 * sampled by free-flight distance alone, without equiangular sampling. */
typedef enum { PT_MIS = 0, PT_LIGHT_ONLY, PT_BSDF_ONLY, PT_MIS_DISTANCE } pt_strategy;

/** The primary ray of pixel (x, y) for pixel numbers (px, py) and lens
 * numbers (lx, ly) in [0,1)^2: box filter of one pixel, thin lens when the
 * camera has an aperture.  The direction is unit length. */
fr_ray pt_camera_ray(const fr_scene *s, uint32_t x, uint32_t y, float px, float py, float lx, float ly);

/** pt_camera_ray from camera c (camera.h's cam_at: the camera at a time
 * within the shutter) instead of the scene's. */
fr_ray pt_camera_ray_from(const fr_scene *s, const fr_camera *c, uint32_t x, uint32_t y, float px, float py,
                          float lx, float ly);

/** Radiance of sample `index` of pixel (x, y); 0 for a sample that came
 * out NaN or infinite (dropped the same way everywhere).  The sample's
 * numbers: the pixel pair, the lens pair (skipped by a pinhole), then,
 * only in a scene with motion (scene.h's fr_motion), a pair whose first
 * number is the sample's time across the shutter, then the path's. */
vec3 pt_sample(const fr_scene *s, pt_strategy strategy, uint32_t x, uint32_t y, uint32_t index);

/** Render rows [y0, y1) with s->settings' size and spp into rgb
 * (3 floats per pixel, row y0 first, caller-owned, width*(y1-y0)*3).
 * With s->settings.noise_threshold E > 0 (adaptive sampling), a pixel
 * takes at least max(16, spp / 16) samples, then stops at the first
 * multiple of 16 samples where the standard error of its mean luminance
 * is at most E times that mean (the mean taken as at least 1e-3); it
 * never takes more than spp.  The decision reads only the pixel's own
 * samples, so any split of the rows renders the same bits. */
void pt_render_rows(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, float *rgb);

/** pt_render_rows that also renders the render passes in the mask
 * `passes` (passes.h; 0: none, out not used) into out:
 * pass_channels(passes) floats per pixel, row y0 first, caller-owned.
 * The beauty has the bits of pt_render_rows either way. */
void pt_render_rows_passes(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, float *rgb,
                           uint32_t passes, float *out);

/** Like pt_render_rows without adaptive sampling (noise_threshold is
 * ignored), keeping each pixel's sums: sums (width*(y1-y0)*3 doubles)
 * holds the sums of samples [0, first) on entry (zeros for first = 0) and
 * of samples [0, spp) on return, and rgb receives sum / spp.  Continuing
 * from `first` gives the bits of a render of every sample at once. */
void pt_render_rows_sums(const fr_scene *s, pt_strategy strategy, uint32_t y0, uint32_t y1, uint32_t first,
                         double *sums, float *rgb);

#endif
