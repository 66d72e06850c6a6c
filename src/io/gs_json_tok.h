/* gs_json_tok.h - a small pull tokenizer for JSON text held in memory: it
 * checks the full grammar (RFC 8259) while handing out one token at a time,
 * so the keypoint readers walk a file without building a tree. Strings are
 * returned raw (between the quotes, escapes not decoded). */
#ifndef GS_JSON_TOK_H
#define GS_JSON_TOK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum {
    GS_JT_ERROR = -1, /* syntax error: see lex->err, lex->err_line */
    GS_JT_EOF = 0,    /* end of the (complete) document */
    GS_JT_OBJ,        /* '{' */
    GS_JT_OBJ_END,    /* '}' */
    GS_JT_ARR,        /* '[' */
    GS_JT_ARR_END,    /* ']' */
    GS_JT_KEY,        /* an object key (the ':' after it is consumed) */
    GS_JT_STR,        /* a string value */
    GS_JT_NUM,        /* a number, text checked against the JSON grammar */
    GS_JT_TRUE,
    GS_JT_FALSE,
    GS_JT_NULL
} gs_jt;

typedef struct {
    gs_jt type;
    const char *s;    /* string contents without quotes, number text, or the punctuation */
    size_t len;
    uint32_t line;    /* 1-based line where the token starts */
    uint32_t depth;   /* nesting depth before the token (for OBJ/ARR: of the container itself) */
} gs_jtok;

#define GS_JSON_MAX_DEPTH 64

typedef struct {
    const char *p, *end;
    uint32_t line;
    uint32_t depth;
    uint8_t stack[GS_JSON_MAX_DEPTH]; /* 'o' object, 'a' array */
    int state;
    uint32_t err_line;
    char err[96];
} gs_jlex;

void gs_jlex_init(gs_jlex *l, const char *text, size_t len);
/* Next token into *t (also returned). After GS_JT_ERROR every call returns GS_JT_ERROR. */
gs_jt gs_jlex_next(gs_jlex *l, gs_jtok *t);
/* Skip the value that starts with token *first (its sub-tree for OBJ/ARR).
 * false on a syntax error. */
bool gs_jlex_skip(gs_jlex *l, const gs_jtok *first);
/* Raw string/key token equals the NUL-terminated s. */
bool gs_jtok_eq(const gs_jtok *t, const char *s);
/* Number token as double (false when not a number token or out of range). */
bool gs_jtok_num(const gs_jtok *t, double *out);

#endif
