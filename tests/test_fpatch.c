/* test_fpatch.c -- scene patches (common/fpatch.h): a scene laid out
 * again from its sections is the same bytes; a patch rebuilds the scene it
 * was made of, byte for byte; a patch that is truncated, damaged, of
 * another base or out of its rules in any field is refused with the byte
 * offset at fault, never a crash; the worker's file form checks its base
 * and its result. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fbin.h"
#include "fpatch.h"
#include "scenes.h"

#define SCENE(CAM, EXTRA)                                                                                    \
    "{\"image\": {\"width\": 16, \"height\": 12, \"spp\": 1},"                                                \
    " \"camera\": {\"position\": " CAM ", \"target\": [0, 0.5, 0], \"fov\": 50},"                            \
    " \"materials\": {\"w\": {\"type\": \"lambert\", \"albedo\": [0.7, 0.7, 0.7]}},"                         \
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [10, 10, 10]}],"             \
    " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.5, \"material\": \"w\"},"    \
    "  {\"type\": \"triangle\", \"vertices\": [[-2, 0, 1], [2, 0, 1], [0, 2, 1]], \"material\": \"w\"}" EXTRA \
    "]}"

static void wr32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void wr64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }

/* Applying p[0..n) to base must fail with a message containing `want`. */
static void refused(const char *what, const unsigned char *p, size_t n, const fr_scene *base, const char *want)
{
    void *out = NULL;
    size_t size = 0;
    fr_error err = {0};
    int rc = fpatch_apply(p, n, base->blob, base->blob_size, &out, &size, &err);
    CHECK(rc < 0 && strstr(err.msg, want), "%s: expected a refusal naming '%s', got rc %d: %s", what, want, rc,
          rc < 0 ? err.msg : "accepted");
    if (rc == 0)
        free(out);
}

/* Applying p to base gives exactly want's bytes. */
static void rebuilds(const char *what, const void *p, size_t n, const fr_scene *base, const fr_scene *want)
{
    void *out = NULL;
    size_t size = 0;
    fr_error err = {0};
    int rc = fpatch_apply(p, n, base->blob, base->blob_size, &out, &size, &err);
    CHECK(rc == 0 && size == want->blob_size && !memcmp(out, want->blob, size), "%s: rebuilt scene differs (%s)",
          what, rc ? err.msg : "bytes");
    free(out);
}

