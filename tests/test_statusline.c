/* test_statusline.c -- the live progress line: it fits every terminal
 * width (never more than cols - 1 characters), keeps its parts in order of
 * importance, counts the hosts it leaves out, and formats durations; an
 * animation's line starts with its frames and its ETA covers them. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "statusline.h"

int main(void)
{
    char d[32];
    statusline_duration(0, d, sizeof d);
    CHECK(!strcmp(d, "0s"), "0 s: %s", d);
    statusline_duration(59.4, d, sizeof d);
    CHECK(!strcmp(d, "59s"), "59.4 s: %s", d);
    statusline_duration(65, d, sizeof d);
    CHECK(!strcmp(d, "1:05"), "65 s: %s", d);
    statusline_duration(3600 + 62, d, sizeof d);
    CHECK(!strcmp(d, "1:01:02"), "3662 s: %s", d);
    statusline_duration(-3, d, sizeof d);
    CHECK(!strcmp(d, "0s"), "-3 s: %s", d);

    sched_host hs[5];
    memset(hs, 0, sizeof hs);
    static const char *const names[] = {"alpha", "bravo-long-host-name", "charlie", "delta", "echo"};
    for (int i = 0; i < 5; i++) {
        hs[i].name = names[i];
        hs[i].tr = (tr_host *)&hs[i]; /* any non-NULL: connected */
        hs[i].slots = 8;
        hs[i].running = 8;
        hs[i].rows = 10 * (i + 1);
    }
    hs[3].pending = 1;
    hs[3].tr = NULL;
    hs[4].dropped = 1;
    statusline_figures f = {125.0, 150, 512, 640.0 * 256, 0, 0, 0};

    /* No limit: every part and every host. */
    char full[1024];
    size_t n = statusline_format(full, sizeof full, 0, &f, hs, 5);
    CHECK(n == strlen(full), "length %zu of '%s'", n, full);
    CHECK(!strncmp(full, "rows 150/512 ( 29%)  elapsed 2:05  ETA 5:02  ", 45), "no limit: '%s'", full);
    CHECK(strstr(full, " alpha:8/8 0.1r/s") && strstr(full, " bravo-long-host-name:8/8") &&
              strstr(full, " delta:starting") && strstr(full, " echo:down") && !strstr(full, " +"),
          "no limit, hosts: '%s'", full);
    CHECK(strstr(full, "Msamples/s"), "no rate: '%s'", full);

    /* Every width from 1 to beyond the whole line: it fits, starts as the
     * whole line does, and any host left out is counted. */
    for (int cols = 1; cols <= (int)n + 3; cols++) {
        char line[1024];
        size_t k = statusline_format(line, sizeof line, cols, &f, hs, 5);
        CHECK(k == strlen(line) && k <= (size_t)cols - 1, "cols %d: %zu characters: '%s'", cols, k, line);
        if (cols > 20) {
            const char *plus = strstr(line, " +");
            size_t head = plus ? (size_t)(plus - line) : k;
            CHECK(!strncmp(line, full, head), "cols %d: '%s' is not the start of the whole line", cols, line);
        }
        if (cols > (int)n)
            CHECK(!strcmp(line, full), "cols %d: '%s' is not the whole line", cols, line);
        /* Wide enough for the figures and two hosts: the rest are counted. */
        if (cols >= 100 && cols <= (int)n - 12) {
            const char *plus = strstr(line, " +");
            CHECK(plus && atoi(plus + 2) >= 1 && atoi(plus + 2) <= 4, "cols %d: hosts left out are not counted: '%s'",
                  cols, line);
        }
    }
    /* A tiny cap is respected too. */
    char small[8];
    size_t k = statusline_format(small, sizeof small, 0, &f, hs, 5);
    CHECK(k < sizeof small && strlen(small) == k, "cap 8: '%s'", small);

    /* No ETA before a row is done, nor once every row is. */
    statusline_figures start = {0.5, 0, 512, 1000, 0, 0, 0};
    char line[256];
    statusline_format(line, sizeof line, 0, &start, hs, 1);
    CHECK(!strstr(line, "ETA") && strstr(line, "elapsed 1s"), "start: '%s'", line);
    statusline_figures end = {10, 512, 512, 1000, 0, 0, 0};
    statusline_format(line, sizeof line, 0, &end, hs, 1);
    CHECK(!strstr(line, "ETA") && strstr(line, "(100%)"), "end: '%s'", line);

    /* An animation: the frames first, and an ETA over the rows of the
     * frames not started yet too (362 + 1024 rows at 1.2 rows/s: 1155 s). */
    statusline_figures anim = {125.0, 150, 512, 1000, 3, 8, 1024};
    statusline_format(line, sizeof line, 0, &anim, hs, 1);
    CHECK(!strncmp(line, "frames 3/8 rows 150/512 ( 29%)  elapsed 2:05  ETA 19:15  ", 57), "animation: '%s'", line);
    /* Its rows all done, frames ahead: still an ETA. */
    statusline_figures between = {10, 512, 512, 1000, 4, 8, 512};
    statusline_format(line, sizeof line, 0, &between, hs, 1);
    CHECK(strstr(line, "frames 4/8 rows 512/512 (100%)") && strstr(line, "ETA 10s"), "between frames: '%s'", line);
    for (int cols = 1; cols <= 80; cols++) {
        size_t w = statusline_format(line, sizeof line, cols, &anim, hs, 5);
        CHECK(w <= (size_t)cols - 1 && !strncmp(line, "frames 3/8 rows 150/512", w < 23 ? w : 23),
              "animation, cols %d: '%s'", cols, line);
    }
    return check_done();
}
