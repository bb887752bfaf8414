/* fuzz_ply.c -- libFuzzer target for the PLY header check
 * (coordinator/compile/plyhead.h): the input is the start of a file whose whole
 * size its first four bytes give (little-endian, up to 4 GiB), the rest
 * the header text. */
#include <stdint.h>
#include <string.h>

#include "compile/plyhead.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 4)
        return 0;
    uint32_t file_size;
    memcpy(&file_size, data, 4);
    fr_error err;
    plyhead_check("fuzz.ply", (const char *)data + 4, size - 4, (size_t)file_size, &err);
    return 0;
}
