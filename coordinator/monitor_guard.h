/** @file monitor_guard.h
 * Who may use the monitor (monitor.h), and for how long: its access token
 * and its connections' deadlines, for the libmicrohttpd server it guards.
 *
 * Token: unless the monitor is open, 16 bytes from getrandom(2) as 32
 * lowercase hex digits; a request is answered only when its `token` query
 * argument equals it (compared in constant time).  The address printed
 * when the monitor starts carries it, so only who can read the render's
 * stderr can watch it (any local user can reach 127.0.0.1).
 *
 * Deadlines: a connection has MG_REQUEST_S seconds to deliver a complete
 * request header (from its opening, or from the end of its previous
 * reply), and MG_REPLY_S seconds to take the reply; past that its socket
 * is shut down by the guard's own thread, however busily the client
 * trickles bytes (libmicrohttpd's own time-out only counts silence).
 * Limits: at most MG_CONNECTIONS connections in all and MG_PER_ADDRESS
 * from one client address; a connection beyond either limit closes the
 * one that has waited longest for its request header (of that address,
 * or of all), or is itself closed when every other is being answered.
 * So slow clients hold no slot for long, and a prompt request always
 * finds one.
 */
#ifndef FRANJA_MONITOR_GUARD_H
#define FRANJA_MONITOR_GUARD_H

#include <microhttpd.h>

#include "error.h"

enum {
    MG_REQUEST_S = 5,      /**< seconds to deliver a request header */
    MG_REPLY_S = 30,       /**< seconds to take a reply */
    MG_CONNECTIONS = 64,   /**< connections kept at once, in all */
    MG_PER_ADDRESS = 48,   /**< ... and from one client address */
    MG_SLOTS = 2 * MG_CONNECTIONS /**< libmicrohttpd's hard limit (closing ones included) */
};

/** A guard: its token and the connections it watches. */
typedef struct mon_guard mon_guard;

/** A new guard with its watching thread; open: no token (every request
 * is let in).  NULL with err set when no random bytes or no thread. */
mon_guard *mg_start(int open, fr_error *err);

/** The token, 32 hex digits (owned by g); NULL when the guard is open. */
const char *mg_token(const mon_guard *g);

/** 1 when a request with this `token` argument (NULL: none) may be
 * answered: the guard is open, or the argument is the token. */
int mg_allowed(const mon_guard *g, const char *token);

/** libmicrohttpd's MHD_OPTION_NOTIFY_CONNECTION callback (cls: the
 * guard): watches each connection from its opening to its closing. */
void mg_connection(void *cls, struct MHD_Connection *c, void **socket_context,
                   enum MHD_ConnectionNotificationCode code);

/** libmicrohttpd's MHD_OPTION_NOTIFY_COMPLETED callback (cls: the guard):
 * a reply is over; the connection's next request header is due in
 * MG_REQUEST_S seconds. */
void mg_completed(void *cls, struct MHD_Connection *c, void **con_cls, enum MHD_RequestTerminationCode toe);

/** Connection c's request header is complete (the access handler's first
 * call for it): its reply is due in MG_REPLY_S seconds. */
void mg_request(mon_guard *g, struct MHD_Connection *c);

/** Stops the watching thread and frees g (NULL: nothing); call it after
 * the server it guards has stopped. */
void mg_stop(mon_guard *g);

#endif
