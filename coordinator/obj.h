/** @file obj.h
 * Wavefront OBJ and MTL files, read into an indexed triangle mesh.
 *
 * Supported: v (x y z [w], extra colour numbers ignored), vt, vn, f with
 * the four corner forms (v, v/vt, v//vn, v/vt/vn), negative (relative)
 * indices, polygons of any size (triangulated by ear clipping in their own
 * plane, so concave ones come out right), g, o, s, usemtl and mtllib (one
 * or more MTL files, found next to the OBJ file).  Statements for curves,
 * lines and points are skipped; anything else is an error naming the file
 * and line.  Corners are merged into one vertex per distinct (v, vt, vn)
 * triple, since a Franja triangle uses one index for all three.
 */
#ifndef FRANJA_OBJ_H
#define FRANJA_OBJ_H

#include <stddef.h>
#include <stdint.h>

#include "budget.h"
#include "error.h"
#include "scene.h"
#include "vec.h"

/** An MTL material, as written in the file (mapped to a Franja material by
 * mesh.c).  `defined` is 0 for a name used by usemtl but found in no MTL
 * file; `line` is then where it was first used. */
typedef struct {
    char name[128];
    vec3 kd, ks, ke, tf;       /**< diffuse, specular, emission, transmission filter */
    float ns, ni, d;           /**< Phong exponent, index of refraction, dissolve */
    int illum;                 /**< illumination model, -1 if not given */
    int defined;
    int line;
} obj_material;

/** An indexed triangle mesh.  Arrays are malloc'd and owned by the mesh
 * (obj_free).  nrm and uv have n_vert entries, or are NULL when no corner
 * of the file has them; a vertex whose corner had none holds zeros. */
typedef struct {
    vec3 *pos, *nrm;
    vec2 *uv;
    uint32_t n_vert;
    uint32_t (*tri)[3];        /**< vertex indices, counter-clockwise as in the file */
    uint8_t *tri_flags;        /**< FR_TRI_NORMALS / FR_TRI_UVS when all three corners have them */
    uint32_t *tri_mat;         /**< index into mats */
    uint32_t n_tri;
    obj_material *mats;        /**< mats[0] is the default for faces before any usemtl */
    uint32_t n_mats;
} obj_mesh;

/** Parses OBJ text (`len` bytes, need not be NUL-terminated) named `name`
 * in messages.  MTL files named by mtllib are read from directory `dir`;
 * with dir NULL they are skipped (every usemtl name is then undefined).
 * On failure the mesh is freed and err says file:line and what was
 * expected. */
int obj_parse(const char *text, size_t len, const char *name, const char *dir, obj_mesh *m, fr_error *err);

/** Reads and parses the OBJ file `path` (see obj_parse). */
int obj_read(const char *path, obj_mesh *m, fr_error *err);

/** obj_read within a compile's budget (budget.h; NULL: no limit): each
 * MTL file is counted against its read limit before it is read, as often
 * as mtllib names it.  The OBJ file itself is the caller's to count. */
int obj_read_within(const char *path, fr_budget *budget, obj_mesh *m, fr_error *err);

/** Parses MTL text into m's materials (defining those already used and
 * appending new ones). */
int obj_parse_mtl(const char *text, size_t len, const char *name, obj_mesh *m, fr_error *err);

void obj_free(obj_mesh *m);

/** The Franja material for an MTL material (see scenes/README.md, "mesh"):
 * Kd diffuse, Ks with Ns Phong glossy (mirror for illum 3 and 5), Tf and Ni
 * glass for illum 4, 6, 7 and 9, Ke emission; lobes scaled down together
 * when they would reflect more than they receive. */
void obj_material_convert(const obj_material *src, fr_material *out);

#endif
