/** @file render.h
 * `franja render` (see franja(1)).
 */
#ifndef FRANJA_RENDER_CMD_H
#define FRANJA_RENDER_CMD_H

/** Runs `franja render` with argv[0] = "render"; returns the exit status:
 * 0 when the image is written, 1 when the render failed, 2 on a usage
 * error, 130 when interrupted (finished slabs are kept for --resume). */
int cmd_render(int argc, char **argv);

#endif
