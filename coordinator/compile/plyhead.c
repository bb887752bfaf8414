/* plyhead.c -- a PLY header's element counts against the file's size. */
#include "compile/plyhead.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Bytes of a binary scalar type, 0 if unknown. */
static unsigned type_size(const char *t, size_t n)
{
    static const struct {
        const char *name;
        unsigned size;
    } types[] = {{"char", 1},  {"int8", 1},   {"uchar", 1},  {"uint8", 1},   {"short", 2},  {"int16", 2},
                 {"ushort", 2}, {"uint16", 2}, {"int", 4},    {"int32", 4},   {"uint", 4},   {"uint32", 4},
                 {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
    for (size_t i = 0; i < sizeof types / sizeof *types; i++)
        if (strlen(types[i].name) == n && !memcmp(types[i].name, t, n))
            return types[i].size;
    return 0;
}

/* The words of one header line: up to 8, each as start and length. */
typedef struct {
    const char *w[8];
    size_t n[8];
    int count;
} words;

static void split(const char *p, const char *end, words *ws)
{
    ws->count = 0;
    while (p < end && ws->count < 8) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\r'))
            p++;
        if (p == end)
            break;
        const char *s = p;
        while (p < end && *p != ' ' && *p != '\t' && *p != '\r')
            p++;
        ws->w[ws->count] = s;
        ws->n[ws->count++] = (size_t)(p - s);
    }
}

static int is(const words *ws, int i, const char *s)
{
    return i < ws->count && ws->n[i] == strlen(s) && !memcmp(ws->w[i], s, ws->n[i]);
}

/* Adds count * each to *need; returns -1 on overflow. */
static int add_need(uint64_t *need, uint64_t count, uint64_t each)
{
    uint64_t t;
    if (__builtin_mul_overflow(count, each, &t) || __builtin_add_overflow(*need, t, need))
        return -1;
    return 0;
}

int plyhead_check(const char *path, const char *text, size_t len, size_t file_size, fr_error *err)
{
    const char *p = text, *end = text + len;
    int binary = -1, line = 0;
    uint64_t need = 0, count = 0, each = 0;
    char name[64] = "";
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        if (!nl)
            return 0; /* no end_header among the bytes read: the importer's to judge */
        words ws;
        split(p, nl, &ws);
        p = nl + 1;
        if (line++ == 0) {
            if (!(ws.count == 1 && is(&ws, 0, "ply")))
                return 0; /* not a PLY file */
            continue;
        }
        if (is(&ws, 0, "format")) {
            binary = is(&ws, 1, "ascii") ? 0 : (is(&ws, 1, "binary_little_endian") || is(&ws, 1, "binary_big_endian"));
            if (!is(&ws, 1, "ascii") && !binary)
                return 0;
        } else if (is(&ws, 0, "element") || is(&ws, 0, "end_header")) {
            uint64_t before = need;
            if (add_need(&need, count, each) < 0 || need > file_size)
                return fr_fail(err, "%s: the PLY header declares %llu '%s' elements, which take at least %llu bytes "
                               "(after %llu for the elements before them): more than the whole file's %zu bytes",
                               path, (unsigned long long)count, name,
                               (unsigned long long)(need >= before ? need - before : UINT64_MAX),
                               (unsigned long long)before, file_size);
            if (is(&ws, 0, "end_header")) {
                size_t body = file_size > (size_t)(p - text) ? file_size - (size_t)(p - text) : 0;
                if (binary < 0)
                    return 0;
                if (need > body)
                    return fr_fail(err, "%s: the PLY header declares elements of at least %llu bytes, more than the "
                                   "%zu bytes after the header", path, (unsigned long long)need, body);
                return 0;
            }
            if (ws.count != 3 || ws.n[2] > 20)
                return 0;
            char num[24];
            memcpy(num, ws.w[2], ws.n[2]);
            num[ws.n[2]] = 0;
            char *e;
            errno = 0;
            unsigned long long c = strtoull(num, &e, 10);
            if (*e || errno || num[0] == '-')
                return 0;
            count = c;
            each = 0;
            snprintf(name, sizeof name, "%.*s", (int)(ws.n[1] < 60 ? ws.n[1] : 60), ws.w[1]);
        } else if (is(&ws, 0, "property")) {
            if (binary < 0)
                return 0;
            if (is(&ws, 1, "list")) {
                if (ws.count != 5)
                    return 0;
                unsigned cs = type_size(ws.w[2], ws.n[2]);
                if (!cs || !type_size(ws.w[3], ws.n[3]))
                    return 0;
                each += binary ? cs : 2; /* at least the count: an empty list */
            } else {
                unsigned s = ws.count == 3 ? type_size(ws.w[1], ws.n[1]) : 0;
                if (!s)
                    return 0;
                each += binary ? s : 2;
            }
        } else if (!(is(&ws, 0, "comment") || is(&ws, 0, "obj_info") || ws.count == 0)) {
            return 0; /* something this check does not know */
        }
    }
    return 0;
}