int main(void)
{
    fr_scene a, b, c;
    test_scene(SCENE("[0, 1, -4]", ""), &a);
    test_scene(SCENE("[1, 1, -4]", ""), &b);
    test_scene(SCENE("[0, 1, -4]", ", {\"type\": \"sphere\", \"center\": [1, 0.5, 0], \"radius\": 0.25, "
                                   "\"material\": \"w\"}"), &c);
    fr_error err;

    /* Sections laid out again: the same file. */
    fpatch_sect s[FPATCH_SECTIONS + 1];
    void *blob = NULL;
    size_t size = 0;
    uint64_t hash = 0;
    CHECK(fpatch_sections(a.blob, a.blob_size, s, &err) == 0, "sections: %s", err.msg);
    CHECK(fpatch_assemble(s, &blob, &size, &hash, &err) == 0, "assemble: %s", err.msg);
    CHECK(size == a.blob_size && hash == a.hash && !memcmp(blob, a.blob, size), "assembled scene differs");
    free(blob);
    CHECK(fpatch_same(&s[2], &s[2]) && !fpatch_same(&s[1], &s[2]), "fpatch_same");

    /* A camera move: the camera section alone, and the scene rebuilt. */
    void *p = NULL;
    size_t n = 0;
    uint64_t mask = 0;
    CHECK(fpatch_make(a.blob, a.blob_size, b.blob, b.blob_size, &p, &n, &mask, &err) == 0, "make: %s", err.msg);
    CHECK(mask == 1u << 1, "a camera move changes the camera section alone, mask %#llx", (unsigned long long)mask);
    CHECK(n == FPATCH_HEADER + FPATCH_ENTRY + sizeof(fr_camera), "camera patch of %zu bytes", n);
    uint64_t base = 0;
    CHECK(fpatch_base(p, n, &base, &err) == 0 && base == a.hash, "the patch names its base");
    rebuilds("camera", p, n, &a, &b);
    refused("another base", p, n, &c, "byte 16");
    /* Truncated anywhere, or with bytes after it. */
    for (size_t k = 0; k < n; k++) {
        char what[64];
        snprintf(what, sizeof what, "truncated to %zu bytes", k);
        refused(what, p, k, &a, "byte ");
    }
    unsigned char *q = malloc(n + 8);
    memcpy(q, p, n);
    memset(q + n, 0, 8);
    refused("trailing bytes", q, n + 8, &a, "after the last section");
    /* Every byte of the header, the entry and the data damaged. */
    for (size_t k = 0; k < n; k++) {
        memcpy(q, p, n);
        q[k] ^= 0x41;
        char what[64];
        snprintf(what, sizeof what, "byte %zu damaged", k);
        void *out = NULL;
        size_t osize;
        fr_error e = {0};
        int rc = fpatch_apply(q, n, a.blob, a.blob_size, &out, &osize, &e);
        CHECK(rc < 0 && strstr(e.msg, "byte "), "%s: %s", what, rc ? e.msg : "accepted");
        if (rc == 0)
            free(out);
    }
    /* Fields out of their rules, one at a time. */
    memcpy(q, p, n);
    wr32(q + 8, 2);
    refused("patch version", q, n, &a, "byte 8");
    memcpy(q, p, n);
    wr32(q + 48, FBIN_VERSION + 1);
    refused("scene version", q, n, &a, "byte 48");
    memcpy(q, p, n);
    q[60] = 1;
    refused("reserved byte", q, n, &a, "byte 60");
    memcpy(q, p, n);
    wr64(q + FPATCH_HEADER + 8, (uint64_t)1 << 40);
    refused("huge count", q, n, &a, "past the end");
    memcpy(q, p, n);
    wr32(q + FPATCH_HEADER + 4, 12);
    refused("element size", q, n, &a, "element size");
    memcpy(q, p, n);
    wr32(q + 12, 1u << 1 | 1u << 5);
    refused("a mask of two sections, one carried", q, n, &a, "runs past the end");
    memcpy(q, p, n);
    wr32(q + 12, 1u << 2);
    refused("a mask naming another section", q, n, &a, "where the mask says");
    memcpy(q, p, n);
    wr32(q + 52, 1u << (FPATCH_SECTIONS - 32));
    refused("a mask naming a section past the last", q, n, &a, "byte 52");
    memcpy(q, p, n);
    wr64(q + 40, b.blob_size + 64);
    refused("announced size", q, n, &a, "byte 40");
    free(q);
    free(p);

    /* New geometry: sections of new sizes, rebuilt exactly too. */
    CHECK(fpatch_make(a.blob, a.blob_size, c.blob, c.blob_size, &p, &n, &mask, &err) == 0, "make: %s", err.msg);
    CHECK(mask & 1u << 4, "a new sphere changes the spheres section, mask %#llx", (unsigned long long)mask);
    rebuilds("geometry", p, n, &a, &c);
    free(p);

    /* The worker's form: the base found by its hash beside the output. */
    char dir[] = "/tmp/franja-test-fpatch-XXXXXX", hex[17], path[256], in[256], out[256];
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    fbin_hash_hex(a.hash, hex);
    snprintf(path, sizeof path, "%s/%s.fbin", dir, hex);
    snprintf(in, sizeof in, "%s/patch", dir);
    snprintf(out, sizeof out, "%s/new.fbin", dir);
    CHECK(fpatch_make(a.blob, a.blob_size, b.blob, b.blob_size, &p, &n, &mask, &err) == 0, "make: %s", err.msg);
    FILE *f = fopen(in, "wb");
    fwrite(p, 1, n, f);
    fclose(f);
    CHECK(fpatch_is(in), "fpatch_is on a patch");
    CHECK(fpatch_file(in, out, &hash, &err) < 0 && strstr(err.msg, "base scene"), "no base: %s", err.msg);
    CHECK(access(in, F_OK) != 0, "the patch file is removed after a failure");
    CHECK(fbin_write(&a, path, &err) == 0, "write base: %s", err.msg);
    CHECK(!fpatch_is(path), "fpatch_is on a scene");
    f = fopen(in, "wb");
    fwrite(p, 1, n, f);
    fclose(f);
    CHECK(fpatch_file(in, out, &hash, &err) == 0 && hash == b.hash, "patched file: %s", err.msg);
    fr_scene got;
    CHECK(fbin_load(out, &got, &err) == 0 && got.blob_size == b.blob_size && !memcmp(got.blob, b.blob, b.blob_size),
          "the patched file is the scene");
    scn_free(&got);
    CHECK(access(in, F_OK) != 0, "the patch file is removed");
    /* A damaged base in the cache is refused by its hash. */
    f = fopen(path, "r+b");
    fseek(f, 2000, SEEK_SET);
    fputc(0x5a, f);
    fclose(f);
    f = fopen(in, "wb");
    fwrite(p, 1, n, f);
    fclose(f);
    unlink(out);
    CHECK(fpatch_file(in, out, &hash, &err) < 0 && access(out, F_OK) != 0, "a damaged base is refused");
    unlink(path);
    rmdir(dir);
    free(p);
    scn_free(&a);
    scn_free(&b);
    scn_free(&c);
    return check_done();
}
