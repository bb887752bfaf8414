/* gltf_doc.c -- a glTF 2.0 file, its buffers and accessors (gltf_doc.h). */
#include "compile/gltf_doc.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "compile/confine.h"
#include "file.h"

#define GLB_MAGIC 0x46546C67u  /* "glTF" */
#define GLB_JSON 0x4E4F534Au   /* "JSON" */
#define GLB_BIN 0x004E4942u    /* "BIN\0" */

/* Extensions whose absence of support would change the picture: a file
 * that requires another one is refused (glTF says a reader must). */
static const char *const supported_required[] = {
    "KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_lights_punctual", "KHR_mesh_quantization",
    "KHR_materials_transmission", "KHR_materials_ior", NULL};

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int gdoc_fail(const gltf_doc *d, fr_error *err, const char *ptr, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (ptr && ptr[0])
        return fr_fail(err, "%s: %s: %s", d->path, ptr, msg);
    return fr_fail(err, "%s: %s", d->path, msg);
}

void gdoc_warn(gltf_doc *d, const char *key, const char *fmt, ...)
{
    for (uint32_t i = 0; i < d->n_warn; i++)
        if (!strcmp(d->warn_key[i], key))
            return;
    if (d->n_warn == GDOC_MAX_WARN) {
        d->n_warn_dropped++;
        return;
    }
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fr_escape_controls(msg, sizeof msg); /* names from the file reach a terminal */
    char *k = strdup(key), *m = strdup(msg);
    if (!k || !m) {
        free(k);
        free(m);
        d->n_warn_dropped++;
        return;
    }
    d->warn_key[d->n_warn] = k;
    d->warn[d->n_warn++] = m;
}

void gdoc_warn_extensions(gltf_doc *d, const char *const *known)
{
    const cJSON *used = cJSON_GetObjectItemCaseSensitive(d->root, "extensionsUsed");
    if (!cJSON_IsArray(used))
        return;
    for (const cJSON *e = used->child; e; e = e->next) {
        if (!cJSON_IsString(e))
            continue;
        int ok = 0;
        for (int i = 0; known[i] && !ok; i++)
            ok = !strcmp(known[i], e->valuestring);
        if (!ok) {
            char key[160];
            snprintf(key, sizeof key, "ext:%s", e->valuestring);
            gdoc_warn(d, key, "extension %s is not supported: ignored", e->valuestring);
        }
    }
}

/* ---- JSON values -------------------------------------------------------- */

int gdoc_uint(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, long long def, uint64_t max,
              uint64_t *out, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) {
        if (def < 0)
            return gdoc_fail(d, err, ptr, "%s is missing", key);
        *out = (uint64_t)def;
        return 0;
    }
    double x = v->valuedouble;
    if (!cJSON_IsNumber(v) || !(x >= 0.0 && x <= (double)max) || x != floor(x))
        return gdoc_fail(d, err, ptr, "%s: expected an integer in [0, %llu]", key, (unsigned long long)max);
    *out = (uint64_t)x;
    return 0;
}

int gdoc_index(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, int required, uint32_t n,
               const char *what, uint32_t *out, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    *out = UINT32_MAX;
    if (!v) {
        if (required)
            return gdoc_fail(d, err, ptr, "%s is missing (expected an index into %s)", key, what);
        return 0;
    }
    double x = v->valuedouble;
    if (!cJSON_IsNumber(v))
        return gdoc_fail(d, err, ptr, "%s: expected an index into %s, not a %s", key, what,
                         cJSON_IsString(v) ? "string" : "non-number");
    if (x != floor(x) || !(x >= 0.0 && x < (double)n))
        return gdoc_fail(d, err, ptr, "%s: %g is not an index into %s (the file has %u)", key, x, what, n);
    *out = (uint32_t)x;
    return 0;
}

int gdoc_number(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, double def, double *out,
                fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v) {
        *out = def;
        return 0;
    }
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || fabs(v->valuedouble) > 1.0e30)
        return gdoc_fail(d, err, ptr, "%s: expected a finite number", key);
    *out = v->valuedouble;
    return 0;
}

