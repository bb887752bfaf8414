/* error.c -- error messages, formatted and escaped (see error.h). */
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* Length of the control character at p: 1 (C0, DEL), 2 (C1 in UTF-8) or 0. */
static size_t control_at(const unsigned char *p)
{
    if ((*p && *p < 0x20) || *p == 0x7f)
        return 1;
    if (p[0] == 0xc2 && p[1] >= 0x80 && p[1] <= 0x9f)
        return 2;
    return 0;
}

void fr_escape_controls(char *s, size_t cap)
{
    size_t n = strlen(s), extra = 0;
    for (size_t i = 0; i < n; i++) {
        size_t k = control_at((const unsigned char *)s + i);
        if (k) {
            extra += 4 * k - k;
            i += k - 1;
        }
    }
    if (extra == 0 || cap == 0)
        return;
    /* Escape from the end backwards, in place; what does not fit in cap is
     * dropped, starting from the end, before any byte is moved. */
    size_t total = n + extra;
    while (total + 1 > cap) {
        /* drop the last character (an escaped one counts 4 per byte) */
        size_t last = n - 1, k = 1;
        if (n >= 2 && control_at((const unsigned char *)s + n - 2) == 2)
            last = n - 2, k = 2;
        total -= control_at((const unsigned char *)s + last) ? 4 * k : k;
        n = last;
    }
    s[n] = 0;
    size_t w = total;
    s[w] = 0;
    for (size_t i = n; i-- > 0;) {
        unsigned char c = (unsigned char)s[i];
        int esc = control_at((const unsigned char *)s + i) == 1 ||
                  (i > 0 && control_at((const unsigned char *)s + i - 1) == 2) ||
                  control_at((const unsigned char *)s + i) == 2;
        if (esc) {
            static const char hex[] = "0123456789abcdef";
            w -= 4;
            s[w] = '\\', s[w + 1] = 'x', s[w + 2] = hex[c >> 4], s[w + 3] = hex[c & 15];
        } else {
            s[--w] = (char)c;
        }
    }
}

int fr_fail(fr_error *e, const char *fmt, ...)
{
    if (e) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(e->msg, sizeof e->msg, fmt, ap);
        va_end(ap);
        fr_escape_controls(e->msg, sizeof e->msg);
    }
    return -1;
}
