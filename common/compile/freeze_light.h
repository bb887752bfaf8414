/** @file freeze_light.h
 * The light table of a scene being frozen (compile time): the step of
 * frz_scene that orders the lights, derives the area lights, measures the
 * scene's bounding sphere, builds the environment map's sampling tables and
 * sets each light's pick probability in proportion to its power.
 */
#ifndef FRANJA_FREEZE_LIGHT_H
#define FRANJA_FREEZE_LIGHT_H

#include "compile/builder.h"

/** Finish b's lights, after the BVH has put the primitives in their final
 * order: distant lights (environment, then suns) first, then point and spot
 * lights in the order they were added, then one area light per primitive
 * with an emissive material (prims[i].light set), in the order the
 * primitives were added: placed[k] is where the BVH put primitive k (NULL:
 * where it still is), so the light table, and with it which light a
 * sample picks, does not depend on how the tree was built; b->world gets the
 * bounding sphere of the primitives and the planes' points, and, for an
 * environment map, its tables in b->distrib (scene.h, fr_world).  Returns
 * 0, or -1 with *err set (memory; an environment map with no light in it). */
int frz_lights(fr_builder *b, const uint32_t *placed, fr_error *err);

#endif
