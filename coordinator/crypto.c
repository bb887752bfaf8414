/* crypto.c -- Cryptomatte ids, manifest and metadata for the
 * crypto_material pass, and the material_id name table (see crypto.h). */
#include "crypto.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "passes.h"

static uint32_t rotl(uint32_t x, int r) { return x << r | x >> (32 - r); }

uint32_t crypto_murmur3(const void *key, size_t len, uint32_t seed)
{
    const unsigned char *p = key;
    const uint32_t c1 = 0xcc9e2d51u, c2 = 0x1b873593u;
    uint32_t h = seed;
    size_t blocks = len / 4;
    for (size_t i = 0; i < blocks; i++, p += 4) {
        uint32_t k = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        k *= c1;
        k = rotl(k, 15);
        k *= c2;
        h ^= k;
        h = rotl(h, 13);
        h = h * 5u + 0xe6546b64u;
    }
    uint32_t k = 0;
    switch (len & 3) {
    case 3: k ^= (uint32_t)p[2] << 16; /* fall through */
    case 2: k ^= (uint32_t)p[1] << 8;  /* fall through */
    case 1:
        k ^= p[0];
        k *= c1;
        k = rotl(k, 15);
        k *= c2;
        h ^= k;
    }
    h ^= (uint32_t)len;
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

float crypto_float(uint32_t hash)
{
    uint32_t exp = hash >> 23 & 0xffu;
    exp = exp < 1 ? 1 : exp > 254 ? 254 : exp;
    uint32_t bits = (hash & 0x80000000u) | exp << 23 | (hash & 0x7fffffu);
    float f;
    memcpy(&f, &bits, 4);
    return f;
}

void crypto_name(const crypto_names *names, uint32_t index, char *out)
{
    if (index < names->n && names->v[index].name[0])
        snprintf(out, 64, "%s", names->v[index].name);
    else
        snprintf(out, 64, "%s%u", names->prefix ? names->prefix : "material", index);
}

/* The Cryptomatte id of material index. */
static float material_id(const crypto_names *names, uint32_t index)
{
    char name[64];
    crypto_name(names, index, name);
    return crypto_float(crypto_murmur3(name, strlen(name), 0));
}

void crypto_ids(float *pass, size_t npx, uint32_t stride, const crypto_names *names)
{
    /* The ids of the named entries once each (a pixel's names are
     * hashed again only past them, or when memory runs out). */
    float *known = names->n ? malloc(names->n * sizeof *known) : NULL;
    for (uint32_t k = 0; known && k < names->n; k++)
        known[k] = material_id(names, k);
    for (size_t i = 0; i < npx; i++)
        for (int r = 0; r < PASS_CRYPTO_RANKS; r++) {
            float *id = pass + i * stride + 2 * r;
            if (*id < 1.0f)
                continue;
            uint32_t k = (uint32_t)*id - 1;
            *id = known && k < names->n ? known[k] : material_id(names, k);
        }
    free(known);
}

/* A growing string. */
typedef struct {
    char *s;
    size_t n, cap;
} text;

static int put(text *t, const char *s)
{
    size_t k = strlen(s);
    if (t->n + k + 1 > t->cap) {
        size_t cap = (t->n + k + 1) * 2;
        char *m = realloc(t->s, cap);
        if (!m)
            return -1;
        t->s = m;
        t->cap = cap;
    }
    memcpy(t->s + t->n, s, k + 1);
    t->n += k;
    return 0;
}

/* name as a JSON string (its quotes and backslashes escaped; names hold no
 * control characters, fbin.c). */
static int put_json(text *t, const char *name)
{
    char q[140];
    size_t k = 0;
    q[k++] = '"';
    for (const char *c = name; *c && k < sizeof q - 3; c++) {
        if (*c == '"' || *c == '\\')
            q[k++] = '\\';
        q[k++] = *c;
    }
    q[k++] = '"';
    q[k] = 0;
    return put(t, q);
}

int crypto_metadata(const char *type, const crypto_names *names, uint32_t n_materials, const char *attrs[8],
                    char **buf, fr_error *err)
{
    char key[16];
    snprintf(key, sizeof key, "%08x", crypto_murmur3(type, strlen(type), 0));
    key[7] = 0;
    text t = {NULL, 0, 0};
    /* The names and the values first, then the manifest, in one buffer:
     * the attribute pointers are taken once it no longer moves. */
    char head[200];
    snprintf(head, sizeof head, "cryptomatte/%s/name%ccryptomatte/%s/hash%ccryptomatte/%s/conversion%c"
             "cryptomatte/%s/manifest%c%s%cMurmurHash3_32%cuint32_to_float32%c", key, 0, key, 0, key, 0, key, 0,
             type, 0, 0, 0);
    size_t head_len = 0;
    for (int z = 0; z < 7; z++)
        head_len += strlen(head + head_len) + 1;
    t.s = malloc(head_len + 64);
    if (!t.s)
        return fr_fail(err, "out of memory for the Cryptomatte manifest");
    memcpy(t.s, head, head_len);
    t.n = head_len;
    t.cap = head_len + 64;
    t.s[t.n] = 0;
    int bad = put(&t, "{");
    for (uint32_t i = 0; i < n_materials && !bad; i++) {
        char name[64], hex[16];
        crypto_name(names, i, name);
        /* A name given twice is one entry (the same id). */
        int seen = 0;
        for (uint32_t j = 0; j < i && !seen; j++) {
            char other[64];
            crypto_name(names, j, other);
            seen = !strcmp(other, name);
        }
        if (seen)
            continue;
        float id = crypto_float(crypto_murmur3(name, strlen(name), 0));
        uint32_t bits;
        memcpy(&bits, &id, 4);
        snprintf(hex, sizeof hex, ":\"%08x\"", bits);
        bad = (t.s[t.n - 1] != '{' && put(&t, ",")) || put_json(&t, name) || put(&t, hex);
    }
    if (bad || put(&t, "}")) {
        free(t.s);
        return fr_fail(err, "out of memory for the Cryptomatte manifest");
    }
    const char *p = t.s;
    const char *v[8];
    for (int z = 0; z < 8; z++) {
        v[z] = p;
        p += strlen(p) + 1;
    }
    /* name, hash, conversion, manifest keys; then their values. */
    for (int z = 0; z < 4; z++) {
        attrs[2 * z] = v[z];
        attrs[2 * z + 1] = v[4 + z];
    }
    *buf = t.s;
    return 0;
}

int crypto_name_table(const crypto_names *names, uint32_t n_materials, char **out, fr_error *err)
{
    text t = {NULL, 0, 0};
    int bad = put(&t, "[");
    for (uint32_t i = 0; i < n_materials && !bad; i++) {
        char name[64];
        crypto_name(names, i, name);
        bad = (i && put(&t, ",")) || put_json(&t, name);
    }
    if (bad || put(&t, "]")) {
        free(t.s);
        return fr_fail(err, "out of memory for the materials' names");
    }
    *out = t.s;
    return 0;
}
