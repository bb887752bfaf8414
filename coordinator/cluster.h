/** @file cluster.h
 * Getting every host of a table ready at once: connect, then a step of the
 * caller's (for a render: probe and stage the scene).  Hosts are handled
 * in parallel, one thread each, so one slow or dead host costs one
 * time-out, not one per host.  Remarks of the backends and of the steps
 * (tr_note) are collected per host while the threads run and handed to
 * the caller's sink afterwards, in host order, from the calling thread.
 */
#ifndef FRANJA_CLUSTER_H
#define FRANJA_CLUSTER_H

#include "protocol.h"
#include "transport.h"

/** One host's state. */
typedef struct {
    const hosts_entry *entry;  /**< from the table (not owned); set by the caller */
    tr_host *tr;               /**< NULL if the host could not be made ready */
    proto_host info;           /**< what the host reported (cl_open; valid when tr) */
    char scene[1024];          /**< path of the scene on the host (when staged) */
    int uploaded;              /**< the scene was sent during this run */
    double ready_s;            /**< seconds it took */
    fr_error err;              /**< why the host is not usable (tr == NULL) */
    char notes[2048];          /**< private: remarks collected while the threads run */
    size_t notes_len;          /**< private: bytes used in notes */
    const note_sink *forward;  /**< private: where remarks go once the threads are done */
} cl_host;

/** A step run on host i once it is connected, in the host's own thread; on
 * failure it returns -1 with err set and the host is closed. */
typedef int (*cl_step)(cl_host *h, int i, void *ctx, fr_error *err);

/** Connects hosts[0..n) (entry set by the caller) and runs step (if not
 * NULL) on each.  Each host ends either with tr set or with err explaining
 * why not.  Later remarks of the hosts go straight to o->notes. */
void cl_each(cl_host *hosts, int n, const tr_options *o, cl_step step, void *ctx);

/** cl_each with the render's step: probe (stage_probe) and, if scene is
 * not NULL, stage the scene with content hash `hash` (stage_scene). */
void cl_open(cl_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash);

/** Refuses a set of ready hosts whose workers report different versions,
 * or a scene format other than this build's; the message names the host. */
int cl_check_versions(const cl_host *hosts, int n, fr_error *err);

/** Closes every ready host whose worker's version line is not this
 * build's ("franja-worker VERSION scene-format N"), setting its err to say
 * which version it has and which is needed: a render goes on with the
 * hosts that match (one host left behind by an upgrade, or a broken node
 * of a Slurm allocation, is no reason to stop). */
void cl_drop_other_versions(cl_host *hosts, int n);

/** Closes every host (tr_close). */
void cl_close(cl_host *hosts, int n);

#endif
