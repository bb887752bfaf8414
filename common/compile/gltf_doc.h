/** @file gltf_doc.h
 * A glTF 2.0 document at compile time: the file (.gltf JSON or .glb
 * binary container), its buffers (GLB chunk, `data:` URIs, external files)
 * and typed access to its accessors, every offset and size checked.
 *
 * Errors name the file and the JSON pointer of the value at fault, e.g.
 * `scene.gltf: /accessors/3/bufferView: 7 is not a bufferView index (the
 * file has 2)`.  Every size read from the file is checked against the bytes
 * that are really there before anything is allocated or read, so a small
 * file never makes the reader allocate much more than its own size.
 *
 * Unsupported features are remembered as warnings, one per feature name
 * (gdoc_warn); the importer (gltf_scene.h) hands them to its caller.
 *
 * Ownership: a gltf_doc owns its JSON tree, file bytes and decoded buffers;
 * gdoc_free() releases them.  Compile time only.
 */
#ifndef FRANJA_GLTF_DOC_H
#define FRANJA_GLTF_DOC_H

#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "compile/budget.h"
#include "compile/confine.h"
#include "error.h"

/** Most distinct warnings kept for one document (later ones are counted). */
#define GDOC_MAX_WARN 64

/** One buffer's bytes (into the file for a GLB chunk, else malloc'd). */
typedef struct {
    const unsigned char *data; /**< NULL until read (an external file is read when first used) */
    size_t len;                /**< the buffer's byteLength */
    unsigned char *owned;      /**< what to free, or NULL */
    const char *uri;           /**< an external file's URI (in the JSON tree), or NULL */
} gdoc_buffer;

/** The top-level arrays of the document, each as a vector of its elements
 * (so that element i is found in constant time). */
typedef struct {
    const cJSON **v;
    uint32_t n;
} gdoc_array;

typedef struct {
    char path[4096];           /**< the file as given (messages) */
    char dir[4096];            /**< its directory (relative URIs) */
    const confine *scope;      /**< where its external files may be read (the caller's; NULL in memory) */
    unsigned char *file;       /**< the whole file */
    size_t file_len;
    cJSON *root;
    gdoc_buffer *buffers;
    uint32_t n_buffers;
    gdoc_array accessors, buffer_views, nodes, meshes, materials, textures, images, samplers, cameras, scenes,
        lights;                /**< lights: KHR_lights_punctual's */
    char *warn[GDOC_MAX_WARN]; /**< distinct warnings, in order (malloc'd) */
    char *warn_key[GDOC_MAX_WARN];
    uint32_t n_warn, n_warn_dropped;
    fr_budget *budget;         /**< counts the buffer files read (NULL: no limit); not owned */
} gltf_doc;

/** Reads and checks the document at `path` (through `scope` when it is
 * `referenced` by another scene file, else as it is named): the GLB
 * header and chunks,
 * `asset.version` (2.x), `extensionsRequired` (each must be one this reader
 * supports), the top-level arrays' types, and every buffer (each loaded and
 * at least byteLength long; external buffers and images are opened
 * through `scope`, which must outlive d: confine.h).  Accessors and views
 * are checked when used.  Returns 0, or -1 with err naming the file (and
 * byte offset or JSON pointer); *d is then freed. */
int gdoc_open(gltf_doc *d, const char *path, const confine *scope, int referenced, fr_error *err);

/** Reads the document from bytes already in memory (`name` for messages,
 * `dir` for external URIs: NULL refuses them).  The bytes are copied. */
int gdoc_open_mem(gltf_doc *d, const void *bytes, size_t len, const char *name, const char *dir, fr_error *err);

void gdoc_free(gltf_doc *d);

/** Records warning `fmt` under `key` unless a warning with that key was
 * already recorded: each unsupported feature is reported once. */
