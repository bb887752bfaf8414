/** @file json_motion.h
 * Keyed JSON shapes that move while the shutter is open (scenes/README.md,
 * "Motion blur").
 *
 * A mesh shape (or one of its `instances`) whose keyed transform differs
 * between shutter open and close becomes moving instances: the mesh is
 * read once in its own space and placed by an instance per placement, each
 * with its transforms at the two ends (builder_motion.h).  Other keyed
 * shapes that move (spheres, rects, boxes, glTF files...) are not blurred:
 * they are posed at the frame's time, with a warning.  Compile time only.
 */
#ifndef FRANJA_JSON_MOTION_H
#define FRANJA_JSON_MOTION_H

#include <cjson/cJSON.h>

#include "compile/builder.h"
#include "compile/confine.h"
#include "compile/scene_hooks.h"

/** Poses keyed shape `s` (JSON path `where`) for the hooks' frame and
 * shutter (h->timed, h->shutter > 0): a mesh shape whose poses at shutter
 * open and close differ is posed at the opening in place and its pose at
 * the closing returned in *close (a new tree, the caller's); any other
 * shape is posed at the frame (with a warning through h->warn when it
 * moves) and *close is NULL.  Returns 0, or -1 with err naming the JSON
 * path at fault. */
int json_motion_pose(cJSON *s, const char *where, const scene_hooks *h, cJSON **close, fr_error *err);

/** Adds moving mesh shape `open` (posed at shutter open by
 * json_motion_pose, JSON path `where`) through h->mesh, placed by
 * instances, and gives each instance its transform at shutter close from
 * `close` (the mesh's placements are read again from it, into a scratch
 * builder).  A shape with `instances` must keep its own transform still
 * (the motion goes in the instances).  Returns 0, or -1 with err set. */
int json_motion_mesh(fr_builder *b, cJSON *open, const cJSON *close, const char *where, const char *dir,
                     const confine *scope, const scene_hooks *h, uint32_t material, fr_error *err);

#endif
