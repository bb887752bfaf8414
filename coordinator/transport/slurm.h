/** @file slurm.h
 * The Slurm allocation franja runs in (`franja render --slurm`, `franja
 * hosts check --slurm`): its nodes and the CPUs it holds on each, found in
 * the job's environment, and the settings the Slurm transport backend
 * (transport_slurm.c) shares between the nodes.
 *
 * franja itself runs where salloc or sbatch put it (a login node, or the
 * first node of a batch job), never inside a job step: its workers are the
 * job steps.  Nothing here talks to a node; the only Slurm command used is
 * `scontrol show hostnames`, to expand the node list.
 */
#ifndef FRANJA_SLURM_H
#define FRANJA_SLURM_H

#include <pthread.h>
#include <stddef.h>

#include "error.h"
#include "transport/hosts.h"
#include "transport/transport.h"

/** Longest node name kept (Slurm's own limit is lower). */
#define SLURM_NODE_MAX 64

/** One allocation and the backend's shared state.  Filled by slurm_open;
 * the caller may then change workdir, shared and worker; slurm_close
 * frees it.  The backend's threads (one per node while hosts are made
 * ready) use it under `lock`. */
typedef struct {
    char job[32];              /**< SLURM_JOB_ID */
    int n;                     /**< number of nodes */
    char (*node)[SLURM_NODE_MAX]; /**< node names, in the allocation's order */
    int *cpus;                 /**< CPUs allocated on each node */
    char workdir[512];         /**< scene cache on the nodes (absolute) */
    int shared;                /**< workdir is one directory that this machine and every
                                    node see: scenes are copied there once, not broadcast */
    char worker[512];          /**< the worker program on the nodes (absolute) */
    int timeout_s;             /**< longest wait for a Slurm command that should be quick */
    pthread_mutex_t lock;      /**< guards what follows */
    int ended;                 /**< the job was seen to have ended */
    int sharing;               /**< new steps share the job's CPUs (srun --overlap) */
    char copied[8][1024];      /**< shared workdir: files already copied this run */
    int ncopied;
} slurm_alloc;

/** Reads the allocation franja runs in from SLURM_JOB_ID,
 * SLURM_JOB_NODELIST (expanded with `scontrol show hostnames`, at most
 * timeout_s seconds) and SLURM_JOB_CPUS_PER_NODE.  Sets the defaults:
 * workdir /tmp/franja-USER (node-local), worker `worker` (the one beside
 * this franja, which the nodes must see at the same path).  Fails outside
 * an allocation (err says so; slurm_hint says what to run instead), inside
 * a job step, and on environment values that do not parse (naming the
 * variable and the offset). */
int slurm_open(slurm_alloc *a, const char *worker, int timeout_s, fr_error *err);

/** Whether the job has ended (cancelled, timed out, failed).  With ask,
 * asks the controller (`squeue`, at most timeout_s) and remembers an
 * ended job; without, only says what is known.  A job the controller
 * cannot be asked about is taken as still running. */
int slurm_job_ended(slurm_alloc *a, int ask);

/** Whether new steps are to share the job's CPUs (srun --overlap) rather
 * than take their own, and slurm_share to make it so: for a job where
 * Slurm no longer hands out CPUs that ended steps used (transport_slurm.c
 * says when). */
int slurm_sharing(slurm_alloc *a);
void slurm_share(slurm_alloc *a);

/** Frees what slurm_open allocated.  Safe on a zeroed struct. */
void slurm_close(slurm_alloc *a);

/** Parses a SLURM_JOB_CPUS_PER_NODE value ("72(x2),36": counts, each
 * optionally repeated) into cpus[n].  Fails unless it describes exactly n
 * nodes with 1..HOSTS_MAX_CORES CPUs each; the message gives the offset. */
int slurm_parse_cpus(const char *s, int n, int *cpus, fr_error *err);

/** A host table with one entry per node (name and address: the node name;
 * cores: its CPUs; worker and workdir from a).  t is freed with hosts_free. */
int slurm_hosts(const slurm_alloc *a, hosts_table *t, fr_error *err);

/** Makes every host of o run through a's job steps (the Slurm backend,
 * with a as its context); a must outlive o's use. */
void slurm_serve(slurm_alloc *a, tr_options *o);

/** Copies local_path to `remote` (absolute, as the nodes name it) with
 * permission bits `mode` on node `node` of the job, for host h of the
 * Slurm backend (slurm_copy.c says how): by sbcast to that node alone,
 * through a temporary name renamed into place, creating the directory;
 * or, with a shared work directory, by copying it here once per run.
 * Checks the size that arrived.  May be called from several threads, one
 * per host. */
int slurm_copy(tr_host *h, slurm_alloc *a, const char *node, const char *local_path, const char *remote, int mode,
               fr_error *err);

/** Writes into out[cap] the lines that show how to run the command argv
 * (as typed) inside an allocation: with salloc, and with sbatch. */
void slurm_hint(int argc, char **argv, char *out, size_t cap);

#endif
