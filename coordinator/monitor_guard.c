/* monitor_guard.c -- the monitor's token and its connections' deadlines
 * (see monitor_guard.h). */
#include "monitor_guard.h"

#include <errno.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <time.h>

#include "clock.h"

enum { TOKEN_BYTES = 16, TICK_MS = 200 };

/* A connection watched: live from its opening to its closing. */
typedef struct {
    struct MHD_Connection *c; /* NULL: a free slot */
    int fd;
    unsigned char addr[16];   /* the client's address (IPv4: its 4 bytes, zero padded) */
    int waiting;              /* waiting for a request header (not being answered) */
    int closing;              /* shut down by the guard; no longer counted */
    double since;             /* when the wait (or the reply) began */
    double deadline;
} watched;

struct mon_guard {
    int open;
    char token[2 * TOKEN_BYTES + 1];
    pthread_mutex_t lock;     /* everything below */
    pthread_cond_t wake;
    int stop;
    watched w[MG_SLOTS];
    pthread_t thread;
};

const char *mg_token(const mon_guard *g) { return g->open ? NULL : g->token; }

int mg_allowed(const mon_guard *g, const char *token)
{
    if (g->open)
        return 1;
    if (!token)
        return 0;
    /* As long as the token whatever the argument, and no early exit. */
    size_t n = strnlen(token, 2 * TOKEN_BYTES + 1);
    unsigned diff = n != 2 * TOKEN_BYTES;
    for (size_t i = 0; i < 2 * TOKEN_BYTES; i++)
        diff |= (unsigned char)g->token[i] ^ (unsigned char)(i < n ? token[i] : 0);
    return diff == 0;
}

static watched *find(mon_guard *g, const struct MHD_Connection *c)
{
    for (int i = 0; i < MG_SLOTS; i++)
        if (g->w[i].c == c)
            return &g->w[i];
    return NULL;
}

/* Shuts w's socket down: libmicrohttpd sees the end of the stream and
 * closes the connection.  Under lock, so the descriptor is still w's
 * (libmicrohttpd closes it only after telling mg_connection). */
static void cut(watched *w)
{
    shutdown(w->fd, SHUT_RDWR);
    w->closing = 1;
}

/* The connection that has waited longest for its request header, other
 * than self, from address addr (NULL: any); NULL when there is none. */
static watched *oldest_waiting(mon_guard *g, const watched *self, const unsigned char *addr)
{
    watched *best = NULL;
    for (int i = 0; i < MG_SLOTS; i++) {
        watched *w = &g->w[i];
        if (!w->c || w == self || w->closing || !w->waiting || (addr && memcmp(w->addr, addr, sizeof w->addr)))
            continue;
        if (!best || w->since < best->since)
            best = w;
    }
    return best;
}

/* A new connection in w: makes room for it within the limits. */
static void admit(mon_guard *g, watched *w)
{
    int all = 0, same = 0;
    for (int i = 0; i < MG_SLOTS; i++) {
        const watched *o = &g->w[i];
        if (o->c && !o->closing) {
            all++;
            same += !memcmp(o->addr, w->addr, sizeof w->addr);
        }
    }
    watched *out = NULL;
    if (same > MG_PER_ADDRESS)
        out = oldest_waiting(g, w, w->addr);
    else if (all > MG_CONNECTIONS)
        out = oldest_waiting(g, w, NULL);
    else
        return;
    cut(out ? out : w);
}

static void client_address(struct MHD_Connection *c, unsigned char addr[16])
{
    memset(addr, 0, 16);
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    const struct sockaddr *sa = ci ? ci->client_addr : NULL;
    if (sa && sa->sa_family == AF_INET)
        memcpy(addr, &((const struct sockaddr_in *)(const void *)sa)->sin_addr, 4);
    else if (sa && sa->sa_family == AF_INET6)
        memcpy(addr, &((const struct sockaddr_in6 *)(const void *)sa)->sin6_addr, 16);
}

