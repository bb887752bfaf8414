/** @file mesh_import.h
 * Mesh files in the formats Assimp reads (ply, stl, gltf, glb, dae, fbx,
 * 3ds ...), read in a child process.
 *
 * Assimp trusts its input more than Franja may: a malformed file can make
 * it abort (its internal assertions), crash or allocate without bound (a
 * PLY header declaring 10^8 faces: refused before the import by
 * plyhead.h, as more than the file holds).  So the import runs in a forked
 * child with limits (address space: 256 MiB plus 64 bytes per byte of the
 * file; CPU time: 60 s plus 1 s per MiB; no core file) and sends the mesh
 * back through a pipe; whatever happens to the child, the caller gets an
 * error naming the file.  Every file Assimp opens (the mesh and what it
 * refers to) goes through Franja's own file functions: it must be a
 * regular file of at most MESH_IMPORT_MAX_BYTES in the scene's folders
 * (confine.h).  Assimp's messages are cut before their first quote, so no
 * token of the file is repeated.
 */
#ifndef FRANJA_MESH_IMPORT_H
#define FRANJA_MESH_IMPORT_H

#include "compile/confine.h"
#include "error.h"
#include "compile/obj.h"

/** The largest file the importer opens: 1 GiB. */
#define MESH_IMPORT_MAX_BYTES ((size_t)1 << 30)

/** Reads the mesh file `path` (and what it names) through `scope` (NULL:
 * its own folder) into m (node transforms applied, polygons
 * triangulated, points and lines dropped; free with mesh_data_free).  Fails,
 * with m empty, with Assimp's own message, plyhead_check's, or "PATH: the mesh importer
 * (Assimp) crashed (signal N: NAME)", "... ran out of its memory limit",
 * "... took more than N s". */
int mesh_import(const char *path, const confine *scope, mesh_data *m, fr_error *err);

#endif
