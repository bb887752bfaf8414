/* monitor.c -- the live web page of a render (see monitor.h). */
#include "monitor.h"

#include <arpa/inet.h>
#include <cjson/cJSON.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include "clock.h"
#include "monitor_guard.h"
#include "output.h"
#include "preview.h"

enum { MON_EVENTS = 50, MON_CURRENT = 64 };

typedef struct {
    char name[64];
    char state[200];
    int running, slots, rows, failures;
} host_copy;

typedef struct {
    double t;
    long seq;
    char host[64];
    char kind[24];
    char text[300];
} event_copy;

/* A frame of an animation rendering now. */
typedef struct {
    size_t index;
    uint32_t number;
    char output[256];
    int rows_done, rows;
} frame_copy;

struct mon_server {
    struct MHD_Daemon *daemon;
    mon_guard *guard;          /* the token and the connections' deadlines */
    uint16_t port;
    char url[96];              /* the page's address, with the token */
    char *output;
    pthread_mutex_t lock;      /* everything below */
    char *dir;                 /* the image's job directory; NULL: no image yet */
    job_spec spec;
    fr_tonemap tm;
    /* An animation: NULL states for a single image. */
    char *list;
    char *states;              /* one letter a frame, count of them, terminated */
    size_t count;
    frame_copy cur[MON_CURRENT];
    int ncur;
    long shown;                /* the frame whose image is served; -1: none */
    int last_rows;             /* rows of the frame opened last */
    double t;
    int done, total, before;
    host_copy *hosts;
    int nhosts, cap;
    event_copy ev[MON_EVENTS]; /* a ring: the last MON_EVENTS */
    long nev;                  /* events so far */
    char status[32];
    /* The image so far, encoded (only the server's thread uses these, under lock). */
    unsigned char *png;
    size_t png_len;
    int png_rows;
    double png_at;
    float *rgb;
    unsigned char *have;
};

static void copy_str(char *dst, size_t cap, const char *src)
{
    snprintf(dst, cap, "%s", src ? src : "");
}

void mon_progress(mon_server *m, double t, int rows_done, int rows_total, int rows_before, const mon_host *hosts,
                  int nhosts)
{
    if (!m)
        return;
    pthread_mutex_lock(&m->lock);
    m->t = t;
    m->done = rows_done;
    m->total = rows_total;
    m->before = rows_before;
    if (nhosts > m->cap) {
        host_copy *h = realloc(m->hosts, (size_t)nhosts * sizeof *h);
        if (h) {
            m->hosts = h;
            m->cap = nhosts;
        }
    }
    m->nhosts = nhosts < m->cap ? nhosts : m->cap;
    for (int i = 0; i < m->nhosts; i++) {
        host_copy *c = &m->hosts[i];
        copy_str(c->name, sizeof c->name, hosts[i].name);
        copy_str(c->state, sizeof c->state, hosts[i].state);
        c->running = hosts[i].running;
        c->slots = hosts[i].slots;
        c->rows = hosts[i].rows;
        c->failures = hosts[i].failures;
    }
    pthread_mutex_unlock(&m->lock);
}

void mon_event(mon_server *m, double t, const char *host, const char *kind, const char *text)
{
    if (!m)
        return;
    pthread_mutex_lock(&m->lock);
    event_copy *e = &m->ev[m->nev % MON_EVENTS];
    e->t = t;
    e->seq = m->nev++;
    copy_str(e->host, sizeof e->host, host);
    copy_str(e->kind, sizeof e->kind, kind);
    copy_str(e->text, sizeof e->text, text);
    pthread_mutex_unlock(&m->lock);
}

void mon_status(mon_server *m, const char *status)
{
    if (!m)
        return;
    pthread_mutex_lock(&m->lock);
    copy_str(m->status, sizeof m->status, status);
    pthread_mutex_unlock(&m->lock);
}


const char *mon_url(const mon_server *m) { return m->url; }

void mon_frame(mon_server *m, size_t index, uint32_t number, char state, const char *output, int rows_done,
               int rows)
{
    if (!m || !m->states || index >= m->count)
        return;
    pthread_mutex_lock(&m->lock);
    m->states[index] = state;
    int k = 0;
    while (k < m->ncur && m->cur[k].index != index)
        k++;
    if (state == 'r') {
        if (k == m->ncur && m->ncur < MON_CURRENT)
            m->ncur++;
        if (k < m->ncur) {
            frame_copy *c = &m->cur[k];
            c->index = index;
            c->number = number;
            copy_str(c->output, sizeof c->output, output);
            c->rows_done = rows_done;
            c->rows = rows;
            m->last_rows = rows;
        }
    } else if (k < m->ncur) {
        memmove(&m->cur[k], &m->cur[k + 1], (size_t)(m->ncur - k - 1) * sizeof *m->cur);
        m->ncur--;
    }
    pthread_mutex_unlock(&m->lock);
}