void gdoc_warn(gltf_doc *d, const char *key, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/** Records warnings for the names of `extensionsUsed` that are not among
 * `known` (NULL-terminated). */
void gdoc_warn_extensions(gltf_doc *d, const char *const *known);

/** @name JSON values, with JSON-pointer errors ("/nodes/3/mesh: ...") */

/** Member `key` of object o (at pointer `ptr`) as an integer in [0, max]:
 * absent gives `def` (or fails when def < 0). */
int gdoc_uint(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, long long def, uint64_t max,
              uint64_t *out, fr_error *err);
/** Member `key` as an index into an array of n elements (absent: *out =
 * UINT32_MAX when optional, else an error). */
int gdoc_index(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, int required, uint32_t n,
               const char *what, uint32_t *out, fr_error *err);
/** Member `key` as a finite number (absent: def). */
int gdoc_number(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, double def, double *out,
                fr_error *err);
/** Member `key` as an array of exactly n finite numbers (absent: out
 * untouched, *present = 0). */
int gdoc_numbers(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, int n, double *out,
                 int *present, fr_error *err);
/** Member `key` as an object, or NULL when absent; a non-object fails. */
int gdoc_object(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, const cJSON **out,
                fr_error *err);
/** Fails with "FILE: PTR: message". */
int gdoc_fail(const gltf_doc *d, fr_error *err, const char *ptr, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/** @name Accessors */

/** Component types (glTF's numbers). */
enum {
    GDOC_I8 = 5120, GDOC_U8 = 5121, GDOC_I16 = 5122, GDOC_U16 = 5123, GDOC_U32 = 5125, GDOC_F32 = 5126
};

/** An accessor, checked: every element lies inside its view and buffer. */
typedef struct {
    uint32_t index;            /**< in the document's accessors */
    uint32_t count;            /**< elements */
    uint32_t comps;            /**< components per element: 1 (SCALAR) to 16 (MAT4) */
    uint32_t ctype;            /**< GDOC_* */
    int normalized;
    const unsigned char *base; /**< element 0, or NULL: all zeros (no bufferView) */
    size_t stride;             /**< bytes from one element to the next */
    uint32_t n_sparse;         /**< sparse substitution: n_sparse sorted indices and their values */
    const unsigned char *sp_index, *sp_value;
    uint32_t sp_itype;         /**< component type of the sparse indices */
} gdoc_acc;

/** Accessor `index` (referred to from pointer `from`), checked to have
 * `comps` components per element (0: any) and, when `ctypes` is not NULL,
 * a component type among the zero-terminated list.  Sparse accessors are
 * supported (indices strictly increasing, inside count). */
int gdoc_accessor(gltf_doc *d, uint32_t index, const char *from, uint32_t comps, const uint32_t *ctypes,
                  gdoc_acc *a, fr_error *err);

/** The `count` of accessor `index` (referred to from `from`), without
 * reading anything: for budgets checked before an accessor's buffer is
 * read. */
int gdoc_count(const gltf_doc *d, uint32_t index, const char *from, uint32_t *count, fr_error *err);

/** Component c of element i as a float (normalized integers mapped to
 * [0, 1] or [-1, 1] as glTF defines; others converted). */
double gdoc_get(const gdoc_acc *a, uint32_t i, uint32_t c);

/** Element i of a SCALAR integer accessor (indices). */
uint32_t gdoc_get_uint(const gdoc_acc *a, uint32_t i);

/** A bufferView's bytes (images stored in the binary chunk).  Checked. */
int gdoc_view_bytes(gltf_doc *d, uint32_t view, const char *from, const unsigned char **data, size_t *len,
                    fr_error *err);

/** Decodes a `data:[<mime>][;base64],<payload>` URI into *out (malloc'd,
 * *len bytes); the MIME type, if wanted, into mime[cap].  Fails on a
 * malformed URI or non-base64 payload. */
int gdoc_data_uri(const char *uri, unsigned char **out, size_t *len, char *mime, size_t cap, fr_error *err);

/** Resolves relative URI `uri` against the document's directory into
 * out[cap], decoding %XX escapes; fails on URIs with another scheme
 * (http:, file: ...) or absolute paths. */
int gdoc_uri_path(const gltf_doc *d, const char *uri, const char *ptr, char *out, size_t cap, fr_error *err);

#endif
