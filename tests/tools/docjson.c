/* docjson.c -- the JSON side of the documentation examples' test
 * (tests/it_docs.sh): reads a scene fragment as the docs show it and builds
 * the scenes that test it.
 *
 * A fragment file holds the text of one fenced example, read as KIND:
 *   value    one complete JSON value (a whole scene)
 *   members  object members, `"name": value, ...` (top-level fields, or
 *            entries of "materials")
 *   seq      JSON values one after another, commas between them optional
 *            (shapes written one per line)
 *   outline  like value, with `...` standing for elided content
 *
 *   docjson parse KIND FRAG
 *       checks FRAG and prints it as one JSON value
 *   docjson merge BASE WHERE FRAG OUT [--dark]
 *       writes BASE with FRAG dropped in: WHERE is `top` (FRAG's members
 *       replace BASE's fields; "materials", "textures" and "media" are
 *       merged entry by entry), `materials` (FRAG's members are added to
 *       BASE's materials) or `shapes` (FRAG's values are added to BASE's
 *       shapes).  --dark first removes BASE's own lights: its "lights" and
 *       every shape whose material has an "emission"
 *   docjson from WHERE FRAG SCENE
 *       checks that FRAG is a piece of SCENE: every field, entry or shape it
 *       has is in SCENE at the same place with the same values (numbers
 *       equal to 1e-9 relative)
 *   docjson spheres BASE FRAG OUTDIR X Y Z R
 *       for every material NAME of FRAG (members of "materials"), writes
 *       OUTDIR/NAME.json: BASE with FRAG's materials and a sphere of radius
 *       R at (X, Y, Z) made of NAME; prints the names, one a line
 *
 * Errors name the line of FRAG (counted from 1) and what was expected, and
 * exit 1; a bad command line exits 2. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return NULL;
    }
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (n + 1 == cap) {
            char *more = cap < ((size_t)64 << 20) ? realloc(buf, cap * 2) : NULL;
            if (!more) {
                free(buf);
                buf = NULL;
                fprintf(stderr, "%s: too large\n", path);
                break;
            }
            buf = more;
            cap *= 2;
        }
    }
    fclose(f);
    if (buf)
        buf[n] = '\0';
    return buf;
}

/* 1-based line of position at in text (the wrapper text before it excluded). */
static int line_of(const char *text, const char *at)
{
    int line = 1;
    for (const char *p = text; p < at && *p; p++)
        line += *p == '\n';
    return line;
}

static cJSON *fail_at(const char *text, const char *at, const char *what)
{
    fprintf(stderr, "line %d: %s\n", line_of(text, at), what);
    return NULL;
}

static const char *skip_space(const char *p)
{
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
        p++;
    return p;
}