int gdoc_numbers(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, int n, double *out,
                 int *present, fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    *present = 0;
    if (!v)
        return 0;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n)
        return gdoc_fail(d, err, ptr, "%s: expected an array of %d numbers", key, n);
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1.0e30)
            return gdoc_fail(d, err, ptr, "%s/%d: expected a finite number", key, i);
        out[i] = e->valuedouble;
    }
    *present = 1;
    return 0;
}

int gdoc_object(const gltf_doc *d, const cJSON *o, const char *ptr, const char *key, const cJSON **out,
                fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    *out = NULL;
    if (!v)
        return 0;
    if (!cJSON_IsObject(v))
        return gdoc_fail(d, err, ptr, "%s: expected an object", key);
    *out = v;
    return 0;
}

/* ---- URIs ------------------------------------------------------------- */

static int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z')
        return c - 'A';
    if (c >= 'a' && c <= 'z')
        return c - 'a' + 26;
    if (c >= '0' && c <= '9')
        return c - '0' + 52;
    if (c == '+')
        return 62;
    if (c == '/')
        return 63;
    return -1;
}

int gdoc_data_uri(const char *uri, unsigned char **out, size_t *len, char *mime, size_t cap, fr_error *err)
{
    *out = NULL;
    *len = 0;
    if (strncmp(uri, "data:", 5) != 0)
        return fr_fail(err, "not a data: URI");
    const char *comma = strchr(uri + 5, ',');
    if (!comma)
        return fr_fail(err, "data: URI without a comma before its payload");
    size_t head = (size_t)(comma - (uri + 5));
    if (head < 7 || strncmp(comma - 7, ";base64", 7) != 0)
        return fr_fail(err, "data: URI not in base64 (only base64 payloads are supported)");
    if (mime && cap) {
        size_t m = strcspn(uri + 5, ";,");
        snprintf(mime, cap, "%.*s", (int)(m < cap ? m : cap - 1), uri + 5);
    }
    const unsigned char *p = (const unsigned char *)comma + 1;
    size_t n = strlen((const char *)p);
    while (n > 0 && p[n - 1] == '=')
        n--;
    if (strlen((const char *)p) - n > 2 || n % 4 == 1)
        return fr_fail(err, "data: URI: base64 payload of a impossible length");
    unsigned char *buf = malloc(n / 4 * 3 + 3);
    if (!buf)
        return fr_fail(err, "data: URI: out of memory");
    size_t o = 0;
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = 0; i < n; i++) {
        int v = b64_value(p[i]);
        if (v < 0) {
            free(buf);
            return fr_fail(err, "data: URI: byte %zu of the payload is not base64", i);
        }
        acc = acc << 6 | (uint32_t)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            buf[o++] = (unsigned char)(acc >> bits);
        }
    }
    *out = buf;
    *len = o;
    return 0;
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

