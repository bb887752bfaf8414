/* statusline.c -- the live progress line (see statusline.h). */
#include "statusline.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>

void statusline_duration(double s, char *out, size_t cap)
{
    long t = s > 0 ? (long)(s + 0.5) : 0;
    if (t < 60)
        snprintf(out, cap, "%lds", t);
    else if (t < 3600)
        snprintf(out, cap, "%ld:%02ld", t / 60, t % 60);
    else
        snprintf(out, cap, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
}

int statusline_columns(int fd)
{
    struct winsize ws;
    if (ioctl(fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0)
        return ws.ws_col;
    const char *c = getenv("COLUMNS");
    char *end;
    long n = c ? strtol(c, &end, 10) : 0;
    if (c && *c && !*end && n >= 10 && n <= 1000)
        return (int)n;
    return 80;
}

/* Appends part to out (length *len) if the result stays within limit
 * characters and cap; returns 1 if it did. */
static int append(char *out, size_t cap, size_t *len, size_t limit, const char *part)
{
    size_t n = strlen(part);
    if (*len + n > limit || *len + n + 1 > cap)
        return 0;
    memcpy(out + *len, part, n + 1);
    *len += n;
    return 1;
}

size_t statusline_format(char *out, size_t cap, int cols, const statusline_figures *f, const sched_host *hosts, int nhosts)
{
    if (cap == 0)
        return 0;
    size_t limit = cols > 0 ? (size_t)cols - 1 : (size_t)-1;
    double t = f->elapsed_s, rate = t > 0 ? f->done / t : 0;
    char part[400], d[32];
    size_t len = 0;
    out[0] = '\0';
    int k = f->frames > 0 ? snprintf(part, sizeof part, "frames %d/%d ", f->frames_done, f->frames) : 0;
    snprintf(part + k, sizeof part - (size_t)k, "rows %d/%d (%3.0f%%)", f->done, f->total,
             f->total ? 100.0 * f->done / f->total : 100.0);
    if (!append(out, cap, &len, limit, part)) {
        /* Not even that: cut it. */
        size_t n = strlen(part) < limit ? strlen(part) : limit;
        if (n >= cap)
            n = cap - 1;
        memcpy(out, part, n);
        out[n] = '\0';
        return n;
    }
    statusline_duration(t, d, sizeof d);
    snprintf(part, sizeof part, "  elapsed %s", d);
    if (!append(out, cap, &len, limit, part))
        return len;
    double left = f->total - f->done + (f->frames > 0 && f->rows_ahead > 0 ? f->rows_ahead : 0);
    if (rate > 0 && left > 0) {
        statusline_duration(left / rate, d, sizeof d);
        snprintf(part, sizeof part, "  ETA %s", d);
        if (!append(out, cap, &len, limit, part))
            return len;
    }
    snprintf(part, sizeof part, "  %.2f Msamples/s ", rate * f->samples_per_row / 1e6);
    if (!append(out, cap, &len, limit, part))
        return len;
    int shown = 0, listed = 0;
    for (int i = 0; i < nhosts; i++) {
        const sched_host *h = &hosts[i];
        if (!h->tr && h->dropped)
            continue;
        listed++;
        if (shown < listed - 1)
            continue; /* one was left out: the rest go too, in order */
        if (h->pending)
            snprintf(part, sizeof part, " %s:starting", h->name);
        else if (h->dropped)
            snprintf(part, sizeof part, " %s:down", h->name);
        else
            snprintf(part, sizeof part, " %s:%d/%d %.1fr/s", h->name, h->running, h->slots,
                     t > 0 ? h->rows / t : 0.0);
        /* Room is kept for the count of the hosts after this one. */
        char more[32];
        snprintf(more, sizeof more, " +%d", nhosts);
        size_t keep = i + 1 < nhosts ? strlen(more) : 0;
        if (len + strlen(part) + keep <= limit && append(out, cap, &len, limit, part))
            shown++;
    }
    if (shown < listed) {
        snprintf(part, sizeof part, " +%d", listed - shown);
        append(out, cap, &len, limit, part);
    }
    return len;
}
