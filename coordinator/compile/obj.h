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
 *
 * A material name (newmtl, usemtl) is the rest of its line without the
 * blanks around it, spaces and `#` included, as Assimp and Blender read
 * it (`newmtl Hard Shiny Plastic White`); it may be empty.  An mtllib file
 * that does not exist is a warning, not an error: the names it would have
 * defined stay undefined (mesh.h gives them the default material).
 */
#ifndef FRANJA_OBJ_H
#define FRANJA_OBJ_H

#include <stddef.h>
#include <stdint.h>

#include "compile/budget.h"
#include "compile/confine.h"
#include "compile/mesh_data.h"
#include "error.h"

/** Where the reader reports warnings (a missing mtllib file), escaped and
 * starting with file:line; fn NULL (or a NULL obj_warn): nowhere. */
typedef struct {
    void (*fn)(void *user, const char *msg);
    void *user;
} obj_warn;

/** Parses OBJ text (`len` bytes, need not be NUL-terminated) named `name`
 * in messages.  MTL files named by mtllib are read from directory `dir`
 * through `scope` (confine.h; NULL: `dir` and below); with dir NULL they
 * are skipped (every usemtl name is then undefined).  Warnings go to
 * `warn` (may be NULL).  On failure the mesh is freed and err says
 * file:line and what was expected, never quoting the text of the OBJ or
 * MTL file. */
int obj_parse(const char *text, size_t len, const char *name, const char *dir, const confine *scope,
              const obj_warn *warn, mesh_data *m, fr_error *err);

/** Reads and parses the OBJ file `path` (see obj_parse): through `scope`
 * when a scene names it, or as named with its own folder as the scope
 * (scope NULL).  Each MTL file it names counts against budget's read
 * limit first (NULL: no limit). */
int obj_read(const char *path, const confine *scope, fr_budget *budget, const obj_warn *warn, mesh_data *m,
             fr_error *err);

/** Parses MTL text into m's materials (defining those already used and
 * appending new ones). */
int obj_parse_mtl(const char *text, size_t len, const char *name, mesh_data *m, fr_error *err);

#endif