/* Reads text as KIND; NULL after a message. */
static cJSON *parse_fragment(const char *kind, const char *text)
{
    if (!strcmp(kind, "value") || !strcmp(kind, "outline")) {
        char *copy = strdup(text);
        if (!copy)
            return NULL;
        if (!strcmp(kind, "outline")) {
            /* `{ ... }` -> `{}`, `[ ... ]` -> `[]`, `, ...` dropped: blank
             * the dots (and a comma before them) in place, keeping lines. */
            for (char *p = strstr(copy, "..."); p; p = strstr(p, "...")) {
                memset(p, ' ', 3);
                char *q = p;
                while (q > copy && (q[-1] == ' ' || q[-1] == '\t'))
                    q--;
                if (q > copy && q[-1] == ',')
                    q[-1] = ' ';
            }
        }
        const char *end;
        cJSON *v = cJSON_ParseWithOpts(copy, &end, 0);
        if (!v) {
            fail_at(copy, cJSON_GetErrorPtr() ? cJSON_GetErrorPtr() : copy, "not valid JSON here");
        } else if (*skip_space(end)) {
            fail_at(copy, end, "text after the JSON value");
            cJSON_Delete(v);
            v = NULL;
        }
        free(copy);
        return v;
    }
    if (!strcmp(kind, "members")) {
        size_t n = strlen(text);
        char *wrapped = malloc(n + 4);
        if (!wrapped)
            return NULL;
        wrapped[0] = '{';
        memcpy(wrapped + 1, text, n);
        strcpy(wrapped + 1 + n, "\n}");
        const char *end;
        cJSON *v = cJSON_ParseWithOpts(wrapped, &end, 0);
        if (!v) {
            const char *at = cJSON_GetErrorPtr();
            at = at && at > wrapped ? at - 1 : wrapped;
            fail_at(text, text + (at - wrapped), "not valid JSON object members here (`\"name\": value, ...`)");
        } else if (*skip_space(end)) {
            fail_at(text, text + (end - wrapped - 1), "text after the members");
            cJSON_Delete(v);
            v = NULL;
        }
        free(wrapped);
        return v;
    }
    if (!strcmp(kind, "seq")) {
        cJSON *arr = cJSON_CreateArray();
        const char *p = skip_space(text);
        while (arr && *p) {
            const char *end;
            cJSON *v = cJSON_ParseWithOpts(p, &end, 0);
            if (!v) {
                const char *at = cJSON_GetErrorPtr();
                fail_at(text, at ? at : p, "not a JSON value here");
                cJSON_Delete(arr);
                return NULL;
            }
            cJSON_AddItemToArray(arr, v);
            p = skip_space(end);
            if (*p == ',')
                p = skip_space(p + 1);
        }
        if (arr && cJSON_GetArraySize(arr) == 0) {
            fail_at(text, text, "no JSON value");
            cJSON_Delete(arr);
            return NULL;
        }
        return arr;
    }
    fprintf(stderr, "docjson: unknown fragment kind '%s' (value, members, seq, outline)\n", kind);
    return NULL;
}

static cJSON *read_json(const char *path, const char *kind)
{
    char *text = slurp(path);
    if (!text)
        return NULL;
    cJSON *v = parse_fragment(kind, text);
    if (!v)
        fprintf(stderr, "(in %s)\n", path);
    free(text);
    return v;
}

static int write_json(const char *path, const cJSON *v)
{
    char *s = cJSON_Print(v);
    FILE *f = s ? fopen(path, "w") : NULL;
    int ok = f && fputs(s, f) >= 0 && fputc('\n', f) != EOF;
    if (f && fclose(f) != 0)
        ok = 0;
    if (!ok)
        perror(path);
    free(s);
    return ok ? 0 : -1;
}

/* Object member key of obj, created as an empty object if missing. */
static cJSON *object_member(cJSON *obj, const char *key)
{
    cJSON *m = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!m)
        m = cJSON_AddObjectToObject(obj, key);
    return m;
}

static void put(cJSON *obj, const char *key, const cJSON *value)
{
    cJSON *copy = cJSON_Duplicate(value, 1);
    if (cJSON_GetObjectItemCaseSensitive(obj, key))
        cJSON_ReplaceItemInObjectCaseSensitive(obj, key, copy);
    else
        cJSON_AddItemToObject(obj, key, copy);
}

static int is_table(const char *key)
{
    return !strcmp(key, "materials") || !strcmp(key, "textures") || !strcmp(key, "media");
}

/* Removes base's lights: "lights", and shapes whose material emits. */
static void make_dark(cJSON *base)
{
    cJSON_DeleteItemFromObjectCaseSensitive(base, "lights");
    cJSON *mats = cJSON_GetObjectItemCaseSensitive(base, "materials");
    cJSON *shapes = cJSON_GetObjectItemCaseSensitive(base, "shapes");
    for (int i = cJSON_GetArraySize(shapes) - 1; i >= 0; i--) {
        cJSON *name = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(shapes, i), "material");
        cJSON *m = cJSON_IsString(name) ? cJSON_GetObjectItemCaseSensitive(mats, name->valuestring) : NULL;
        if (m && cJSON_GetObjectItemCaseSensitive(m, "emission"))
            cJSON_DeleteItemFromArray(shapes, i);
    }
}

