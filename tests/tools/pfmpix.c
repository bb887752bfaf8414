/* pfmpix -- print pixels of a PFM image (as franja-worker and franja write
 * them), for tests that check known pixels:
 *
 *   pfmpix IMAGE.pfm X Y [X Y ...]
 *
 * prints "R G B" (linear floats) for each (X, Y), X from the left and Y
 * from the top row; `pfmpix IMAGE.pfm size` prints "W H". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: pfmpix IMAGE.pfm X Y [X Y ...] | size\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "rb");
    if (!f) {
        perror(argv[1]);
        return 1;
    }
    char magic[3] = {0};
    int w, h, c;
    double scale;
    if (fscanf(f, "%2s", magic) != 1 || strcmp(magic, "PF") != 0)
        goto bad;
    while ((c = fgetc(f)) == '\n' || c == ' ' || c == '#')
        if (c == '#')
            while ((c = fgetc(f)) != '\n' && c != EOF) {}
    ungetc(c, f);
    if (fscanf(f, "%d %d %lf", &w, &h, &scale) != 3 || fgetc(f) != '\n' || w <= 0 || h <= 0 || w > 65536 ||
        h > 65536 || scale >= 0)
        goto bad;
    if (!strcmp(argv[2], "size")) {
        printf("%d %d\n", w, h);
        return 0;
    }
    size_t n = (size_t)w * h * 3;
    float *px = malloc(n * sizeof *px);
    if (!px || fread(px, sizeof *px, n, f) != n)
        goto bad;
    for (int i = 2; i + 1 < argc; i += 2) {
        int x = atoi(argv[i]), y = atoi(argv[i + 1]);
        if (x < 0 || y < 0 || x >= w || y >= h) {
            fprintf(stderr, "pfmpix: (%d, %d) is outside %dx%d\n", x, y, w, h);
            return 1;
        }
        const float *p = px + ((size_t)(h - 1 - y) * w + x) * 3; /* PFM rows run bottom to top */
        printf("%g %g %g\n", p[0], p[1], p[2]);
    }
    free(px);
    fclose(f);
    return 0;
bad:
    fprintf(stderr, "pfmpix: %s: not a PFM image\n", argv[1]);
    return 1;
}
