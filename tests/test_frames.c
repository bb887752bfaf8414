/* test_frames.c -- frame lists and '#' patterns (coordinator/framelist.h). */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "framelist.h"

/* Parses spec and compares with want[0..n) (n < 0: must fail with a
 * message holding frag). */
static void list(const char *spec, const uint32_t *want, int n, const char *frag)
{
    frame_list l;
    fr_error e = {{0}};
    int rc = framelist_parse(spec, &l, &e);
    if (n < 0) {
        CHECK(rc == -1 && l.n == 0 && l.v == NULL, "'%s' accepted (%zu frames)", spec, l.n);
        CHECK(strstr(e.msg, frag) != NULL, "'%s': message '%s' lacks '%s'", spec, e.msg, frag);
        framelist_free(&l);
        return;
    }
    CHECK(rc == 0 && l.n == (size_t)n, "'%s': rc %d, %zu frames, want %d (%s)", spec, rc, l.n, n, e.msg);
    for (size_t i = 0; want && rc == 0 && i < l.n && i < (size_t)n; i++)
        CHECK(l.v[i] == want[i], "'%s': frame %zu is %u, want %u", spec, i, l.v[i], want[i]);
    framelist_free(&l);
}

static void subst(const char *pat, uint32_t f, size_t cap, const char *want)
{
    char buf[64];
    int rc = framelist_subst(pat, f, buf, cap);
    if (!want)
        CHECK(rc == -1, "'%s' %u into %zu bytes: accepted as '%s'", pat, f, cap, buf);
    else
        CHECK(rc == 0 && !strcmp(buf, want), "'%s' %u: got '%s' (rc %d), want '%s'", pat, f, rc ? "" : buf, rc,
              want);
}

int main(void)
{
    list("7", (const uint32_t[]){7}, 1, NULL);
    list("1-4", (const uint32_t[]){1, 2, 3, 4}, 4, NULL);
    list("1-9:3", (const uint32_t[]){1, 4, 7}, 3, NULL);
    list("1-10:3", (const uint32_t[]){1, 4, 7, 10}, 4, NULL);
    list("1,5,9", (const uint32_t[]){1, 5, 9}, 3, NULL);
    list("10-11,2,0-4:4", (const uint32_t[]){10, 11, 2, 0, 4}, 5, NULL);
    list("999999999", (const uint32_t[]){999999999}, 1, NULL);
    list("", NULL, -1, "empty");
    list("3-1", NULL, -1, "runs backwards");
    list("1-3:0", NULL, -1, "at byte 0");
    list("1,,2", NULL, -1, "at byte 2");
    list("1,", NULL, -1, "at byte 2");
    list("-1", NULL, -1, "at byte 0");
    list("1-", NULL, -1, "at byte 0");
    list("1 - 3", NULL, -1, "at byte 0");
    list("1-3x", NULL, -1, "at byte 0");
    list("1000000000", NULL, -1, "0..999999999");
    list("0-999999999", NULL, -1, "more than 100000 frames");
    list("0-99999,0-1", NULL, -1, "more than 100000 frames");
    list("0-99999", NULL, 100000, NULL); /* the most frames: count only */

    subst("f.####.json", 7, 64, "f.0007.json");
    subst("f.#.json", 123, 64, "f.123.json");
    subst("#/x.##.png", 5, 64, "5/x.05.png");
    subst("plain", 5, 64, "plain");
    subst("f.####", 7, 7, "f.0007");
    subst("f.####", 7, 6, NULL);
    subst("ab", 1, 2, NULL);
    subst("ab", 1, 3, "ab");
    CHECK(framelist_is_pattern("a#b") && !framelist_is_pattern("ab"), "framelist_is_pattern");
    return check_done();
}
