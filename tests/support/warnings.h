/* warnings.h -- a scene_hooks warn callback that counts what it is told.
 *
 * For tests of the scene readers: n_warnings counts the warnings since the
 * test last zeroed it, last_warning holds the latest; warn_hooks passes
 * on_warn and nothing else. */
#ifndef FRANJA_TEST_WARNINGS_H
#define FRANJA_TEST_WARNINGS_H

#include <stdio.h>

#include "compile/scene_hooks.h"

static int n_warnings;
static char last_warning[800];

static void on_warn(void *user, const char *msg)
{
    (void)user;
    n_warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

static const scene_hooks warn_hooks = {.warn = on_warn};

#endif