void mg_connection(void *cls, struct MHD_Connection *c, void **socket_context,
                   enum MHD_ConnectionNotificationCode code)
{
    (void)socket_context;
    mon_guard *g = cls;
    if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
        pthread_mutex_lock(&g->lock);
        watched *w = find(g, c);
        if (w)
            memset(w, 0, sizeof *w);
        pthread_mutex_unlock(&g->lock);
        return;
    }
    if (code != MHD_CONNECTION_NOTIFY_STARTED)
        return;
    const union MHD_ConnectionInfo *fi = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (!fi)
        return;
    unsigned char addr[16];
    client_address(c, addr);
    double now = clock_now();
    pthread_mutex_lock(&g->lock);
    watched *w = find(g, NULL);
    if (!w) {
        shutdown(fi->connect_fd, SHUT_RDWR); /* no slot to watch it in */
    } else {
        *w = (watched){.c = c, .fd = fi->connect_fd, .waiting = 1, .since = now, .deadline = now + MG_REQUEST_S};
        memcpy(w->addr, addr, sizeof addr);
        admit(g, w);
    }
    pthread_mutex_unlock(&g->lock);
}

void mg_request(mon_guard *g, struct MHD_Connection *c)
{
    double now = clock_now();
    pthread_mutex_lock(&g->lock);
    watched *w = find(g, c);
    if (w && w->waiting) {
        w->waiting = 0;
        w->since = now;
        w->deadline = now + MG_REPLY_S;
    }
    pthread_mutex_unlock(&g->lock);
}

void mg_completed(void *cls, struct MHD_Connection *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)con_cls;
    (void)toe;
    mon_guard *g = cls;
    double now = clock_now();
    pthread_mutex_lock(&g->lock);
    watched *w = find(g, c);
    if (w) {
        w->waiting = 1;
        w->since = now;
        w->deadline = now + MG_REQUEST_S;
    }
    pthread_mutex_unlock(&g->lock);
}

/* The watching thread: every TICK_MS, cuts the connections past their deadline. */
static void *watch(void *arg)
{
    mon_guard *g = arg;
    pthread_mutex_lock(&g->lock);
    while (!g->stop) {
        double now = clock_now();
        for (int i = 0; i < MG_SLOTS; i++) {
            watched *w = &g->w[i];
            if (w->c && !w->closing && now >= w->deadline)
                cut(w);
        }
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        ts.tv_nsec += TICK_MS * 1000000L;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&g->wake, &g->lock, &ts);
    }
    pthread_mutex_unlock(&g->lock);
    return NULL;
}

static void hex(const unsigned char *b, size_t n, char *out)
{
    static const char digits[] = "0123456789abcdef";
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = digits[b[i] >> 4];
        out[2 * i + 1] = digits[b[i] & 15];
    }
    out[2 * n] = '\0';
}

mon_guard *mg_start(int open, fr_error *err)
{
    mon_guard *g = calloc(1, sizeof *g);
    if (!g) {
        fr_fail(err, "out of memory");
        return NULL;
    }
    g->open = open;
    if (!open) {
        unsigned char b[TOKEN_BYTES];
        size_t got = 0;
        while (got < sizeof b) {
            ssize_t r = getrandom(b + got, sizeof b - got, 0);
            if (r < 0 && errno == EINTR)
                continue;
            if (r <= 0) {
                fr_fail(err, "no random bytes for the access token: %s", strerror(errno));
                free(g);
                return NULL;
            }
            got += (size_t)r;
        }
        hex(b, sizeof b, g->token);
    }
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_mutex_init(&g->lock, NULL);
    pthread_cond_init(&g->wake, &ca);
    pthread_condattr_destroy(&ca);
    int rc = pthread_create(&g->thread, NULL, watch, g);
    if (rc) {
        pthread_cond_destroy(&g->wake);
        pthread_mutex_destroy(&g->lock);
        free(g);
        fr_fail(err, "cannot start the monitor's watching thread: %s", strerror(rc));
        return NULL;
    }
    return g;
}

void mg_stop(mon_guard *g)
{
    if (!g)
        return;
    pthread_mutex_lock(&g->lock);
    g->stop = 1;
    pthread_cond_signal(&g->wake);
    pthread_mutex_unlock(&g->lock);
    pthread_join(g->thread, NULL);
    pthread_cond_destroy(&g->wake);
    pthread_mutex_destroy(&g->lock);
    free(g);
}
