/** @file rlimit.h
 * The limits of a child process that reads untrusted input (the compile
 * child, the Assimp importer): no core file, an address space of what the
 * process maps already (libraries, the copy of its parent) plus a budget,
 * and CPU seconds.
 */
#ifndef FRANJA_RLIMIT_H
#define FRANJA_RLIMIT_H

#include <stdint.h>

/** Sets this process's limits: RLIMIT_CORE 0; RLIMIT_AS the bytes mapped
 * now plus `extra` (left as it is when extra is 2^62 or more, or the
 * mapped size cannot be read); RLIMIT_CPU cpu_soft seconds (SIGXCPU) and
 * cpu_hard (SIGKILL).  Call it in the child, before reading its input. */
void rlimit_child(uint64_t extra, uint64_t cpu_soft, uint64_t cpu_hard);

#endif
