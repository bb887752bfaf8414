/* test_confine.c -- which files a scene may read (confine.h): folders,
 * '..', absolute names, links out, FIFOs and devices; and the escaping of
 * control characters in messages (error.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "compile/confine.h"
#include "error.h"

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static void escaping(void)
{
    fr_error e;
    fr_fail(&e, "a%cb%c[2J%c", 7, 27, 0x7f);
    CHECK(!strcmp(e.msg, "a\\x07b\\x1b[2J\\x7f"), "C0 and DEL escaped: %s", e.msg);
    fr_fail(&e, "x\xc2\x9b" "1m \xc3\xa9");
    CHECK(!strcmp(e.msg, "x\\xc2\\x9b1m \xc3\xa9"), "C1 escaped, other UTF-8 kept: %s", e.msg);
    char again[64];
    snprintf(again, sizeof again, "%s", "a\\x1b b");
    fr_escape_controls(again, sizeof again);
    CHECK(!strcmp(again, "a\\x1b b"), "escaping twice changes nothing: %s", again);
    char small[8] = "ab\033\033";
    fr_escape_controls(small, sizeof small);
    CHECK(!strcmp(small, "ab\\x1b"), "an escape that does not fit is dropped, not left raw: %s", small);
    for (size_t i = 0; i < sizeof e.msg; i++)
        e.msg[i] = 0;
    char big[600];
    memset(big, 27, sizeof big - 1);
    big[sizeof big - 1] = 0;
    fr_fail(&e, "%s", big);
    CHECK(strlen(e.msg) < sizeof e.msg && !strchr(e.msg, 27), "a long message of ESC bytes: cut, all escaped");
}

static void folders(void)
{
    char base[] = "/tmp/franja-confine-XXXXXX", p[512], q[512];
    CHECK(mkdtemp(base) != NULL, "mkdtemp");
    snprintf(p, sizeof p, "%s/scene", base);
    mkdir(p, 0755);
    snprintf(p, sizeof p, "%s/scene/sub", base);
    mkdir(p, 0755);
    snprintf(p, sizeof p, "%s/out", base);
    mkdir(p, 0755);
    snprintf(p, sizeof p, "%s/scene/in.txt", base);
    put(p, "inside");
    snprintf(p, sizeof p, "%s/out/secret.txt", base);
    put(p, "outside");
    snprintf(p, sizeof p, "%s/scene/link.txt", base);
    CHECK(symlink("../out/secret.txt", p) == 0, "symlink");
    snprintf(p, sizeof p, "%s/scene/fifo", base);
    CHECK(mkfifo(p, 0600) == 0, "mkfifo");

    confine c;
    fr_error e;
    snprintf(p, sizeof p, "%s/scene/s.json", base);
    CHECK(confine_init(&c, p, NULL, 0, &e) == 0, "init: %s", e.msg);
    char *data;
    size_t len;
    snprintf(p, sizeof p, "%s/scene/sub/../in.txt", base);
    CHECK(confine_read(&c, p, 100, &data, &len, &e) == 0 && len == 6 && !strcmp(data, "inside"), "inside: %s",
          e.msg);
    if (data)
        free(data);
    snprintf(p, sizeof p, "%s/scene/../out/secret.txt", base);
    CHECK(confine_read(&c, p, 100, &data, &len, &e) < 0 && strstr(e.msg, "outside the scene's folder") && !data,
          "'..' out: %s", e.msg);
    snprintf(p, sizeof p, "%s/scene/link.txt", base);
    CHECK(confine_read(&c, p, 100, &data, &len, &e) < 0 && strstr(e.msg, "outside the scene's folder"),
          "link out: %s", e.msg);
    CHECK(confine_read(&c, "/etc/hostname", 100, &data, &len, &e) < 0 && strstr(e.msg, "/etc/hostname: "),
          "absolute: %s", e.msg);
    snprintf(p, sizeof p, "%s/scene/fifo", base);
    CHECK(confine_read(&c, p, 100, &data, &len, &e) < 0 && strstr(e.msg, "not a regular file (a FIFO)"),
          "FIFO: %s", e.msg);
    snprintf(p, sizeof p, "%s/scene/in.txt", base);
    CHECK(confine_read(&c, p, 3, &data, &len, &e) < 0 && strstr(e.msg, "more than the 3"), "size: %s", e.msg);

    /* --allow-path widens it; a folder that only shares a prefix does not */
    snprintf(q, sizeof q, "%s/out", base);
    const char *allow[] = {q};
    snprintf(p, sizeof p, "%s/scene/s.json", base);
    CHECK(confine_init(&c, p, allow, 1, &e) == 0, "init with allow: %s", e.msg);
    snprintf(p, sizeof p, "%s/scene/link.txt", base);
    CHECK(confine_read(&c, p, 100, &data, &len, &e) == 0 && !strcmp(data, "outside"), "allowed: %s", e.msg);
    free(data);
    CHECK(confine_below("/a/b", "/a/b") && confine_below("/a/b/c", "/a/b") && !confine_below("/a/bc", "/a/b") &&
              confine_below("/x", "/"),
          "confine_below is by whole components");
    const char *missing[] = {"/nonexistent/franja"};
    CHECK(confine_init(&c, p, missing, 1, &e) < 0 && strstr(e.msg, "--allow-path"), "missing allowed folder: %s",
          e.msg);
    CHECK(confine_open(NULL, "x", 1, &(int){0}, &(size_t){0}, &e) < 0, "no scope refuses");

    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", base);
    CHECK(system(cmd) == 0, "cleanup");
}

int main(void)
{
    escaping();
    folders();
    return check_done();
}
