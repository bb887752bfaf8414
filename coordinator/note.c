/* note.c -- message lines handed to the caller's sink (see note.h). */
#include "note.h"

#include <stdarg.h>
#include <stdio.h>

void note_say(const note_sink *s, const char *fmt, ...)
{
    if (!s || !s->fn)
        return;
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    s->fn(s->ctx, line);
}
