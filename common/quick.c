#include "quick.h"

#include <stdlib.h>

int quick_spp(uint32_t *spp, fr_error *err)
{
    const char *s = getenv(QUICK_ENV);
    if (!s)
        return 0;
    uint32_t cap = 0;
    const char *p = s;
    for (; *p >= '0' && *p <= '9' && cap <= (1u << 20); p++)
        cap = cap * 10 + (uint32_t)(*p - '0');
    if (p == s || *p != '\0' || cap < 1 || cap > (1u << 20))
        return fr_fail(err, "%s='%s': expected an integer in [1, 1048576]", QUICK_ENV, s);
    if (*spp <= cap)
        return 0;
    *spp = cap;
    return 1;
}
