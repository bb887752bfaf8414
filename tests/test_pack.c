/* test_pack.c -- scenes compressed for the trip to a host and unpacked
 * there (coordinator/transport/pack.h, common/unpack.h): the unpacked file
 * is the scene byte for byte, with its hash; a damaged or cut stream and a
 * file that is no scene are refused, leaving nothing behind; the shared
 * compressed copy is made once and removed with its last holder. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "tmpfiles.h"
#include "fbin.h"
#include "file.h"
#include "transport/pack.h"
#include "unpack.h"

static char dir[64];

static int entries(void) { return tmpfiles_entries(dir); }

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/franja-test-pack-XXXXXX");
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    setenv("TMPDIR", dir, 1);
    char scene[128], zst[128], out[128];
    snprintf(scene, sizeof scene, "%s/s.fbin", dir);
    snprintf(zst, sizeof zst, "%s/s.fbin.zst", dir);
    snprintf(out, sizeof out, "%s/cache.fbin", dir);
    /* Compiled into the test's own directory: no fixed name in /tmp. */
    CHECK(tmpfiles_compile("scenes/cornell-textured.json", scene) == 0, "compile");
    fr_scene s;
    fr_error err;
    CHECK(fbin_load(scene, &s, &err) == 0, "%s", err.msg);
    uint64_t want = s.hash;
    scn_free(&s);
    struct stat st;
    stat(scene, &st);

    /* Packed, unpacked: the same bytes and hash; the packed file is gone. */
    uint64_t size, hash;
    CHECK(pack_file(scene, zst, PACK_LEVEL, &size, &err) == 0, "%s", err.msg);
    CHECK(size > 0 && size * 2 < (uint64_t)st.st_size, "a textured scene packs to under half: %llu of %lld bytes",
          (unsigned long long)size, (long long)st.st_size);
    CHECK(pack_file(scene, zst, PACK_LEVEL, &size, &err) < 0, "an existing file is not overwritten");
    CHECK(unpack_available() == 1, "this build unpacks");
    CHECK(unpack_file(zst, out, &hash, &err) == 0, "%s", err.msg);
    CHECK(hash == want && tmpfiles_same(out, scene), "the unpacked scene is the scene");
    CHECK(access(zst, F_OK) < 0 && entries() == 2, "only the scene and its copy are left: %d", entries());

    /* A damaged stream: refused by zstd's checksum, nothing left. */
    unlink(out);
    const struct { long at; const char *what; } damage[] = {{2000, "checksum"}, {-1, "cut short"}};
    for (int k = 0; k < 2; k++) {
        CHECK(pack_file(scene, zst, 1, &size, &err) == 0, "%s", err.msg);
        if (damage[k].at >= 0) {
            FILE *f = fopen(zst, "r+b");
            fseek(f, damage[k].at, SEEK_SET);
            fputs("XXXX", f);
            fclose(f);
        } else {
            CHECK(truncate(zst, (off_t)size / 2) == 0, "truncate");
        }
        CHECK(unpack_file(zst, out, &hash, &err) < 0 && strstr(err.msg, damage[k].what), "damage %d: %s", k,
              err.msg);
        CHECK(entries() == 1, "damage %d: only the scene is left (%d entries)", k, entries());
    }
    /* Not a scene (a damaged .fbin, packed whole): refused by its hash. */
    char bad[128], cmd[300];
    snprintf(bad, sizeof bad, "%s/bad.fbin", dir);
    snprintf(cmd, sizeof cmd, "cp %s %s && printf X | dd of=%s bs=1 seek=5000 conv=notrunc 2>/dev/null", scene, bad,
             bad);
    CHECK(system(cmd) == 0, "damage");
    CHECK(pack_file(bad, zst, 1, &size, &err) == 0, "%s", err.msg);
    CHECK(unpack_file(zst, out, &hash, &err) < 0 && strstr(err.msg, "hash"), "a damaged scene: %s", err.msg);
    CHECK(access(out, F_OK) < 0 && access(zst, F_OK) < 0, "nothing left of it");
    unlink(bad);

    /* The shared copy: one file for two holders, gone after both. */
    char p1[4200], p2[4200];
    uint64_t n1, n2;
    CHECK(pack_acquire(scene, want, PACK_ZSTD, p1, sizeof p1, &n1, &err) == 0, "%s", err.msg);
    CHECK(pack_acquire(scene, want, PACK_ZSTD, p2, sizeof p2, &n2, &err) == 0, "%s", err.msg);
    CHECK(!strcmp(p1, p2) && n1 == n2 && !strncmp(p1, dir, strlen(dir)), "one copy in $TMPDIR: %s %s", p1, p2);
    /* The other form: a copy of its own, smaller. */
    char p3[4200];
    uint64_t n3;
    CHECK(pack_acquire(scene, want, PACK_PARTS, p3, sizeof p3, &n3, &err) == 0, "%s", err.msg);
    CHECK(strcmp(p1, p3) && n3 < n1 && access(p3, F_OK) == 0, "a packed scene beside: %s %llu, %llu", p3,
          (unsigned long long)n3, (unsigned long long)n1);
    pack_release(want, PACK_PARTS);
    CHECK(access(p3, F_OK) < 0 && access(p1, F_OK) == 0, "each form released on its own");
    pack_release(want, PACK_ZSTD);
    CHECK(access(p1, F_OK) == 0, "kept while held");
    pack_release(want, PACK_ZSTD);
    CHECK(access(p1, F_OK) < 0, "removed after the last holder");

    unlink(scene);
    rmdir(dir);
    return check_done();
}