static int merge(cJSON *base, const char *where, const cJSON *frag)
{
    if (!strcmp(where, "top")) {
        if (!cJSON_IsObject(frag))
            return fprintf(stderr, "a top-level fragment is object members\n"), -1;
        for (const cJSON *m = frag->child; m; m = m->next) {
            if (is_table(m->string) && cJSON_IsObject(m)) {
                cJSON *t = object_member(base, m->string);
                for (const cJSON *e = m->child; e; e = e->next)
                    put(t, e->string, e);
            } else {
                put(base, m->string, m);
            }
        }
        return 0;
    }
    if (!strcmp(where, "materials")) {
        if (!cJSON_IsObject(frag))
            return fprintf(stderr, "a materials fragment is object members\n"), -1;
        cJSON *t = object_member(base, "materials");
        for (const cJSON *e = frag->child; e; e = e->next)
            put(t, e->string, e);
        return 0;
    }
    if (!strcmp(where, "shapes")) {
        cJSON *shapes = cJSON_GetObjectItemCaseSensitive(base, "shapes");
        if (!shapes)
            shapes = cJSON_AddArrayToObject(base, "shapes");
        const cJSON *e = cJSON_IsArray(frag) ? frag->child : frag;
        for (; e; e = cJSON_IsArray(frag) ? e->next : NULL)
            cJSON_AddItemToArray(shapes, cJSON_Duplicate(e, 1));
        return 0;
    }
    fprintf(stderr, "docjson: unknown place '%s' (top, materials, shapes)\n", where);
    return -1;
}

/* Deep equality, numbers to 1e-9 relative; on a difference, path gets where. */
static int same(const cJSON *a, const cJSON *b, char *path, size_t cap)
{
    if (cJSON_IsNumber(a) && cJSON_IsNumber(b)) {
        double x = a->valuedouble, y = b->valuedouble;
        return fabs(x - y) <= 1e-9 * fmax(1.0, fmax(fabs(x), fabs(y)));
    }
    if ((a->type & 0xff) != (b->type & 0xff))
        return 0;
    if (cJSON_IsString(a))
        return !strcmp(a->valuestring, b->valuestring);
    if (cJSON_IsArray(a)) {
        if (cJSON_GetArraySize(a) != cJSON_GetArraySize(b))
            return 0;
        int i = 0;
        for (const cJSON *x = a->child, *y = b->child; x; x = x->next, y = y->next, i++) {
            size_t n = strlen(path);
            snprintf(path + n, cap - n, "[%d]", i);
            if (!same(x, y, path, cap))
                return 0;
            path[n] = '\0';
        }
        return 1;
    }
    if (cJSON_IsObject(a)) {
        if (cJSON_GetArraySize(a) != cJSON_GetArraySize(b))
            return 0;
        for (const cJSON *x = a->child; x; x = x->next) {
            size_t n = strlen(path);
            snprintf(path + n, cap - n, ".%s", x->string);
            const cJSON *y = cJSON_GetObjectItemCaseSensitive(b, x->string);
            if (!y || !same(x, y, path, cap))
                return 0;
            path[n] = '\0';
        }
        return 1;
    }
    return 1; /* true, false, null of the same type */
}

static int member_in(const char *table, const cJSON *e, const cJSON *scene_table, const char *scene)
{
    char top[256], path[512];
    snprintf(top, sizeof top, "%s%s%s", table, *table ? "." : "", e->string);
    snprintf(path, sizeof path, "%s", top);
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(scene_table, e->string);
    if (!s) {
        fprintf(stderr, "%s has no %s\n", scene, top);
        return -1;
    }
    if (!same(e, s, path, sizeof path)) {
        fprintf(stderr, "%s differs from %s's (at %s)\n", top, scene, path);
        return -1;
    }
    return 0;
}