int gdoc_uri_path(const gltf_doc *d, const char *uri, const char *ptr, char *out, size_t cap, fr_error *err)
{
    /* A scheme is letters, digits, + - . before the first ':' (and before
     * any '/'); glTF's own files are relative references. */
    size_t s = strspn(uri, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789+-.");
    if (s > 0 && uri[s] == ':')
        return gdoc_fail(d, err, ptr, "uri '%.*s...': only relative file names and data: URIs are supported",
                         (int)(s + 1), uri);
    if (!d->dir[0])
        return gdoc_fail(d, err, ptr, "uri '%s': external files are not read for a document held in memory", uri);
    if (uri[0] == '/' || uri[0] == 0)
        return gdoc_fail(d, err, ptr, "uri '%s': expected a file name relative to the glTF file", uri);
    char name[4096];
    size_t o = 0;
    for (size_t i = 0; uri[i]; i++) {
        char c = uri[i];
        if (c == '%') {
            int h = hexval(uri[i + 1]), l = h < 0 ? -1 : hexval(uri[i + 2]);
            if (h < 0 || l < 0 || (h == 0 && l == 0))
                return gdoc_fail(d, err, ptr, "uri '%s': bad %%-escape", uri);
            c = (char)(h * 16 + l);
            i += 2;
        }
        if (o + 1 >= sizeof name)
            return gdoc_fail(d, err, ptr, "uri: too long");
        name[o++] = c;
    }
    name[o] = 0;
    if ((size_t)snprintf(out, cap, "%s/%s", d->dir, name) >= cap)
        return gdoc_fail(d, err, ptr, "uri: too long");
    return 0;
}

/* ---- opening ---------------------------------------------------------- */

/* Reads exactly `need` bytes of the file `path`, which must lie in the
 * document's scope (confine.h) and be a regular file: its size is checked
 * first, so a short file fails before anything is allocated, and no more
 * than `need` bytes are read of a longer one. */
static int read_exact(const gltf_doc *d, const char *path, size_t need, unsigned char **out, fr_error *err)
{
    *out = NULL;
    int fd;
    size_t size;
    if (confine_open(d->scope, path, SIZE_MAX, &fd, &size, err) < 0)
        return -1;
    if (size < need) {
        close(fd);
        return fr_fail(err, "%s has %zu bytes, fewer than the %zu the glTF file says", path, size, need);
    }
    unsigned char *buf = malloc(need ? need : 1);
    if (!buf) {
        close(fd);
        return fr_fail(err, "%s: out of memory", path);
    }
    size_t got = 0;
    while (got < need) {
        ssize_t r = read(fd, buf + got, need - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0) {
            free(buf);
            close(fd);
            return fr_fail(err, "%s: read error after %zu bytes", path, got);
        }
        got += (size_t)r;
    }
    close(fd);
    *out = buf;
    return 0;
}

static int collect(gltf_doc *d, const cJSON *parent, const char *key, const char *ptr, gdoc_array *a,
                   fr_error *err)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(parent, key);
    a->v = NULL;
    a->n = 0;
    if (!v)
        return 0;
    if (!cJSON_IsArray(v))
        return gdoc_fail(d, err, ptr, "expected an array");
    int n = cJSON_GetArraySize(v);
    if (n == 0)
        return 0;
    if ((a->v = malloc((size_t)n * sizeof *a->v)) == NULL)
        return gdoc_fail(d, err, ptr, "out of memory");
    for (const cJSON *e = v->child; e; e = e->next) {
        if (!cJSON_IsObject(e)) {
            free(a->v);
            a->v = NULL;
            return gdoc_fail(d, err, ptr, "element %u: expected an object", a->n);
        }
        a->v[a->n++] = e;
    }
    return 0;
}

/* Checks every buffer's byteLength and uri, and takes the GLB chunk and
 * data: URIs (which the file itself holds).  External files are read
 * when an accessor or view first needs them (buffer_data). */
static int load_buffers(gltf_doc *d, const unsigned char *bin, size_t bin_len, int glb, fr_error *err)
{
    gdoc_array bufs;
    if (collect(d, d->root, "buffers", "/buffers", &bufs, err) < 0)
        return -1;
    int rc = 0;
    if (bufs.n && (d->buffers = calloc(bufs.n, sizeof *d->buffers)) == NULL)
        rc = gdoc_fail(d, err, "/buffers", "out of memory");
    for (uint32_t i = 0; rc == 0 && i < bufs.n; i++, d->n_buffers++) {
        char ptr[64];
        snprintf(ptr, sizeof ptr, "/buffers/%u", i);
        uint64_t len;
        gdoc_buffer *b = &d->buffers[i];
        if ((rc = gdoc_uint(d, bufs.v[i], ptr, "byteLength", -1, (uint64_t)1 << 40, &len, err)) < 0)
            break;
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(bufs.v[i], "uri");
        b->len = (size_t)len;
        if (!uri) {
            if (!glb || i != 0 || !bin) {
                rc = gdoc_fail(d, err, ptr, "no uri, and not the binary chunk of a .glb file");
            } else if (bin_len < len) {
                rc = gdoc_fail(d, err, ptr, "byteLength %llu, but the .glb binary chunk has %zu bytes",
                               (unsigned long long)len, bin_len);
            } else {
                b->data = bin;
            }
        } else if (!cJSON_IsString(uri)) {
            rc = gdoc_fail(d, err, ptr, "uri: expected a string");
        } else if (!strncmp(uri->valuestring, "data:", 5)) {
            size_t n;
            fr_error e;
            if (gdoc_data_uri(uri->valuestring, &b->owned, &n, NULL, 0, &e) < 0)
                rc = gdoc_fail(d, err, ptr, "uri: %s", e.msg);
            else if (n < len)
                rc = gdoc_fail(d, err, ptr, "byteLength %llu, but its data: URI holds %zu bytes",
                               (unsigned long long)len, n);
            b->data = b->owned;
        } else {
            char path[4096];
            if ((rc = gdoc_uri_path(d, uri->valuestring, ptr, path, sizeof path, err)) < 0)
                break;
            b->uri = uri->valuestring;
        }
    }
    free(bufs.v);
    return rc;
}

