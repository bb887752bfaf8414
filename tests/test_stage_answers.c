/* test_stage_answers.c -- the coordinator's reading of hosts' answers to cache
 * commands.
 *
 * What the coordinator reads from a host's answers to its cache commands
 * (stage.h): the scenes the cache trimming removed ("NAME BYTES" lines),
 * the cache listing (a size a line), what the cleaning did ("REMOVED
 * BYTES IN_USE TEMP") and the codename of os-release.  Each
 * reads only the bytes the host sent (an answer is not NUL-terminated:
 * what lies after it in memory must change nothing), refuses a line of
 * another shape naming it, saturates sums instead of wrapping, and
 * leaves no control character of the host's text in what is shown. */
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "transport/stage.h"

static void evicted(void)
{
    int n;
    uint64_t bytes;
    fr_error err;
    const char two[] = "0a1b.fbin 1200\n9f8e.fbin 34\n";
    CHECK(stage_parse_evicted(two, strlen(two), &n, &bytes, &err) == 0 && n == 2 && bytes == 1234,
          "two scenes removed: %d, %llu bytes", n, (unsigned long long)bytes);
    CHECK(stage_parse_evicted(NULL, 0, &n, &bytes, &err) == 0 && n == 0 && bytes == 0, "nothing removed: %d", n);
    /* The answer is the first 13 bytes: "0a1b.fbin 120"; the digits after
     * it in memory are not the host's. */
    CHECK(stage_parse_evicted(two, 13, &n, &bytes, &err) == 0 && n == 1 && bytes == 120,
          "an answer cut after '120' read as %d scenes, %llu bytes", n, (unsigned long long)bytes);
    const char bad[] = "a.fbin 5\nnonsense\n";
    CHECK(stage_parse_evicted(bad, strlen(bad), &n, &bytes, &err) == -1 && strstr(err.msg, "line 2"),
          "a line without a size: %s", err.msg);
    const char neg[] = "a.fbin -5\n";
    CHECK(stage_parse_evicted(neg, strlen(neg), &n, &bytes, &err) == -1, "a negative size was taken");
    const char huge[] = "a.fbin 99999999999999999999999\nb.fbin 18446744073709551615\n";
    CHECK(stage_parse_evicted(huge, strlen(huge), &n, &bytes, &err) == 0 && bytes == UINT64_MAX,
          "sizes past 2^64 sum to %llu", (unsigned long long)bytes);
}

static void cache(void)
{
    int n;
    uint64_t bytes;
    fr_error err;
    const char list[] = "  1048576\n512\n\t77 \n";
    CHECK(stage_parse_cache(list, strlen(list), &n, &bytes, &err) == 0 && n == 3 && bytes == 1048576 + 512 + 77,
          "three scenes: %d, %llu bytes", n, (unsigned long long)bytes);
    CHECK(stage_parse_cache(list, 6, &n, &bytes, &err) == 0 && n == 1 && bytes == 1048,
          "an answer cut after '1048' read as %llu bytes", (unsigned long long)bytes);
    const char bad[] = "12\n\n3\n";
    CHECK(stage_parse_cache(bad, strlen(bad), &n, &bytes, &err) == -1 && strstr(err.msg, "line 2"),
          "an empty line: %s", err.msg);
    const char two[] = "1 2\n";
    CHECK(stage_parse_cache(two, strlen(two), &n, &bytes, &err) == -1, "two numbers on a line were taken");
}

static void cleaned(void)
{
    stage_cleaned c;
    fr_error err;
    const char ok[] = "3 4096 1 2\n";
    CHECK(stage_parse_cleaned(ok, strlen(ok), &c, &err) == 0 && c.removed == 3 && c.bytes == 4096 && c.in_use == 1 &&
              c.temp == 2, "3 4096 1 2: %d %llu %d %d", c.removed, (unsigned long long)c.bytes, c.in_use, c.temp);
    /* A count past int, which sscanf's %d could not hold. */
    const char big[] = "99999999999 1 0 0";
    CHECK(stage_parse_cleaned(big, strlen(big), &c, &err) == 0 && c.removed == 2147483647,
          "a count past int: %d", c.removed);
    CHECK(stage_parse_cleaned(ok, 7, &c, &err) == -1, "an answer cut after '3 4096 ' was taken");
    const char *bad[] = {"", "\n", "3 4096 1", "3 4096 1 2 5", "3 -1 1 2", "3  4096 1 2", "3 4096 1 2x", "a b c d"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        CHECK(stage_parse_cleaned(bad[i], strlen(bad[i]), &c, &err) == -1 && strstr(err.msg, "REMOVED BYTES"),
              "'%s' was taken", bad[i]);
}

static void codename(void)
{
    char os[64];
    stage_os_codename("NAME=x\nVERSION_CODENAME=\"bookworm\"\n", os);
    CHECK(!strcmp(os, "bookworm"), "quoted codename: '%s'", os);
    stage_os_codename("VERSION_CODENAME=bull\x1b[2Jseye\r\n", os);
    CHECK(!strcmp(os, "bull?[2Jseye?"), "control characters kept: '%s'", os);
    stage_os_codename("ID=debian\n", os);
    CHECK(os[0] == 0, "no codename: '%s'", os);
}

int main(void)
{
    evicted();
    cache();
    cleaned();
    codename();
    return check_done();
}
