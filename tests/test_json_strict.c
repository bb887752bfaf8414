/* test_json_strict.c -- scene JSON with duplicate members or bad syntax is
 * refused at its line.
 *
 * Scene JSON is read strictly: a member named twice (two materials of one
 * name, a radius given twice), text after the scene's closing brace and
 * every syntax error are refused with the file, line and column; what is
 * valid still reads. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compile/json_scene.h"

#define HEAD                                                                                            \
    "{\"image\": {\"width\": 4, \"height\": 4},\n"                                                      \
    " \"camera\": {\"position\": [0, 0, -5], \"target\": [0, 0, 0], \"fov\": 40},\n"
#define MATS " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5], \"emission\": [1, 1, 1]}},\n"
#define BALL "{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}"
#define GOOD HEAD MATS " \"shapes\": [" BALL "]}\n"

/* Parse text as scene.json: 0 or -1, the message in *err. */
static int parse(const char *text, fr_error *err)
{
    fr_builder b;
    bld_init(&b);
    int rc = json_scene_parse(text, "scene.json", NULL, &b, err);
    bld_free(&b);
    return rc;
}

/* text must be refused with a message holding every fragment. */
static void refused(const char *what, const char *text, const char *f1, const char *f2)
{
    fr_error err = {{0}};
    int rc = parse(text, &err);
    CHECK(rc < 0, "%s: accepted", what);
    if (rc < 0)
        CHECK(strstr(err.msg, f1) && (!f2 || strstr(err.msg, f2)), "%s: message '%s' lacks '%s'%s%s", what, err.msg,
              f1, f2 ? " or " : "", f2 ? f2 : "");
}

int main(void)
{
    fr_error err;
    CHECK(parse(GOOD, &err) == 0, "the valid scene: %s", err.msg);

    /* Names given twice. */
    refused("two materials of one name",
            HEAD " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]},\n"
                 "   \"m\": {\"type\": \"emitter\", \"emission\": [4, 4, 4]}},\n \"shapes\": [" BALL "]}",
            "scene.json:4:4: duplicate member \"m\" in materials (first at 3:16)", NULL);
    refused("a radius given twice",
            HEAD MATS " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"radius\": 2, "
                      "\"material\": \"m\"}]}",
            "scene.json:4:66: duplicate member \"radius\" in shapes[0] (first at 4:53)", NULL);
    refused("camera given twice", HEAD MATS " \"camera\": {}, \"shapes\": [" BALL "]}",
            "scene.json:4:2: duplicate member \"camera\" in the top-level object (first at 2:2)", NULL);
    refused("the same name written with an escape",
            HEAD " \"materials\": {\"m\": {\"type\": \"lambert\", \"albedo\": [0.5, 0.5, 0.5]}, \"\\u006d\": {}},\n"
                 " \"shapes\": [" BALL "]}",
            "scene.json:3:", "duplicate member \"m\" in materials");

    /* Text after the scene. */
    refused("text after the scene", GOOD "xyz\n", "scene.json:5:1: 'x' after the end of the JSON value (which ends at 4:84)",
            NULL);
    refused("a second object after the scene", GOOD "{}", "scene.json:5:1: '{' after the end of the JSON value", NULL);
    refused("a stray brace", HEAD MATS " \"shapes\": [" BALL "]}}", "scene.json:4:", "'}' after the end");

    /* Syntax errors: line and column. */
    refused("a missing comma", HEAD MATS " \"shapes\": [" BALL "\n  " BALL "]}",
            "scene.json:5:3: expected ',' or ']' after an element of the array that opens at 4:12", NULL);
    refused("a trailing comma in an object", HEAD " \"materials\": {\"m\": {\"type\": \"lambert\",}},",
            "scene.json:3:40: a comma before '}'", NULL);
    refused("a trailing comma in an array", HEAD MATS " \"shapes\": [" BALL ",]}", "scene.json:4:",
            "a comma before ']'");
    refused("a missing colon", "{\"image\" {}}", "scene.json:1:10: expected ':' after the member name", NULL);
    refused("single quotes", "{'image': {}}", "scene.json:1:2: expected a member name", NULL);
    refused("a comment", "{\n  // the image\n  \"image\": {}}", "scene.json:2:3: expected a member name", NULL);
    refused("a leading zero", "{\"a\": 01}", "scene.json:1:7: bad number: no leading zeros", NULL);
    refused("NaN", "{\"a\": NaN}", "scene.json:1:7: expected a value", NULL);
    refused("an unterminated string", "{\"a\": \"abc}\n", "scene.json:1:12: unterminated string (it opens at 1:7", NULL);
    refused("a raw tab in a string", "{\"a\t\": 1}", "scene.json:1:4: a control character (byte 0x09)", NULL);
    refused("a lone surrogate", "{\"a\": \"\\ud800\"}", "scene.json:1:8: bad \\u escape", NULL);
    refused("an escaped NUL", "{\"a\": \"x\\u0000\"}", "scene.json:1:9: \\u0000", NULL);
    refused("the end of the text", "{\"image\": ", "scene.json:1:11: expected a value, found the end of the text",
            NULL);
    refused("a column after a multibyte character", "{\"é\": 1 2}", "scene.json:1:9:", NULL);
    char deep[1200] = "{\"a\": ";
    for (int i = 0; i < 300; i++)
        strcat(deep, "[");
    refused("300 nested arrays", deep, "nested deeper than 256 levels", NULL);

    /* Valid scenes with escapes, exponents and unicode names still read. */
    CHECK(parse(HEAD " \"materials\": {\"m\\u00e9\": {\"type\": \"lambert\", \"albedo\": [5e-1, 0.5E+0, 0.5]},"
                     " \"mé2\": {\"type\": \"emitter\", \"emission\": [1, 1, 1]}},\n"
                     " \"shapes\": [{\"type\": \"sphere\", \"center\": [0, 0, -0.0], \"radius\": 1, \"material\": "
                     "\"m\\u00e9\"}, {\"type\": \"sphere\", \"center\": [0, 3, 0], \"radius\": 1, \"material\": "
                     "\"mé2\"}]}\r\n\t ",
                &err) == 0,
          "escapes and unicode: %s", err.msg);
    return check_done();
}