/* Buffer i's bytes, reading its file the first time one is needed: its
 * byteLength counted against the budget first, at most FILE_READ_MAX. */
static int buffer_data(gltf_doc *d, uint32_t i, fr_error *err)
{
    gdoc_buffer *b = &d->buffers[i];
    if (b->data || b->len == 0)
        return 0;
    char ptr[64], where[4200], path[4096];
    snprintf(ptr, sizeof ptr, "/buffers/%u", i);
    snprintf(where, sizeof where, "%s: %s", d->path, ptr);
    if (b->len > FILE_READ_MAX)
        return gdoc_fail(d, err, ptr, "byteLength %zu: more than the %zu bytes a buffer file may have", b->len,
                         FILE_READ_MAX);
    if (gdoc_uri_path(d, b->uri, ptr, path, sizeof path, err) < 0 ||
        budget_take(d->budget, BUDGET_READ, b->len, where, err) < 0)
        return -1;
    fr_error e;
    if (read_exact(d, path, b->len, &b->owned, &e) < 0)
        return gdoc_fail(d, err, ptr, "%s", e.msg);
    b->data = b->owned;
    return 0;
}

static int check_required(gltf_doc *d, fr_error *err)
{
    const cJSON *req = cJSON_GetObjectItemCaseSensitive(d->root, "extensionsRequired");
    if (!req)
        return 0;
    if (!cJSON_IsArray(req))
        return gdoc_fail(d, err, "/extensionsRequired", "expected an array of names");
    for (const cJSON *e = req->child; e; e = e->next) {
        if (!cJSON_IsString(e))
            return gdoc_fail(d, err, "/extensionsRequired", "expected an array of names");
        int ok = 0;
        for (int i = 0; supported_required[i] && !ok; i++)
            ok = !strcmp(supported_required[i], e->valuestring);
        if (!ok)
            return gdoc_fail(d, err, "/extensionsRequired", "the file requires extension %s, which is not supported",
                             e->valuestring);
    }
    return 0;
}

