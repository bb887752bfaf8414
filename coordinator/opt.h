/** @file opt.h
 * Command-line options of the franja subcommands: getopt_long with the
 * messages franja gives (the nearest option to an unknown one; what a bad
 * value may be), value parsers that say what is allowed, and the output
 * name made from a scene's.  Messages go to stderr as "franja CMD: ...";
 * nothing here exits.
 */
#ifndef FRANJA_OPT_H
#define FRANJA_OPT_H

#include <getopt.h>
#include <stddef.h>
#include <stdint.h>

/** The name of an output made from scene in the current directory: the
 * scene's file name without its directory and without a scene extension
 * (.json .gltf .glb .fbin, any case), then ext (".png", ".fbin"): so
 * "scenes/cornell.json" gives "cornell.png".  Returns -1 when that name
 * does not fit in buf[cap] or would be ext alone (a scene named ".json"). */
int opt_default_output(const char *scene, const char *ext, char *buf, size_t cap);

/** The next option of a subcommand's argv, by getopt_long(3) (options and
 * operands in any order, --spp=8 or --spp 8, abbreviations that are
 * unambiguous, -- ends the options; argv is permuted so that the operands
 * end up in argv[optind..argc)).  Set optind = 0 before the first call.
 * shortopts and longopts are getopt_long's (shortopts without a leading
 * ':').  Returns the option's value, *optarg set when it takes one, or -1
 * after the last option.  An unknown option (with the nearest known one,
 * opt_suggest), an ambiguous abbreviation (with its candidates) or a
 * missing value is reported on stderr as "franja CMD: ..." and returns '?'. */
int opt_next(const char *cmd, int argc, char **argv, const char *shortopts, const struct option *longopts);

/** A copy of argv[0..argc) (the pointers, then NULL), for opt_next to
 * permute while argv keeps the order the person typed (for messages that
 * repeat the command).  Free with free(); NULL when out of memory. */
char **opt_copy(int argc, char **argv);

/** The known option nearest to typed (an option as written, "--samples",
 * "--spp=0", "-x"), for "did you mean": a usual synonym ("--samples" ->
 * "--spp"), a long option within a few edits, or one that typed is a
 * prefix of.  Writes "--NAME" or "-C" to buf[cap] and returns 0; -1 when
 * none is near. */
int opt_suggest(const char *typed, const char *shortopts, const struct option *longopts, char *buf, size_t cap);

/** Parses an option's value as a decimal integer in [lo, hi]; otherwise
 * prints "franja CMD: OPT: 'V' is not an integer in LO..HI" and returns
 * -1. */
int opt_uint(const char *cmd, const char *opt, const char *v, uint32_t lo, uint32_t hi, uint32_t *out);

/** Parses an option's value as a number in [lo, hi] (strtod); otherwise
 * prints the range and returns -1. */
int opt_float(const char *cmd, const char *opt, const char *v, float lo, float hi, float *out);

/** Parses an option's value as a number above 0 and at most 1; otherwise
 * prints "franja CMD: OPT: 'V' is not a number in (0, 1] ..." and returns
 * -1. */
int opt_fraction(const char *cmd, const char *opt, const char *v, float *out);

/** Parses an option's value as WxH (proto_parse_size); otherwise prints
 * what is expected and returns -1. */
int opt_size(const char *cmd, const char *opt, const char *v, uint32_t *w, uint32_t *h);

/** The largest --scale: 400%. */
#define OPT_SCALE_MAX 4.0

/** Parses a scale factor: a percentage ("50%") or a plain factor ("0.5"),
 * above 0 and at most OPT_SCALE_MAX; otherwise prints what is allowed and
 * returns -1. */
int opt_scale(const char *cmd, const char *opt, const char *v, double *out);

/** The longest --time-limit: a week, in seconds. */
#define OPT_DURATION_MAX (7.0 * 24 * 3600)

/** Parses a duration: a number above 0 with an optional unit, s (the
 * default), m or h ("90", "90s", "1.5m", "2h"), at most OPT_DURATION_MAX;
 * writes seconds to *out.  Otherwise prints what is allowed and returns
 * -1. */
int opt_duration(const char *cmd, const char *opt, const char *v, double *out);

/** Scales a scene's side of n pixels by s: rounded to the nearest pixel
 * (halves up), at least 1.  So 50% of 255 is 128, 10% of 4 is 1. */
uint32_t opt_scaled(uint32_t n, double s);

/** When w x h has another aspect ratio than the scene's sw x sh, writes a
 * line saying so, naming both ratios ("2:1 (2.000)"), to buf[cap] and
 * returns 1; otherwise returns 0 and leaves buf empty. */
int opt_aspect_note(uint32_t w, uint32_t h, uint32_t sw, uint32_t sh, char *buf, size_t cap);

/** Finds v among the NULL-terminated choices and returns its index;
 * otherwise prints "franja CMD: OPT: 'V' is not one of: A, B" and returns
 * -1. */
int opt_choice(const char *cmd, const char *opt, const char *v, const char *const *choices);

#endif