static int from(const char *where, const cJSON *frag, const cJSON *scene, const char *name)
{
    int bad = 0;
    if (!strcmp(where, "top")) {
        for (const cJSON *m = frag->child; m; m = m->next) {
            if (is_table(m->string) && cJSON_IsObject(m)) {
                const cJSON *t = cJSON_GetObjectItemCaseSensitive(scene, m->string);
                for (const cJSON *e = m->child; e; e = e->next)
                    bad |= member_in(m->string, e, t, name);
            } else {
                bad |= member_in("", m, scene, name);
            }
        }
    } else if (!strcmp(where, "materials")) {
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(scene, "materials");
        for (const cJSON *e = frag->child; e; e = e->next)
            bad |= member_in("materials", e, t, name);
    } else if (!strcmp(where, "shapes")) {
        const cJSON *shapes = cJSON_GetObjectItemCaseSensitive(scene, "shapes");
        int i = 0;
        for (const cJSON *e = frag->child; e; e = e->next, i++) {
            int found = 0;
            for (const cJSON *s = shapes ? shapes->child : NULL; s && !found; s = s->next) {
                char path[512] = "";
                found = same(e, s, path, sizeof path);
            }
            if (!found) {
                fprintf(stderr, "shape %d of the example is not one of %s's shapes\n", i + 1, name);
                bad = 1;
            }
        }
    } else {
        fprintf(stderr, "docjson: unknown place '%s' (top, materials, shapes)\n", where);
        return -1;
    }
    return bad ? -1 : 0;
}

static int usage(void)
{
    fprintf(stderr, "usage: docjson parse KIND FRAG\n"
                    "       docjson merge BASE top|materials|shapes FRAG OUT [--dark]\n"
                    "       docjson from top|materials|shapes FRAG SCENE\n"
                    "       docjson spheres BASE FRAG OUTDIR X Y Z R\n");
    return 2;
}

static const char *kind_of(const char *where)
{
    return !strcmp(where, "shapes") ? "seq" : "members";
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "parse")) {
        cJSON *v = read_json(argv[3], argv[2]);
        if (!v)
            return 1;
        char *s = cJSON_PrintUnformatted(v);
        puts(s ? s : "");
        free(s);
        cJSON_Delete(v);
        return 0;
    }
    if ((argc == 6 || (argc == 7 && !strcmp(argv[6], "--dark"))) && !strcmp(argv[1], "merge")) {
        cJSON *base = read_json(argv[2], "value"), *frag = base ? read_json(argv[4], kind_of(argv[3])) : NULL;
        int rc = 1;
        if (frag) {
            if (argc == 7)
                make_dark(base);
            if (merge(base, argv[3], frag) == 0 && write_json(argv[5], base) == 0)
                rc = 0;
        }
        cJSON_Delete(base);
        cJSON_Delete(frag);
        return rc;
    }
    if (argc == 5 && !strcmp(argv[1], "from")) {
        cJSON *frag = read_json(argv[3], kind_of(argv[2])), *scene = frag ? read_json(argv[4], "value") : NULL;
        int rc = scene && from(argv[2], frag, scene, argv[4]) == 0 ? 0 : 1;
        cJSON_Delete(frag);
        cJSON_Delete(scene);
        return rc;
    }
    if (argc == 9 && !strcmp(argv[1], "spheres")) {
        cJSON *base = read_json(argv[2], "value"), *frag = base ? read_json(argv[3], "members") : NULL;
        int rc = frag ? 0 : 1;
        double c[4];
        for (int i = 0; i < 4 && !rc; i++) {
            char *end;
            c[i] = strtod(argv[5 + i], &end);
            if (*end || end == argv[5 + i])
                rc = usage();
        }
        for (const cJSON *e = frag && !rc ? frag->child : NULL; e && !rc; e = e->next) {
            cJSON *s = cJSON_Duplicate(base, 1);
            char path[4096];
            merge(s, "materials", frag);
            cJSON *sphere = cJSON_CreateObject();
            cJSON_AddStringToObject(sphere, "type", "sphere");
            cJSON *center = cJSON_AddArrayToObject(sphere, "center");
            for (int i = 0; i < 3; i++)
                cJSON_AddItemToArray(center, cJSON_CreateNumber(c[i]));
            cJSON_AddNumberToObject(sphere, "radius", c[3]);
            cJSON_AddStringToObject(sphere, "material", e->string);
            merge(s, "shapes", sphere);
            cJSON_Delete(sphere);
            if (snprintf(path, sizeof path, "%s/%s.json", argv[4], e->string) >= (int)sizeof path ||
                strchr(e->string, '/') || write_json(path, s) < 0)
                rc = 1;
            else
                printf("%s\n", e->string);
            cJSON_Delete(s);
        }
        cJSON_Delete(base);
        cJSON_Delete(frag);
        return rc;
    }
    return usage();
}