static int parse(gltf_doc *d, fr_error *err)
{
    const unsigned char *json = d->file, *bin = NULL;
    size_t json_len = d->file_len, bin_len = 0;
    int glb = d->file_len >= 4 && le32(d->file) == GLB_MAGIC;
    if (glb) {
        if (d->file_len < 20)
            return gdoc_fail(d, err, NULL, "truncated .glb: %zu bytes, fewer than a header and a chunk header",
                             d->file_len);
        uint32_t version = le32(d->file + 4), total = le32(d->file + 8);
        if (version != 2)
            return gdoc_fail(d, err, NULL, "byte 4: .glb version %u (expected 2)", version);
        if (total > d->file_len)
            return gdoc_fail(d, err, NULL, "truncated .glb: the header says %u bytes, the file has %zu", total,
                             d->file_len);
        size_t at = 12;
        for (int chunk = 0; at + 8 <= total; chunk++) {
            uint32_t clen = le32(d->file + at), ctype = le32(d->file + at + 4);
            if (clen > total - at - 8)
                return gdoc_fail(d, err, NULL, "byte %zu: chunk %d of %u bytes runs past the end (%u)", at, chunk,
                                 clen, total);
            if (chunk == 0 && ctype != GLB_JSON)
                return gdoc_fail(d, err, NULL, "byte %zu: the first chunk is not JSON", at);
            if (chunk == 0) {
                json = d->file + at + 8;
                json_len = clen;
            } else if (chunk == 1 && ctype == GLB_BIN) {
                bin = d->file + at + 8;
                bin_len = clen;
            }
            at += 8 + (size_t)clen;
        }
        if (json == d->file)
            return gdoc_fail(d, err, NULL, "no JSON chunk");
    }
    d->root = cJSON_ParseWithLength((const char *)json, json_len);
    if (!d->root) {
        const char *at = cJSON_GetErrorPtr();
        int line = 1;
        for (const char *p = (const char *)json; at && p < at && p < (const char *)json + json_len; p++)
            line += *p == '\n';
        return gdoc_fail(d, err, NULL, "%s%d: invalid JSON", glb ? "JSON chunk line " : "line ", line);
    }
    if (!cJSON_IsObject(d->root))
        return gdoc_fail(d, err, "(top level)", "expected an object");
    const cJSON *asset = cJSON_GetObjectItemCaseSensitive(d->root, "asset");
    const cJSON *ver = asset ? cJSON_GetObjectItemCaseSensitive(asset, "version") : NULL;
    if (!cJSON_IsObject(asset) || !cJSON_IsString(ver))
        return gdoc_fail(d, err, "/asset/version", "missing (not a glTF file?)");
    if (strncmp(ver->valuestring, "2.", 2) != 0)
        return gdoc_fail(d, err, "/asset/version", "'%s': only glTF 2.x is supported", ver->valuestring);
    const cJSON *minv = cJSON_GetObjectItemCaseSensitive(asset, "minVersion");
    if (cJSON_IsString(minv) && strcmp(minv->valuestring, "2.0") != 0)
        return gdoc_fail(d, err, "/asset/minVersion", "'%s': this reader knows glTF 2.0", minv->valuestring);
    const cJSON *ext = NULL, *lights = NULL;
    if (check_required(d, err) < 0 || gdoc_object(d, d->root, "", "extensions", &ext, err) < 0 ||
        (ext && gdoc_object(d, ext, "/extensions", "KHR_lights_punctual", &lights, err) < 0))
        return -1;
    struct { const char *key; gdoc_array *a; } arrays[] = {
        {"accessors", &d->accessors}, {"bufferViews", &d->buffer_views}, {"nodes", &d->nodes},
        {"meshes", &d->meshes},       {"materials", &d->materials},      {"textures", &d->textures},
        {"images", &d->images},       {"samplers", &d->samplers},        {"cameras", &d->cameras},
        {"scenes", &d->scenes}};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) {
        char ptr[32];
        snprintf(ptr, sizeof ptr, "/%s", arrays[i].key);
        if (collect(d, d->root, arrays[i].key, ptr, arrays[i].a, err) < 0)
            return -1;
    }
    if (lights && collect(d, lights, "lights", "/extensions/KHR_lights_punctual/lights", &d->lights, err) < 0)
        return -1;
    return load_buffers(d, bin, bin_len, glb, err);
}

int gdoc_open_mem(gltf_doc *d, const void *bytes, size_t len, const char *name, const char *dir, fr_error *err)
{
    memset(d, 0, sizeof *d);
    snprintf(d->path, sizeof d->path, "%s", name);
    snprintf(d->dir, sizeof d->dir, "%s", dir ? dir : "");
    if ((d->file = malloc(len + 1)) == NULL)
        return fr_fail(err, "%s: out of memory", name);
    memcpy(d->file, bytes, len);
    d->file[len] = 0;
    d->file_len = len;
    if (parse(d, err) < 0) {
        gdoc_free(d);
        return -1;
    }
    return 0;
}

int gdoc_open(gltf_doc *d, const char *path, const confine *scope, int referenced, fr_error *err)
{
    memset(d, 0, sizeof *d);
    d->scope = scope;
    char *text;
    size_t len;
    if ((referenced ? confine_read(scope, path, FILE_READ_MAX, &text, &len, err)
                    : file_read(path, &text, &len, err)) < 0)
        return -1;
    snprintf(d->path, sizeof d->path, "%s", path);
    file_dir(path, d->dir, sizeof d->dir);
    d->file = (unsigned char *)text;
    d->file_len = len;
    if (parse(d, err) < 0) {
        gdoc_free(d);
        return -1;
    }
    return 0;
}

void gdoc_free(gltf_doc *d)
{
    for (uint32_t i = 0; i < d->n_buffers; i++)
        free(d->buffers[i].owned);
    free(d->buffers);
    gdoc_array *arrays[] = {&d->accessors, &d->buffer_views, &d->nodes,   &d->meshes,  &d->materials, &d->textures,
                            &d->images,    &d->samplers,     &d->cameras, &d->scenes, &d->lights};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        free(arrays[i]->v);
    for (uint32_t i = 0; i < d->n_warn; i++) {
        free(d->warn[i]);
        free(d->warn_key[i]);
    }
    cJSON_Delete(d->root);
    free(d->file);
    memset(d, 0, sizeof *d);
}

