/* check.h -- the few lines every Franja test program shares.
 *
 * CHECK(cond, fmt, ...) counts a pass or prints one line per failure;
 * check_done() prints the closing "N passed, N failed" line and returns the
 * exit status. */
#ifndef FRANJA_CHECK_H
#define FRANJA_CHECK_H

#include <stdio.h>

static int check_passed, check_failed;

#define CHECK(cond, ...)                                                       \
    do {                                                                       \
        if (cond) {                                                            \
            check_passed++;                                                    \
        } else {                                                               \
            check_failed++;                                                    \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                        \
            printf(__VA_ARGS__);                                               \
            printf("\n");                                                      \
        }                                                                      \
    } while (0)

static inline int check_done(void)
{
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed ? 1 : 0;
}

#endif
