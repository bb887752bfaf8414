/* pfmpix.c -- print pixels of a PFM image (as franja-worker and franja write
 * them), for tests that check known pixels:
 *
 *   pfmpix IMAGE.pfm X Y [X Y ...]
 *
 * prints "R G B" (linear floats) for each (X, Y), X from the left and Y
 * from the top row; `pfmpix IMAGE.pfm size` prints "W H". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfmread.h"

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: pfmpix IMAGE.pfm X Y [X Y ...] | size\n");
        return 2;
    }
    image im;
    if (read_pfm("pfmpix", argv[1], &im))
        return 1;
    if (!strcmp(argv[2], "size")) {
        printf("%d %d\n", im.w, im.h);
        free(im.px);
        return 0;
    }
    for (int i = 2; i + 1 < argc; i += 2) {
        int x = atoi(argv[i]), y = atoi(argv[i + 1]);
        if (x < 0 || y < 0 || x >= im.w || y >= im.h) {
            fprintf(stderr, "pfmpix: (%d, %d) is outside %dx%d\n", x, y, im.w, im.h);
            free(im.px);
            return 1;
        }
        const float *p = im.px + ((size_t)y * im.w + x) * 3;
        printf("%g %g %g\n", p[0], p[1], p[2]);
    }
    free(im.px);
    return 0;
}