/* ---- views and accessors ---------------------------------------------- */

/* The bytes of bufferView `view`, and its byteStride (0 if none). */
static int view_range(gltf_doc *d, uint32_t view, const unsigned char **data, size_t *len, size_t *stride,
                      fr_error *err)
{
    char ptr[64];
    snprintf(ptr, sizeof ptr, "/bufferViews/%u", view);
    const cJSON *v = d->buffer_views.v[view];
    uint32_t buf;
    uint64_t off, n, st;
    if (gdoc_index(d, v, ptr, "buffer", 1, d->n_buffers, "buffers", &buf, err) < 0 ||
        gdoc_uint(d, v, ptr, "byteOffset", 0, (uint64_t)1 << 40, &off, err) < 0 ||
        gdoc_uint(d, v, ptr, "byteLength", -1, (uint64_t)1 << 40, &n, err) < 0 ||
        gdoc_uint(d, v, ptr, "byteStride", 0, 252, &st, err) < 0)
        return -1;
    if (st != 0 && st < 4)
        return gdoc_fail(d, err, ptr, "byteStride %llu: expected 4 to 252", (unsigned long long)st);
    if (off + n > d->buffers[buf].len)
        return gdoc_fail(d, err, ptr, "bytes %llu to %llu lie outside buffer %u (%zu bytes)", (unsigned long long)off,
                         (unsigned long long)(off + n), buf, d->buffers[buf].len);
    if (n && buffer_data(d, buf, err) < 0)
        return -1;
    *data = d->buffers[buf].data + off;
    *len = (size_t)n;
    *stride = (size_t)st;
    return 0;
}

int gdoc_view_bytes(gltf_doc *d, uint32_t view, const char *from, const unsigned char **data, size_t *len,
                    fr_error *err)
{
    size_t stride;
    if (view >= d->buffer_views.n)
        return gdoc_fail(d, err, from, "bufferView %u does not exist (the file has %u)", view, d->buffer_views.n);
    return view_range(d, view, data, len, &stride, err);
}

static uint32_t csize(uint32_t ctype)
{
    switch (ctype) {
    case GDOC_I8: case GDOC_U8: return 1;
    case GDOC_I16: case GDOC_U16: return 2;
    case GDOC_U32: case GDOC_F32: return 4;
    default: return 0;
    }
}

static const struct { const char *name; uint32_t comps; } types[] = {
    {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}};

