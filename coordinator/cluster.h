/** @file cluster.h
 * Getting every host of a table ready at once: connect, ask what it is,
 * and (for a render) put the scene there.  Hosts are handled in parallel,
 * one thread each, so one slow or dead host costs one time-out, not one
 * per host.
 */
#ifndef FRANJA_CLUSTER_H
#define FRANJA_CLUSTER_H

#include "transport.h"

/** One host's state after cl_open. */
typedef struct {
    const hosts_entry *entry;  /**< from the table (not owned) */
    tr_host *tr;               /**< NULL if the host could not be made ready */
    tr_info info;              /**< what the host reported (valid when tr) */
    char scene[1024];          /**< path of the scene on the host (when staged) */
    int uploaded;              /**< the scene was sent during this run */
    double ready_s;            /**< seconds it took */
    fr_error err;              /**< why the host is not usable (tr == NULL) */
} cl_host;

/** Prepares hosts[0..n) (entry set by the caller): connect, probe and, if
 * scene is not NULL, stage the scene with content hash `hash`.  Each host
 * ends either with tr set or with err explaining why not. */
void cl_open(cl_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash);

/** Refuses a set of ready hosts whose workers report different versions,
 * or a scene format other than this build's; the message names the host. */
int cl_check_versions(const cl_host *hosts, int n, fr_error *err);

/** Closes every host (tr_close). */
void cl_close(cl_host *hosts, int n);

#endif
