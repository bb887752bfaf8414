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
#include "transport/stage.h"
#include "transport/transport.h"

/** One host's state. */
typedef struct {
    const hosts_entry *entry;  /**< from the table (not owned); set by the caller */
    tr_host *tr;               /**< NULL if the host could not be made ready */
    proto_host info;           /**< what the host reported (cluster_open; valid when tr) */
    char scene[1024];          /**< path of the scene on the host (when staged) */
    char lease[1200];          /**< the render's lease on it (stage_scene), "" if none; remove it at the end */
    uint64_t sent;             /**< bytes of the scene sent during this run (0: it was cached) */
    double ready_s;            /**< seconds it took */
    fr_error err;              /**< why the host is not usable (tr == NULL) */
    char notes[2048];          /**< private: remarks collected while the threads run */
    size_t notes_len;          /**< private: bytes used in notes */
    const note_sink *forward;  /**< private: where remarks go once the threads are done */
} cluster_host;

/** A step run on host i once it is connected, in the host's own thread; on
 * failure it returns -1 with err set and the host is closed. */
typedef int (*cluster_step)(cluster_host *h, int i, void *ctx, fr_error *err);

/** Connects hosts[0..n) (entry set by the caller) and runs step (if not
 * NULL) on each.  Each host ends either with tr set or with err explaining
 * why not.  Later remarks of the hosts go straight to o->notes. */
void cluster_each(cluster_host *hosts, int n, const tr_options *o, cluster_step step, void *ctx);

/** cluster_each with the render's step: probe (stage_probe) and, if scene is
 * not NULL, stage the scene with content hash `hash` (stage_scene). */
void cluster_open(cluster_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash);

/** The render's step after the probe, for one more scene on a ready host
 * (the frames of an animation): stage_scene (patch, remote, lease, *sent
 * as it says), then the host's scene cache trimmed to its limit (stage_evict;
 * what went, or why it could not, is a remark of the host).  -1 with err
 * when the scene cannot be staged. */
int cluster_stage(tr_host *tr, const hosts_entry *entry, const char *scene, uint64_t hash, const stage_patch *patch,
                  char *remote, size_t cap, char *lease, size_t lease_cap, uint64_t *sent, fr_error *err);

/** Hosts being made ready in the background (cluster_start). */
typedef struct cluster_group cluster_group;

/** cluster_open's work (probe, and stage the scene at path `scene` with content
 * hash `hash`), in the background: one thread per host, and returns at
 * once, so that a render can start on the first hosts that are ready
 * while a slow or hung one is still being waited for.  Each thread works
 * on its own copy of its host (entry included); cluster_next_ready hands it
 * over.  The strings o and scene point to must outlive the group (argv,
 * static buffers); o->backend_ctx too, unless cluster_end waits.  NULL when out
 * of memory (nothing started). */
cluster_group *cluster_start(const cluster_host *hosts, int n, const tr_options *o, const char *scene, uint64_t hash);

/** Waits up to ms milliseconds (0: not at all) for a host whose
 * preparation has ended and not yet been handed over; copies it into *out
 * (ready: tr set; or not: err says why), hands its remarks to o->notes and
 * returns its index; later remarks of the host go straight to o->notes.
 * -1 when none has ended in that time. */
int cluster_next_ready(cluster_group *g, cluster_host *out, int ms);

/** Hosts still being prepared (not yet handed over). */
int cluster_pending(cluster_group *g);

/** Ends the group.  wait: wait for every thread; otherwise hosts still
 * being prepared are abandoned: their threads close what they opened when
 * their time-outs end, and the last one frees the group.  The hosts handed
 * over must be closed (tr_close) before.  Returns how many were
 * abandoned. */
int cluster_end(cluster_group *g, int wait);

/** The version check of one ready host: closes it, with err saying which
 * version it has and which this build needs, when its worker's version line
 * is not this build's.  Returns 0 if it stays ready. */
int cluster_check_version(cluster_host *h);

/** Refuses a set of ready hosts whose workers report different versions,
 * or a scene format other than this build's; the message names the host. */
int cluster_check_versions(const cluster_host *hosts, int n, fr_error *err);

/** Closes every ready host whose worker's version line is not this
 * build's ("franja-worker VERSION scene-format N"), setting its err to say
 * which version it has and which is needed: a render goes on with the
 * hosts that match (one host left behind by an upgrade, or a broken node
 * of a Slurm allocation, is no reason to stop). */
void cluster_drop_other_versions(cluster_host *hosts, int n);

/** Closes every host (tr_close). */
void cluster_close(cluster_host *hosts, int n);

#endif