static int sparse(gltf_doc *d, const cJSON *sp, const char *ptr, gdoc_acc *a, size_t elem, fr_error *err)
{
    char p[96], pi[112], pv[112];
    snprintf(p, sizeof p, "%s/sparse", ptr);
    snprintf(pi, sizeof pi, "%s/indices", p);
    snprintf(pv, sizeof pv, "%s/values", p);
    uint64_t n, ioff, voff, itype;
    const cJSON *ix = NULL, *vs = NULL;
    uint32_t iview, vview;
    if (!cJSON_IsObject(sp))
        return gdoc_fail(d, err, p, "expected an object");
    if (gdoc_uint(d, sp, p, "count", -1, a->count, &n, err) < 0 || gdoc_object(d, sp, p, "indices", &ix, err) < 0 ||
        gdoc_object(d, sp, p, "values", &vs, err) < 0)
        return -1;
    if (!ix || !vs || n == 0)
        return gdoc_fail(d, err, p, "expected count >= 1, indices and values");
    if (gdoc_index(d, ix, pi, "bufferView", 1, d->buffer_views.n, "bufferViews", &iview, err) < 0 ||
        gdoc_uint(d, ix, pi, "byteOffset", 0, (uint64_t)1 << 40, &ioff, err) < 0 ||
        gdoc_uint(d, ix, pi, "componentType", -1, 65535, &itype, err) < 0 ||
        gdoc_index(d, vs, pv, "bufferView", 1, d->buffer_views.n, "bufferViews", &vview, err) < 0 ||
        gdoc_uint(d, vs, pv, "byteOffset", 0, (uint64_t)1 << 40, &voff, err) < 0)
        return -1;
    if (itype != GDOC_U8 && itype != GDOC_U16 && itype != GDOC_U32)
        return gdoc_fail(d, err, pi, "componentType %llu: expected 5121, 5123 or 5125", (unsigned long long)itype);
    const unsigned char *idata, *vdata;
    size_t ilen, vlen, st;
    if (view_range(d, iview, &idata, &ilen, &st, err) < 0 || view_range(d, vview, &vdata, &vlen, &st, err) < 0)
        return -1;
    if (ioff + n * csize((uint32_t)itype) > ilen)
        return gdoc_fail(d, err, pi, "%llu indices run past the end of bufferView %u", (unsigned long long)n, iview);
    if (voff + n * elem > vlen)
        return gdoc_fail(d, err, pv, "%llu values run past the end of bufferView %u", (unsigned long long)n, vview);
    a->n_sparse = (uint32_t)n;
    a->sp_itype = (uint32_t)itype;
    a->sp_index = idata + ioff;
    a->sp_value = vdata + voff;
    /* Indices strictly increasing and inside the accessor. */
    gdoc_acc ia = {0};
    ia.count = a->n_sparse;
    ia.comps = 1;
    ia.ctype = a->sp_itype;
    ia.base = a->sp_index;
    ia.stride = csize(a->sp_itype);
    uint32_t prev = 0;
    for (uint32_t i = 0; i < a->n_sparse; i++) {
        uint32_t k = gdoc_get_uint(&ia, i);
        if (k >= a->count || (i > 0 && k <= prev))
            return gdoc_fail(d, err, pi, "index %u (%u): not increasing or not below count %u", i, k, a->count);
        prev = k;
    }
    return 0;
}

int gdoc_count(const gltf_doc *d, uint32_t index, const char *from, uint32_t *count, fr_error *err)
{
    if (index >= d->accessors.n)
        return gdoc_fail(d, err, from, "accessor %u does not exist (the file has %u)", index, d->accessors.n);
    char ptr[64];
    uint64_t n;
    snprintf(ptr, sizeof ptr, "/accessors/%u", index);
    if (gdoc_uint(d, d->accessors.v[index], ptr, "count", -1, 0x7fffffff, &n, err) < 0)
        return -1;
    *count = (uint32_t)n;
    return 0;
}

