/* quick.c -- FRANJA_MAX_SPP read from the environment as a cap on samples per
 * pixel (see quick.h). */

#include "quick.h"

#include <stdlib.h>

#include "proto_limits.h"

int quick_spp(uint32_t *spp, fr_error *err)
{
    const char *s = getenv(QUICK_ENV);
    if (!s)
        return 0;
    uint32_t cap = 0;
    const char *p = s;
    for (; *p >= '0' && *p <= '9' && cap <= PROTO_MAX_SPP; p++)
        cap = cap * 10 + (uint32_t)(*p - '0');
    if (p == s || *p != '\0' || cap < 1 || cap > PROTO_MAX_SPP)
        return fr_fail(err, "%s='%s': expected an integer in [1, %u]", QUICK_ENV, s, PROTO_MAX_SPP);
    if (*spp <= cap)
        return 0;
    *spp = cap;
    return 1;
}
