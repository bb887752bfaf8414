/** @file builder_group.h
 * Light groups at compile time: named sets of lights whose light the
 * light_groups render pass (common/passes.h) keeps apart.
 *
 * A reader names the group of a light it has just added (bld_light_group)
 * or of an emissive material (bld_material_group: every area light of
 * that material); lights without one are in the group "default", group 0,
 * which exists as soon as any group is named.  frz_lights (freeze_light.h)
 * gives each light of the frozen table its group (frz_light_groups), and
 * frz_scene writes the light_groups and group_names sections; a scene
 * that names no group has neither.
 */
#ifndef FRANJA_BUILDER_GROUP_H
#define FRANJA_BUILDER_GROUP_H

#include "compile/builder.h"

/** Light `light` (an index into b->lights as the readers add them) is in
 * group `name`.  0, or -1 with *err set: more than PASS_LIGHT_GROUPS
 * groups (naming `where`), or memory. */
int bld_light_group(fr_builder *b, uint32_t light, const char *name, const char *where, fr_error *err);

/** The area lights of material `material` are in group `name`; as
 * bld_light_group. */
int bld_material_group(fr_builder *b, uint32_t material, const char *name, const char *where, fr_error *err);

/** The group of light `given` (as the readers added it) or, for an area
 * light (given FR_NONE), of its material `material`: 0 when none was
 * named. */
uint32_t bld_group_of(const fr_builder *b, uint32_t given, uint32_t material);

#endif
