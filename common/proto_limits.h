/** @file proto_limits.h
 * The limits of a render, part of the worker protocol (protocol.h) and of
 * the binary scene format (FORMAT.md, "settings"): the scene readers, the
 * partial-image reader and both command lines enforce them.  A header of
 * its own, depending on nothing, so that the lowest modules (image.c,
 * fbin.c) can use it.
 */
#ifndef FRANJA_PROTO_LIMITS_H
#define FRANJA_PROTO_LIMITS_H

/** Largest image width or height, pixels. */
#define PROTO_MAX_SIZE 65536u
/** Largest number of samples per pixel (2^20). */
#define PROTO_MAX_SPP (1u << 20)
/** Largest path depth (bounces) a scene may ask for. */
#define PROTO_MAX_DEPTH 4096u

#endif
