/* test_quick.c -- FRANJA_MAX_SPP caps the samples per pixel, or changes
 * nothing.
 *
 * FRANJA_MAX_SPP (common/quick.c): unset changes nothing; set, it caps the
 * samples per pixel and says so; a bad value is an error naming it. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "quick.h"

static int run(const char *value, uint32_t *spp, fr_error *err)
{
    if (value)
        setenv(QUICK_ENV, value, 1);
    else
        unsetenv(QUICK_ENV);
    err->msg[0] = '\0';
    return quick_spp(spp, err);
}

int main(void)
{
    fr_error err;
    uint32_t spp = 64;
    CHECK(run(NULL, &spp, &err) == 0 && spp == 64, "unset: %u", spp);
    CHECK(run("4", &spp, &err) == 1 && spp == 4, "4 over 64: %u", spp);
    spp = 2;
    CHECK(run("4", &spp, &err) == 0 && spp == 2, "4 over 2: %u", spp);
    spp = 1048576;
    CHECK(run("1048576", &spp, &err) == 0 && spp == 1048576, "at the limit: %u", spp);
    static const char *bad[] = {"", "0", "-1", "4x", " 4", "1048577", "99999999999999999999"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        spp = 64;
        int rc = run(bad[i], &spp, &err);
        CHECK(rc == -1 && spp == 64 && strstr(err.msg, QUICK_ENV), "'%s': rc %d, spp %u, '%s'", bad[i], rc, spp,
              err.msg);
    }
    return check_done();
}
