/** @file passout.h
 * The final image with its render passes (common/passes.h): one
 * multilayer OpenEXR, or, for other types, the beauty and one file per
 * pass beside it.
 *
 * OpenEXR: one part, 32-bit (or --exr-half) float channels named as
 * Blender's multilayer files name them, "ViewLayer.PASS.CHANNEL"
 * (Nuke reads the part before the last dot as the layer): the beauty as
 * ViewLayer.Combined.R, .G, .B and .A (alpha 1), then each pass's layer
 * (passes.h: "Denoising Albedo" RGB, "Denoising Normal" XYZ, "Depth" Z,
 * "Position" XYZ, "Emit" RGB, "DiffDir" ... "TransInd" RGB, "IndexMA" X),
 * then the Cryptomatte layer ViewLayer.CryptoMaterial00, 01, 02 (RGBA,
 * crypto.h, named as Blender names its own),
 * and the attributes franja:passes naming the passes, franja:materials
 * (with material_id or crypto_material: the materials' names as a JSON
 * array, IndexMA k being entry k - 1) and Cryptomatte's.
 *
 * Other types: the beauty to OUT and pass NAME to OUT with ".NAME" before
 * its extension (out.png: out.albedo.png), each written as the beauty is
 * (HDR types linear; LDR types through the same tone mapping, the normal
 * as 0.5 + 0.5 n, the depth and material_id divided by their largest
 * value in the image, so that they are pictures to look at; the EXR keeps
 * the data).  One-channel passes become grey; crypto_material is written
 * to OpenEXR only.
 */
#ifndef FRANJA_PASSOUT_H
#define FRANJA_PASSOUT_H

#include "crypto.h"
#include "error.h"
#include "imageio.h"
#include "jobdir.h"
#include "tonemap.h"

/** Writes the beauty rgb (width*height*3 floats) and, when *passes is not
 * NULL and spec->passes not 0, the passes (width*height*pass_channels
 * floats, top row first, malloc'd, the caller's) to path as passout.h
 * says, each file atomically.  An OpenEXR is made in *passes itself,
 * reallocated (*passes updated; its values are then the file's), so the
 * passes are not held twice.
 * o: the writer's options (NULL: none); names: the materials' names
 * (n_materials of them), objects: the objects' names (objects->n of
 * them), for the metadata; groups: the light groups' names (groups->n,
 * 0: the one "default" group), whose layers are written
 * (ViewLayer.Combined_NAME; PNG ...: OUT.Combined_NAME.png).  Fails naming the file not written (files
 * written before it stay). */
int passout_write(const char *path, const float *rgb, float **passes, const job_spec *spec,
                  const fr_tonemap *tm, const iio_options *o, const crypto_names *names, uint32_t n_materials,
                  const crypto_names *objects, const crypto_names *groups, fr_error *err);

#endif