int mon_show(mon_server *m, uint32_t number, const char *dir, const job_spec *spec, const fr_tonemap *tm,
             fr_error *err)
{
    if (!m)
        return 0;
    char *d = strdup(dir);
    float *rgb = malloc((size_t)spec->width * spec->height * 3 * sizeof *rgb);
    unsigned char *have = malloc(spec->height);
    if (!d || !rgb || !have) {
        free(d);
        free(rgb);
        free(have);
        return fr_fail(err, "out of memory for a %ux%u monitor image", spec->width, spec->height);
    }
    pthread_mutex_lock(&m->lock);
    free(m->dir);
    free(m->rgb);
    free(m->have);
    m->dir = d;
    m->rgb = rgb;
    m->have = have;
    m->spec = *spec;
    m->tm = *tm;
    m->shown = number;
    m->png_rows = -1; /* the next request reads the new frame's rows */
    m->png_at = 0;
    pthread_mutex_unlock(&m->lock);
    return 0;
}

/* An animation's part of state.json, and its ETA, under lock. */
static void frames_json(const mon_server *m, cJSON *o, double rate)
{
    cJSON *f = cJSON_AddObjectToObject(o, "frames");
    if (!f)
        return;
    cJSON_AddStringToObject(f, "list", m->list);
    cJSON_AddNumberToObject(f, "count", (double)m->count);
    cJSON_AddStringToObject(f, "states", m->states);
    static const char letters[] = "wrdsfx";
    static const char *const names[] = {"waiting", "rendering", "done", "skipped", "failed", "stopped"};
    size_t n[6] = {0};
    for (size_t i = 0; i < m->count; i++) {
        const char *at = strchr(letters, m->states[i]);
        if (at)
            n[at - letters]++;
    }
    for (int k = 0; k < 6; k++)
        cJSON_AddNumberToObject(f, names[k], (double)n[k]);
    cJSON *cur = cJSON_AddArrayToObject(f, "current");
    double left = (double)n[0] * m->last_rows;
    for (int i = 0; cur && i < m->ncur; i++) {
        const frame_copy *c = &m->cur[i];
        cJSON *j = cJSON_CreateObject();
        if (!j)
            break;
        cJSON_AddNumberToObject(j, "frame", c->number);
        cJSON_AddStringToObject(j, "output", c->output);
        cJSON_AddNumberToObject(j, "rows_done", c->rows_done);
        cJSON_AddNumberToObject(j, "rows", c->rows);
        cJSON_AddItemToArray(cur, j);
        left += c->rows > c->rows_done ? c->rows - c->rows_done : 0;
    }
    if (m->shown >= 0)
        cJSON_AddNumberToObject(f, "shown", (double)m->shown);
    else
        cJSON_AddNullToObject(f, "shown");
    cJSON_DeleteItemFromObject(o, "eta_s");
    if (left <= 0 && n[0] == 0 && n[1] == 0)
        cJSON_AddNumberToObject(o, "eta_s", 0);
    else if (rate > 0)
        cJSON_AddNumberToObject(o, "eta_s", left / rate);
    else
        cJSON_AddNullToObject(o, "eta_s");
}

/* /state.json, under lock.  NULL when out of memory. */
static char *state_json(mon_server *m)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    double rate = m->t > 0 ? (m->done - m->before) / m->t : 0;
    cJSON_AddStringToObject(o, "output", m->output);
    cJSON_AddStringToObject(o, "status", m->status);
    cJSON_AddNumberToObject(o, "width", m->spec.width);
    cJSON_AddNumberToObject(o, "height", m->spec.height);
    cJSON_AddNumberToObject(o, "spp", m->spec.spp);
    cJSON_AddNumberToObject(o, "rows_done", m->done);
    cJSON_AddNumberToObject(o, "rows", m->total ? m->total : (int)m->spec.height);
    cJSON_AddNumberToObject(o, "elapsed_s", m->t);
    cJSON_AddNumberToObject(o, "rows_per_s", rate);
    if (rate > 0 && m->done < m->total)
        cJSON_AddNumberToObject(o, "eta_s", (m->total - m->done) / rate);
    else if (m->total && m->done >= m->total)
        cJSON_AddNumberToObject(o, "eta_s", 0);
    else
        cJSON_AddNullToObject(o, "eta_s");
    cJSON *hs = cJSON_AddArrayToObject(o, "hosts");
    for (int i = 0; hs && i < m->nhosts; i++) {
        const host_copy *h = &m->hosts[i];
        cJSON *j = cJSON_CreateObject();
        if (!j)
            break;
        cJSON_AddStringToObject(j, "name", h->name);
        cJSON_AddStringToObject(j, "state", h->state);
        cJSON_AddNumberToObject(j, "running", h->running);
        cJSON_AddNumberToObject(j, "slots", h->slots);
        cJSON_AddNumberToObject(j, "rows", h->rows);
        cJSON_AddNumberToObject(j, "rows_per_s", m->t > 0 ? h->rows / m->t : 0);
        cJSON_AddNumberToObject(j, "failures", h->failures);
        cJSON_AddItemToArray(hs, j);
    }
    cJSON_AddNumberToObject(o, "events_total", (double)m->nev);
    cJSON *es = cJSON_AddArrayToObject(o, "events");
    long first = m->nev > MON_EVENTS ? m->nev - MON_EVENTS : 0;
    for (long k = first; es && k < m->nev; k++) {
        const event_copy *e = &m->ev[k % MON_EVENTS];
        cJSON *j = cJSON_CreateObject();
        if (!j)
            break;
        cJSON_AddNumberToObject(j, "t", e->t);
        cJSON_AddStringToObject(j, "host", e->host);
        cJSON_AddStringToObject(j, "kind", e->kind);
        cJSON_AddStringToObject(j, "text", e->text);
        cJSON_AddItemToArray(es, j);
    }
    if (m->states)
        frames_json(m, o, rate);
    char *s = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    return s;
}