int gdoc_accessor(gltf_doc *d, uint32_t index, const char *from, uint32_t comps, const uint32_t *ctypes,
                  gdoc_acc *a, fr_error *err)
{
    memset(a, 0, sizeof *a);
    if (index >= d->accessors.n)
        return gdoc_fail(d, err, from, "accessor %u does not exist (the file has %u)", index, d->accessors.n);
    char ptr[64];
    snprintf(ptr, sizeof ptr, "/accessors/%u", index);
    const cJSON *o = d->accessors.v[index];
    uint64_t ct, count, off;
    uint32_t view;
    if (gdoc_uint(d, o, ptr, "componentType", -1, 65535, &ct, err) < 0 ||
        gdoc_uint(d, o, ptr, "count", -1, 0x7fffffff, &count, err) < 0 ||
        gdoc_uint(d, o, ptr, "byteOffset", 0, (uint64_t)1 << 40, &off, err) < 0 ||
        gdoc_index(d, o, ptr, "bufferView", 0, d->buffer_views.n, "bufferViews", &view, err) < 0)
        return -1;
    if (csize((uint32_t)ct) == 0)
        return gdoc_fail(d, err, ptr, "componentType %llu is not a glTF component type", (unsigned long long)ct);
    if (count == 0)
        return gdoc_fail(d, err, ptr, "count: expected at least 1");
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "type");
    a->comps = 0;
    for (size_t i = 0; cJSON_IsString(t) && i < sizeof types / sizeof types[0]; i++)
        if (!strcmp(t->valuestring, types[i].name))
            a->comps = types[i].comps;
    if (!a->comps)
        return gdoc_fail(d, err, ptr, "type: expected SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4");
    const cJSON *nz = cJSON_GetObjectItemCaseSensitive(o, "normalized");
    if (nz && !cJSON_IsBool(nz))
        return gdoc_fail(d, err, ptr, "normalized: expected true or false");
    a->index = index;
    a->count = (uint32_t)count;
    a->ctype = (uint32_t)ct;
    a->normalized = cJSON_IsTrue(nz);
    if (a->normalized && (ct == GDOC_F32 || ct == GDOC_U32))
        return gdoc_fail(d, err, ptr, "normalized: not allowed for componentType %llu", (unsigned long long)ct);
    if (comps && a->comps != comps)
        return gdoc_fail(d, err, from, "accessor %u has type %s, expected %u components", index, t->valuestring,
                         comps);
    if (ctypes) {
        int ok = 0;
        for (int i = 0; ctypes[i] && !ok; i++)
            ok = ctypes[i] == a->ctype;
        if (!ok)
            return gdoc_fail(d, err, from, "accessor %u: componentType %u is not allowed here", index, a->ctype);
    }
    size_t elem = (size_t)a->comps * csize(a->ctype);
    if (view != UINT32_MAX) {
        const unsigned char *data;
        size_t len, stride;
        if (view_range(d, view, &data, &len, &stride, err) < 0)
            return -1;
        if (stride && stride < elem)
            return gdoc_fail(d, err, ptr, "bufferView %u's byteStride %zu is smaller than an element (%zu bytes)",
                             view, stride, elem);
        a->stride = stride ? stride : elem;
        uint64_t end = off + (uint64_t)a->stride * (a->count - 1) + elem;
        if (end > len)
            return gdoc_fail(d, err, ptr, "%u elements from byte %llu need %llu bytes; bufferView %u has %zu",
                             a->count, (unsigned long long)off, (unsigned long long)end, view, len);
        a->base = data + off;
    } else if (off != 0) {
        return gdoc_fail(d, err, ptr, "byteOffset without a bufferView");
    }
    const cJSON *sp = cJSON_GetObjectItemCaseSensitive(o, "sparse");
    if (sp && sparse(d, sp, ptr, a, elem, err) < 0)
        return -1;
    return 0;
}

static double component(const unsigned char *p, uint32_t ctype, int normalized)
{
    switch (ctype) {
    case GDOC_I8: {
        double x = (double)(int8_t)p[0];
        return normalized ? fmax(x / 127.0, -1.0) : x;
    }
    case GDOC_U8:
        return normalized ? p[0] / 255.0 : p[0];
    case GDOC_I16: {
        double x = (double)(int16_t)(uint16_t)(p[0] | p[1] << 8);
        return normalized ? fmax(x / 32767.0, -1.0) : x;
    }
    case GDOC_U16: {
        double x = (double)(uint16_t)(p[0] | p[1] << 8);
        return normalized ? x / 65535.0 : x;
    }
    case GDOC_U32:
        return (double)le32(p);
    default: {
        uint32_t u = le32(p);
        float f;
        memcpy(&f, &u, sizeof f);
        return f;
    }
    }
}

/* Where element i's bytes are, or NULL for a zero element. */
static const unsigned char *element(const gdoc_acc *a, uint32_t i)
{
    if (a->n_sparse) {
        uint32_t isz = csize(a->sp_itype), lo = 0, hi = a->n_sparse;
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            const unsigned char *q = a->sp_index + (size_t)mid * isz;
            uint32_t k = isz == 1 ? q[0] : isz == 2 ? (uint32_t)(q[0] | q[1] << 8) : le32(q);
            if (k == i)
                return a->sp_value + (size_t)mid * a->comps * csize(a->ctype);
            if (k < i)
                lo = mid + 1;
            else
                hi = mid;
        }
    }
    return a->base ? a->base + a->stride * i : NULL;
}

double gdoc_get(const gdoc_acc *a, uint32_t i, uint32_t c)
{
    const unsigned char *p = element(a, i);
    return p ? component(p + (size_t)c * csize(a->ctype), a->ctype, a->normalized) : 0.0;
}

uint32_t gdoc_get_uint(const gdoc_acc *a, uint32_t i)
{
    const unsigned char *p = element(a, i);
    if (!p)
        return 0;
    switch (a->ctype) {
    case GDOC_U8: return p[0];
    case GDOC_U16: return (uint32_t)(p[0] | p[1] << 8);
    default: return le32(p);
    }
}
