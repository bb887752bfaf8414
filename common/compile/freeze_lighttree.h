/** @file freeze_lighttree.h
 * The light tree of a scene being frozen (compile time): a binary tree over
 * the local lights (every light but the sun and the environment) that
 * bounds their points, the cone of their normals, how far they emit beyond
 * it and their power (fr_light_node in scene.h), for next-event estimation
 * by an importance that each shading point gives each node (light.c).
 *
 * The build is top-down: a node's lights are split where the cost of
 * Conty Estevez and Kulla (2018) is least -- for each side its power times
 * the solid angle its cone of emission covers times the surface area of its
 * box, the box's shape weighted as pbrt-v4's BVHLightSampler does -- over 12
 * buckets of the lights' centres along each axis; ties, flat boxes and deep
 * levels fall back to the median along the widest axis, so no leaf is
 * deeper than FR_BVH_MAX_DEPTH levels.
 */
#ifndef FRANJA_FREEZE_LIGHTTREE_H
#define FRANJA_FREEZE_LIGHTTREE_H

#include "compile/builder.h"

/** Build b->light_nodes over b's local lights, which follow its distant
 * lights in b->lights (frz_lights orders them); power[i] is light i's
 * power as its pick in the power table counts it.  Node j is the leaf of
 * light nd + j (nd distant lights), the inner nodes follow, the root last.
 * Returns 0, or -1 with *err set (memory). */
int frz_light_tree(fr_builder *b, const double *power, fr_error *err);

#endif
