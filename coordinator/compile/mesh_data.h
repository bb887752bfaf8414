/** @file mesh_data.h
 * The indexed triangle mesh that every mesh reader returns (OBJ by obj.h,
 * PLY, STL, FBX and the rest by mesh_import.h), with the materials of its
 * file, and their conversion to Franja materials.
 */
#ifndef FRANJA_MESH_DATA_H
#define FRANJA_MESH_DATA_H

#include <stdint.h>

#include "scene.h"
#include "vec.h"

/** An MTL material, as written in the file (mapped to a Franja material
 * by mesh_data_material).  `defined` is 0 for a name used by usemtl but found in no MTL
 * file; `line` is then where it was first used. */
typedef struct {
    char name[128];
    vec3 kd, ks, ke, tf;       /**< diffuse, specular, emission, transmission filter */
    float ns, ni, d;           /**< Phong exponent, index of refraction, dissolve */
    int illum;                 /**< illumination model, -1 if not given */
    int defined;
    int line;
} mesh_material;

/** An indexed triangle mesh.  Arrays are malloc'd and owned by the mesh
 * (mesh_data_free).  nrm and uv have n_vert entries, or are NULL when no corner
 * of the file has them; a vertex whose corner had none holds zeros. */
typedef struct {
    vec3 *pos, *nrm;
    vec2 *uv;
    uint32_t n_vert;
    uint32_t (*tri)[3];        /**< vertex indices, counter-clockwise as in the file */
    uint8_t *tri_flags;        /**< FR_TRI_NORMALS / FR_TRI_UVS when all three corners have them */
    uint32_t *tri_mat;         /**< index into mats */
    uint32_t n_tri;
    mesh_material *mats;        /**< mats[0] is the default for faces before any usemtl */
    uint32_t n_mats;
} mesh_data;

/** Frees m's arrays and zeroes it; a zeroed mesh may be freed again. */
void mesh_data_free(mesh_data *m);

/** The Franja material for an MTL material (see scenes/README.md, "mesh"):
 * Kd diffuse, Ks with Ns Phong glossy (mirror for illum 3 and 5), Tf and Ni
 * glass for illum 4, 6, 7 and 9, Ke emission; lobes scaled down together
 * when they would reflect more than they receive. */
void mesh_data_material(const mesh_material *src, fr_material *out);

#endif
