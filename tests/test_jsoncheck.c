/* test_jsoncheck.c -- the strict JSON check: what it accepts and where it
 * refuses.
 *
 * jsoncheck.h: strict JSON recognized, everything else refused at the
 * right line and column; duplicate names found at any depth and among many
 * members; NUL bytes and every example scene handled. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "file.h"
#include "compile/jsoncheck.h"

static int check(const char *text, size_t len, fr_error *err) { return jc_check(text, len, "t.json", err); }

static void valid(const char *text)
{
    fr_error err;
    CHECK(check(text, strlen(text), &err) == 0, "refused %s: %s", text, err.msg);
}

static void invalid(const char *text, const char *want)
{
    fr_error err = {{0}};
    int rc = check(text, strlen(text), &err);
    CHECK(rc < 0 && strstr(err.msg, want), "%s: %s (want '%s')", text, rc < 0 ? err.msg : "accepted", want);
}

int main(void)
{
    /* Every kind of value, at the top too. */
    valid("{}");
    valid("[]");
    valid(" \t\r\n{\"a\": [1, -0, 0.5, -2e10, 3E-2, 4e+1, true, false, null, \"s\", {}, []]} \n");
    valid("\"just a string\"");
    valid("42");
    valid("{\"\": 1, \"a\\\"b\": 2, \"a\\\\b\": 3, \"\\ud83d\\ude00\": 4, \"\xf0\x9f\x98\x80x\": 5}");
    /* Same names in different objects are fine. */
    valid("{\"a\": {\"x\": 1}, \"b\": {\"x\": 2}, \"c\": [{\"x\": 1}, {\"x\": 2}]}");

    invalid("", "t.json:1:1: expected a value, found the end of the text");
    invalid("{\"a\": 1, \"b\": 2, \"a\": 3}", "t.json:1:18: duplicate member \"a\" in the top-level object (first at 1:2)");
    invalid("{\"s\": [0, {\"k\": {\"x\": 1, \"y\": 2, \"x\": 3}}]}",
            "t.json:1:34: duplicate member \"x\" in s[1].k (first at 1:18)");
    invalid("{\"\\ud83d\\ude00\": 1, \"\xf0\x9f\x98\x80\": 2}", "duplicate member \"\xf0\x9f\x98\x80\"");
    /* Of two duplicated names, the one whose repeat comes first is named. */
    invalid("{\"b\": 1, \"a\": 1, \"a\": 2, \"b\": 2}", "duplicate member \"a\"");
    invalid("{\"a\": 1}{", "t.json:1:9: '{' after the end of the JSON value (which ends at 1:9)");
    invalid("{\"a\": 1} x", "t.json:1:10: 'x' after the end");
    invalid("{\"a\": tru}", "t.json:1:7: expected a value");
    invalid("{\"a\": 1.}", "bad number: a digit must follow '.'");
    invalid("{\"a\": -}", "bad number: a digit must follow '-'");
    invalid("{\"a\": 1e}", "exponent");
    invalid("{\"a\": +1}", "t.json:1:7: expected a value");
    invalid("{\"a\": \"\\x\"}", "t.json:1:8: bad escape");
    invalid("{\"a\": \"\\u12g4\"}", "t.json:1:8: bad \\u escape (expected four hexadecimal digits)");
    invalid("{\"a\": \"\\udc00\"}", "low surrogate");
    invalid("{\"a\": \"\\ud800\\u0041\"}", "high surrogate");
    invalid("[1,\n 2\n 3]", "t.json:3:2: expected ',' or ']' after an element of the array that opens at 1:1");
    invalid("{\"a\": 1\n\"b\": 2}", "t.json:2:1: expected ',' or '}' after a member of the object that opens at 1:1");
    invalid("{1: 2}", "t.json:1:2: expected a member name");

    /* NUL bytes, counted by length. */
    fr_error err = {{0}};
    CHECK(check("{\"a\": 1}\0", 9, &err) < 0 && strstr(err.msg, "t.json:1:9: byte 0x00 after the end"), "NUL after: %s",
          err.msg);
    CHECK(check("{\"a\0\": 1}", 9, &err) < 0 && strstr(err.msg, "t.json:1:4: a control character (byte 0x00)"),
          "NUL in a string: %s", err.msg);

    /* Many members: duplicates found among 200000 names, quickly. */
    size_t cap = 200000 * 24 + 64, n = 0;
    char *big = malloc(cap);
    n += (size_t)snprintf(big + n, cap - n, "{");
    for (int i = 0; i < 200000; i++)
        n += (size_t)snprintf(big + n, cap - n, "%s\"m%d\": %d", i ? ", " : "", (i * 7919) % 200000, i);
    n += (size_t)snprintf(big + n, cap - n, "}");
    CHECK(check(big, n, &err) == 0, "200000 distinct members: %s", err.msg);
    big[n - 1] = 0;
    n = strlen(big);
    n += (size_t)snprintf(big + n, cap - n, ", \"m12345\": 0}");
    CHECK(check(big, n, &err) < 0 && strstr(err.msg, "duplicate member \"m12345\""), "the 200001st member: %s",
          err.msg);
    free(big);

    /* Deep nesting: 256 levels pass, 257 do not. */
    char deep[600];
    memset(deep, '[', 257);
    memset(deep + 257, ']', 257);
    CHECK(check(deep + 1, 512, &err) == 0, "256 levels: %s", err.msg);
    CHECK(check(deep, 514, &err) < 0 && strstr(err.msg, "t.json:1:257: values nested deeper than 256 levels"),
          "257 levels: %s", err.msg);

    /* The example scenes are strict JSON. */
    const char *scenes[] = {"scenes/cornell.json", "scenes/spheres.json", "scenes/cornell-textured.json",
                            "scenes/fog-room.json", "scenes/knot.json", "scenes/bumpy.json"};
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        char *text;
        size_t len;
        if (file_read(scenes[i], &text, &len, &err) < 0) {
            CHECK(0, "%s", err.msg);
            continue;
        }
        CHECK(jc_check(text, len, scenes[i], &err) == 0, "%s", err.msg);
        free(text);
    }
    return check_done();
}