/* Brings the encoded image up to date (at most once a second, and only
 * when the job directory's rows changed), under lock. */
static void refresh_image(mon_server *m)
{
    if (!m->dir)
        return;
    int rows = job_rows_present(m->dir);
    double now = clock_now();
    if (m->png && (rows == m->png_rows || now - m->png_at < 1.0))
        return;
    fr_error err;
    if (preview_image(m->dir, &m->spec, m->rgb, m->have, NULL, &err) < 0)
        return; /* the last image stays */
    unsigned char *data = NULL;
    size_t len = 0;
    if (out_encode("monitor.png", m->rgb, &m->spec, &m->tm, &data, &len, &err))
        return;
    free(m->png);
    m->png = data;
    m->png_len = len;
    m->png_rows = rows;
    m->png_at = now;
}

/* The Host header names this machine: localhost, 127.0.0.1 or [::1], any port. */
static int local_host_header(const char *h)
{
    if (!h)
        return 0;
    static const char *const names[] = {"localhost", "127.0.0.1", "[::1]"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        size_t n = strlen(names[i]);
        if (!strncasecmp(h, names[i], n) && (h[n] == '\0' || h[n] == ':'))
            return 1;
    }
    return 0;
}

static enum MHD_Result reply(struct MHD_Connection *c, unsigned code, const char *type, const void *data,
                             size_t len)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, (void *)data, MHD_RESPMEM_MUST_COPY);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
    MHD_add_response_header(r, "Content-Security-Policy",
                            "default-src 'self'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                            "img-src 'self' blob:");
    enum MHD_Result rc = MHD_queue_response(c, code, r);
    MHD_destroy_response(r);
    return rc;
}

static enum MHD_Result text_reply(struct MHD_Connection *c, unsigned code, const char *text)
{
    return reply(c, code, "text/plain; charset=utf-8", text, strlen(text));
}

