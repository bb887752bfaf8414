/* error.c -- fr_fail, the one way an error message is written into an fr_error
 * (see error.h). */

#include "error.h"

#include <stdarg.h>
#include <stdio.h>

int fr_fail(fr_error *e, const char *fmt, ...)
{
    if (e) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(e->msg, sizeof e->msg, fmt, ap);
        va_end(ap);
    }
    return -1;
}
