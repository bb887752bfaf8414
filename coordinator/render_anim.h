/** @file render_anim.h
 * `franja render PATTERN --frames LIST`: the frames of an animation (see
 * framewalk.h for the list, the file names and what is said) rendered
 * together over one set of hosts, connected once.  Frames are opened
 * (locked, compiled) in the order of the list; once every slab of a frame
 * has started, a slot that comes free starts the next frame's slabs, and
 * each frame is written as soon as its rows are in.  The reporters follow
 * the frames in flight: --progress json is one stream whose frame events
 * carry the frame's number (progress.h), the monitor shows every frame's
 * state and the newest frame's image (monitor.h), and --preview writes each
 * frame's file while it renders (one without '#' follows the newest frame).
 * --time-limit is the run's: at the limit the frames in flight stop with
 * their finished slabs kept, as after an interrupt.
 */
#ifndef FRANJA_RENDER_ANIM_H
#define FRANJA_RENDER_ANIM_H

#include "frame.h"

/** Parses one frame's command line (argv[0] is the command's name) into a
 * new image whose stop flag is set; NULL with *status set (0 after --help,
 * 2 on a usage error). */
typedef frame_image *(*render_anim_parse_fn)(int argc, char **argv, int *status);

/** Renders the frames of a->frames; argv is the command line as typed,
 * each frame's own made from it by framewalk.h's rules and parsed with
 * parse.  Returns the exit status of `franja render` (130 when
 * interrupted, FRAMES_TIME_LIMIT when stopped by --time-limit: the frames
 * in flight keep their finished slabs for --resume). */
int render_anim(int argc, char **argv, frame_settings *a, render_anim_parse_fn parse);

#endif