static enum MHD_Result handle(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                              const char *version, const char *upload, size_t *upload_len, void **con_cls)
{
    (void)version;
    (void)upload;
    (void)con_cls;
    mon_server *m = cls;
    mg_request(m->guard, c); /* its header is in: the reply's deadline from now */
    if (strcmp(method, "GET") && strcmp(method, "HEAD"))
        return text_reply(c, MHD_HTTP_METHOD_NOT_ALLOWED, "only GET and HEAD\n");
    if (*upload_len)
        return text_reply(c, MHD_HTTP_BAD_REQUEST, "no request body expected\n");
    if (!local_host_header(MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host")))
        return text_reply(c, MHD_HTTP_FORBIDDEN, "the monitor answers requests for localhost only\n");
    if (!mg_allowed(m->guard, MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "token")))
        return text_reply(c, MHD_HTTP_FORBIDDEN,
                          "this monitor needs its token: open the address franja printed when it started\n");
    if (!strcmp(url, "/") || !strcmp(url, "/index.html"))
        return reply(c, MHD_HTTP_OK, "text/html; charset=utf-8", mon_page_html, strlen(mon_page_html));
    if (!strcmp(url, "/state.json")) {
        pthread_mutex_lock(&m->lock);
        char *s = state_json(m);
        pthread_mutex_unlock(&m->lock);
        if (!s)
            return text_reply(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory\n");
        enum MHD_Result rc = reply(c, MHD_HTTP_OK, "application/json", s, strlen(s));
        free(s);
        return rc;
    }
    if (!strcmp(url, "/image.png")) {
        pthread_mutex_lock(&m->lock);
        refresh_image(m);
        enum MHD_Result rc = m->png ? reply(c, MHD_HTTP_OK, "image/png", m->png, m->png_len)
                                    : text_reply(c, MHD_HTTP_SERVICE_UNAVAILABLE, "no image yet\n");
        pthread_mutex_unlock(&m->lock);
        return rc;
    }
    return text_reply(c, MHD_HTTP_NOT_FOUND, "not found\n");
}

static void release(mon_server *m)
{
    free(m->output);
    free(m->list);
    free(m->states);
    free(m->dir);
    free(m->hosts);
    free(m->png);
    free(m->rgb);
    free(m->have);
    free(m);
}

/* A server for output, no image yet (mon_show gives it one). */
static mon_server *start(uint16_t port, int open, const char *output, fr_error *err)
{
    mon_server *m = calloc(1, sizeof *m);
    if (!m || !(m->output = strdup(output))) {
        free(m);
        fr_fail(err, "out of memory");
        return NULL;
    }
    if (!(m->guard = mg_start(open, err))) {
        release(m);
        return NULL;
    }
    m->shown = -1;
    copy_str(m->status, sizeof m->status, "starting");
    /* The listening socket is made here, so that a port in use is said as such. */
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_in sa;
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port);
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    int one = 1;
    socklen_t sl = sizeof sa;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) ||
        bind(fd, (struct sockaddr *)&sa, sizeof sa) || listen(fd, MG_CONNECTIONS) ||
        getsockname(fd, (struct sockaddr *)&sa, &sl)) {
        fr_fail(err, "cannot listen on 127.0.0.1:%u: %s", port, strerror(errno));
        if (fd >= 0)
            close(fd);
        mg_stop(m->guard);
        release(m);
        return NULL;
    }
    m->port = ntohs(sa.sin_port);
    const char *token = mg_token(m->guard);
    snprintf(m->url, sizeof m->url, "http://127.0.0.1:%u/%s%s", m->port, token ? "?token=" : "", token ? token : "");
    pthread_mutex_init(&m->lock, NULL);
    /* One thread polls every connection (epoll where there is one), so a
     * slow client delays no other; the guard cuts those past their
     * deadline and keeps the connections within its limits, and
     * MG_SLOTS is only the hard limit behind it. */
    m->daemon = MHD_start_daemon(MHD_USE_AUTO_INTERNAL_THREAD, 0, NULL, NULL, handle, m, MHD_OPTION_LISTEN_SOCKET, fd,
                                 MHD_OPTION_CONNECTION_LIMIT, (unsigned)MG_SLOTS, MHD_OPTION_CONNECTION_TIMEOUT,
                                 (unsigned)MG_REQUEST_S, MHD_OPTION_NOTIFY_CONNECTION, mg_connection, m->guard,
                                 MHD_OPTION_NOTIFY_COMPLETED, mg_completed, m->guard, MHD_OPTION_END);
    if (!m->daemon) {
        close(fd);
        pthread_mutex_destroy(&m->lock);
        mg_stop(m->guard);
        release(m);
        fr_fail(err, "cannot start the web server on 127.0.0.1:%u", port);
        return NULL;
    }
    return m;
}

mon_server *mon_start(uint16_t port, int open, const char *output, const char *dir, const job_spec *spec,
                      const fr_tonemap *tm, fr_error *err)
{
    mon_server *m = start(port, open, output, err);
    if (m && mon_show(m, 0, dir, spec, tm, err)) {
        mon_stop(m);
        return NULL;
    }
    if (m) {
        pthread_mutex_lock(&m->lock);
        m->shown = -1; /* a single image: no frame */
        m->total = (int)spec->height;
        pthread_mutex_unlock(&m->lock);
    }
    return m;
}

mon_server *mon_start_frames(uint16_t port, int open, const char *output, const char *list, size_t n, fr_error *err)
{
    char *states = malloc(n + 1), *l = strdup(list);
    if (!states || !l) {
        free(states);
        free(l);
        fr_fail(err, "out of memory");
        return NULL;
    }
    memset(states, 'w', n);
    states[n] = '\0';
    mon_server *m = start(port, open, output, err);
    if (!m) {
        free(states);
        free(l);
        return NULL;
    }
    pthread_mutex_lock(&m->lock);
    m->states = states;
    m->list = l;
    m->count = n;
    pthread_mutex_unlock(&m->lock);
    return m;
}

void mon_stop(mon_server *m)
{
    if (!m)
        return;
    MHD_stop_daemon(m->daemon); /* closes the listening socket */
    mg_stop(m->guard);
    pthread_mutex_destroy(&m->lock);
    release(m);
}
