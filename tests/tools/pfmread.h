/* pfmread.h -- reads the PFM images that franja and franja-worker write
 * (little-endian RGB, comment lines allowed between the header's fields),
 * for the test tools.  One definition per tool: include it once. */
#ifndef FRANJA_TOOLS_PFMREAD_H
#define FRANJA_TOOLS_PFMREAD_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An image of w x h RGB floats, top row first. */
typedef struct {
    int w, h;
    float *px;
} image;

/* Reads path into *im (im->px malloc'd, the caller frees it).  Sides are
 * limited to 65536.  On failure prints "TOOL: PATH: why" and returns -1
 * with im->px NULL. */
static int read_pfm(const char *tool, const char *path, image *im)
{
    im->px = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "%s: ", tool);
        perror(path);
        return -1;
    }
    char magic[3] = {0};
    double scale;
    int c;
    float *raw = NULL;
    if (fscanf(f, "%2s", magic) != 1 || strcmp(magic, "PF") != 0)
        goto bad;
    while ((c = fgetc(f)) == '\n' || c == ' ' || c == '#')
        if (c == '#')
            while ((c = fgetc(f)) != '\n' && c != EOF) {}
    ungetc(c, f);
    if (fscanf(f, "%d %d %lf", &im->w, &im->h, &scale) != 3 || fgetc(f) != '\n' || im->w <= 0 || im->h <= 0 ||
        scale >= 0 || im->w > 65536 || im->h > 65536)
        goto bad;
    size_t n = (size_t)im->w * im->h * 3;
    im->px = malloc(n * sizeof(float));
    raw = malloc(n * sizeof(float));
    if (!im->px || !raw || fread(raw, sizeof(float), n, f) != n)
        goto bad;
    for (int y = 0; y < im->h; y++) /* PFM rows are bottom to top */
        memcpy(im->px + (size_t)y * im->w * 3, raw + (size_t)(im->h - 1 - y) * im->w * 3, (size_t)im->w * 12);
    free(raw);
    fclose(f);
    return 0;
bad:
    fprintf(stderr, "%s: %s: not a little-endian RGB PFM\n", tool, path);
    free(raw);
    free(im->px);
    im->px = NULL;
    fclose(f);
    return -1;
}

#endif
