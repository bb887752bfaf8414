/** @file le.h
 * Little-endian integers in byte buffers: the byte order of binary scenes
 * and scene patches, whatever the host's.
 */
#ifndef FRANJA_LE_H
#define FRANJA_LE_H

#include <stdint.h>

/** Write v at p[0..4) / p[0..8), least significant byte first. */
static inline void le_put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}
static inline void le_put64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/** The value at p[0..4) / p[0..8), least significant byte first. */
static inline uint32_t le_get32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t le_get64(const unsigned char *p) { return (uint64_t)le_get32(p) | (uint64_t)le_get32(p + 4) << 32; }

#endif
