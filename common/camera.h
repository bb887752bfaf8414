/** @file camera.h
 * The camera as a sensor: where a direction lands on the image, how
 * much importance it carries, and the densities with which camera rays
 * are sampled (what light tracing and bidirectional path tracing need).
 *
 * pathtrace.h's pt_camera_ray makes the rays: a point uniform in a pixel
 * of an image plane at distance 1 along the view axis (box filter), seen
 * from the pinhole or from a point uniform on the lens disk (thin lens,
 * radius `aperture`, aimed at the focal plane `focus` along the axis).
 * The functions here invert that mapping.  Conventions (pbrt's): the image
 * plane has area A = 4 tan_half^2 W/H at distance 1; a pinhole counts as a
 * lens of area 1 and a thin lens as one of area pi aperture^2; the
 * importance of a ray leaving a lens point at angle theta to the axis
 * toward a point of the image is We = 1 / (A * lens_area * cos^4 theta),
 * normalized over the whole image, so light-tracing splats are divided by
 * the samples per pixel (not by the pixel count).
 */
#ifndef FRANJA_CAMERA_H
#define FRANJA_CAMERA_H

#include "scene.h"

/** Offset from the camera position of the lens point for lens numbers
 * (lx, ly) in [0,1)^2: uniform on the disk of radius `aperture` in the
 * plane of right and upv (concentric mapping, which keeps the numbers'
 * stratification); zero for a pinhole. */
vec3 cam_lens(const fr_camera *c, float lx, float ly);

/** The camera at time u in [0, 1] across the shutter (scene.h's
 * fr_motion) into *out: s->camera itself at u = 0 or when the camera does
 * not move; otherwise position, field of view, aperture and focus blended
 * linearly toward the shutter-close camera, and the view axis and up
 * blended and made orthonormal again (right = forward x up, as the
 * builder derives them). */
void cam_at(const fr_scene *s, float u, fr_camera *out);

/** Lens area as the importance convention counts it: pi aperture^2, or 1
 * for a pinhole. */
float cam_lens_area(const fr_camera *c);

/** Where a ray leaving lens point `o` (a point of the lens disk, the
 * position for a pinhole) in unit direction w lands on the image: the
 * continuous raster position (pixel x + fraction, top row y = 0) in *rx,
 * *ry.  Returns 1 when it lands inside the image (of s->settings' size),
 * 0 when it points away from the image or outside it. */
int cam_raster(const fr_scene *s, vec3 o, vec3 w, float *rx, float *ry);

/** Importance We of the ray from lens point o in unit direction w (0
 * outside the image) through camera c (s->camera, or cam_at's camera at a
 * sample's time; the image's size is s->settings'), in *pdf_dir the
 * solid-angle density with which pt_camera_ray_from picks w given o (0
 * outside), and, when rx and ry are not NULL and the ray lands inside,
 * its raster position as cam_raster gives for that camera. */
float cam_importance(const fr_scene *s, const fr_camera *c, vec3 o, vec3 w, float *pdf_dir, float *rx, float *ry);

/** The ray cone of a camera ray (Akenine-Moller et al. 2019, "Texture
 * Level of Detail Strategies for Real-Time Ray Tracing"): the angle one
 * pixel spans at the image's centre, 2 tan(vfov / 2) / height, radians,
 * times max(1/8, 1/sqrt(spp)) as pbrt-v4 scales its ray differentials:
 * the pixel is already averaged over its spp samples, so each sample
 * need only filter its share of it.  A ray's cone is this angle times the
 * distance it travelled (through perfect mirrors and glass, whose
 * flat-surface approximation keeps the angle); a thin lens's aperture is
 * not counted. */
float cam_pixel_spread(const fr_scene *s);

/** The footprint on a surface (fr_surface.footprint) of a cone `width`
 * wide arriving along unit direction d at a surface of unit normal ng:
 * width / sqrt|cos|, the width of the disk whose area is that of the
 * cone's elliptical section (width across, width / |cos| along); 0 when
 * the ray grazes the surface (cos = 0). */
float cam_footprint(float width, vec3 ng, vec3 d);

#endif
