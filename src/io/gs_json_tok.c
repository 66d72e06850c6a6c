/* gs_json_tok.c - pull tokenizer for JSON in memory, full grammar check. */
#include "gs_json_tok.h"

#include <string.h>

#include "gravscale/gs_num.h"

enum {
    S_VALUE = 0,      /* a value is required (document start, after ':' or ',' in an array) */
    S_VALUE_OR_END,   /* after '[': a value or ']' */
    S_KEY_OR_END,     /* after '{': a key or '}' */
    S_KEY,            /* after ',' in an object */
    S_AFTER,          /* after a value inside a container: ',' or the closing bracket */
    S_DONE,           /* top-level value complete: only blanks may follow */
    S_ERROR
};

void gs_jlex_init(gs_jlex *l, const char *text, size_t len)
{
    memset(l, 0, sizeof *l);
    l->p = text;
    l->end = text + len;
    l->line = 1;
    l->state = S_VALUE;
}

static gs_jt fail(gs_jlex *l, gs_jtok *t, const char *msg)
{
    size_t n = strlen(msg);
    if (n >= sizeof l->err)
        n = sizeof l->err - 1;
    memcpy(l->err, msg, n);
    l->err[n] = '\0';
    l->err_line = l->line;
    l->state = S_ERROR;
    t->type = GS_JT_ERROR;
    t->s = l->p;
    t->len = 0;
    t->line = l->line;
    return GS_JT_ERROR;
}

static void skip_blanks(gs_jlex *l)
{
    while (l->p < l->end) {
        char c = *l->p;
        if (c == '\n')
            l->line++;
        else if (c != ' ' && c != '\t' && c != '\r')
            return;
        l->p++;
    }
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* l->p at the opening quote; on success t->s/len hold the raw contents. */
static bool scan_string(gs_jlex *l, gs_jtok *t, const char **why)
{
    const char *q = l->p + 1;
    while (q < l->end) {
        unsigned char c = (unsigned char)*q;
        if (c == '"') {
            t->s = l->p + 1;
            t->len = (size_t)(q - (l->p + 1));
            l->p = q + 1;
            return true;
        }
        if (c < 0x20) {
            *why = "control character in string";
            return false;
        }
        if (c == '\\') {
            if (q + 1 >= l->end)
                break;
            char e = q[1];
            if (e == 'u') {
                if (l->end - q < 6 || hexval(q[2]) < 0 || hexval(q[3]) < 0 || hexval(q[4]) < 0 ||
                    hexval(q[5]) < 0) {
                    *why = "bad \\u escape in string";
                    return false;
                }
                q += 6;
                continue;
            }
            if (!strchr("\"\\/bfnrt", e) || e == '\0') {
                *why = "bad escape in string";
                return false;
            }
            q += 2;
            continue;
        }
        q++;
    }
    *why = "unterminated string";
    return false;
}

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

static bool is_delim(char c)
{
    return c == ',' || c == ']' || c == '}' || c == ' ' || c == '\t' || c == '\r' || c == '\n' ||
           c == ':';
}

static bool scan_number(gs_jlex *l, gs_jtok *t)
{
    const char *q = l->p, *e = l->end;
    if (q < e && *q == '-')
        q++;
    if (q >= e || !is_digit(*q))
        return false;
    if (*q == '0') {
        q++;
    } else {
        while (q < e && is_digit(*q))
            q++;
    }
    if (q < e && *q == '.') {
        q++;
        if (q >= e || !is_digit(*q))
            return false;
        while (q < e && is_digit(*q))
            q++;
    }
    if (q < e && (*q == 'e' || *q == 'E')) {
        q++;
        if (q < e && (*q == '+' || *q == '-'))
            q++;
        if (q >= e || !is_digit(*q))
            return false;
        while (q < e && is_digit(*q))
            q++;
    }
    if (q < e && !is_delim(*q))
        return false;
    t->s = l->p;
    t->len = (size_t)(q - l->p);
    l->p = q;
    return true;
}

static bool scan_literal(gs_jlex *l, const char *word)
{
    size_t n = strlen(word);
    if ((size_t)(l->end - l->p) < n || memcmp(l->p, word, n) != 0)
        return false;
    if (l->p + n < l->end && !is_delim(l->p[n]))
        return false;
    l->p += n;
    return true;
}

/* After a complete value: where the grammar goes next. */
static void value_done(gs_jlex *l)
{
    l->state = l->depth == 0 ? S_DONE : S_AFTER;
}

gs_jt gs_jlex_next(gs_jlex *l, gs_jtok *t)
{
    for (;;) {
        if (l->state == S_ERROR) {
            t->type = GS_JT_ERROR;
            t->s = l->p;
            t->len = 0;
            t->line = l->err_line;
            return GS_JT_ERROR;
        }
        skip_blanks(l);
        t->line = l->line;
        t->depth = l->depth;
        t->s = l->p;
        t->len = 1;
        if (l->state == S_DONE) {
            if (l->p < l->end)
                return fail(l, t, "unexpected text after the end of the document");
            t->type = GS_JT_EOF;
            t->len = 0;
            return GS_JT_EOF;
        }
        if (l->p >= l->end)
            return fail(l, t, l->depth == 0 && l->state == S_VALUE
                                  ? "empty document"
                                  : "unexpected end of file (truncated JSON)");
        char c = *l->p;

        if (l->state == S_AFTER) {
            char top = (char)l->stack[l->depth - 1];
            if (c == ',') {
                l->p++;
                l->state = top == 'o' ? S_KEY : S_VALUE;
                continue;
            }
            if ((c == '}' && top == 'o') || (c == ']' && top == 'a')) {
                l->p++;
                l->depth--;
                t->depth = l->depth;
                t->type = c == '}' ? GS_JT_OBJ_END : GS_JT_ARR_END;
                value_done(l);
                return t->type;
            }
            return fail(l, t, top == 'o' ? "expected ',' or '}'" : "expected ',' or ']'");
        }

        if (l->state == S_KEY_OR_END || l->state == S_KEY) {
            if (c == '}' && l->state == S_KEY_OR_END) {
                l->p++;
                l->depth--;
                t->depth = l->depth;
                t->type = GS_JT_OBJ_END;
                value_done(l);
                return GS_JT_OBJ_END;
            }
            if (c != '"')
                return fail(l, t, "expected a string key");
            const char *why = "bad string";
            if (!scan_string(l, t, &why))
                return fail(l, t, why);
            skip_blanks(l);
            if (l->p >= l->end || *l->p != ':')
                return fail(l, t, "expected ':' after a key");
            l->p++;
            l->state = S_VALUE;
            t->type = GS_JT_KEY;
            return GS_JT_KEY;
        }

        /* S_VALUE or S_VALUE_OR_END */
        if (c == ']' && l->state == S_VALUE_OR_END) {
            l->p++;
            l->depth--;
            t->depth = l->depth;
            t->type = GS_JT_ARR_END;
            value_done(l);
            return GS_JT_ARR_END;
        }
        if (c == '{' || c == '[') {
            if (l->depth >= GS_JSON_MAX_DEPTH)
                return fail(l, t, "nesting too deep");
            l->stack[l->depth++] = c == '{' ? 'o' : 'a';
            l->p++;
            l->state = c == '{' ? S_KEY_OR_END : S_VALUE_OR_END;
            t->type = c == '{' ? GS_JT_OBJ : GS_JT_ARR;
            return t->type;
        }
        if (c == '"') {
            const char *why = "bad string";
            if (!scan_string(l, t, &why))
                return fail(l, t, why);
            t->type = GS_JT_STR;
            value_done(l);
            return GS_JT_STR;
        }
        if (c == '-' || is_digit(c)) {
            if (!scan_number(l, t))
                return fail(l, t, "malformed number");
            t->type = GS_JT_NUM;
            value_done(l);
            return GS_JT_NUM;
        }
        if (c == 't' && scan_literal(l, "true")) {
            t->type = GS_JT_TRUE;
            t->len = 4;
            value_done(l);
            return GS_JT_TRUE;
        }
        if (c == 'f' && scan_literal(l, "false")) {
            t->type = GS_JT_FALSE;
            t->len = 5;
            value_done(l);
            return GS_JT_FALSE;
        }
        if (c == 'n' && scan_literal(l, "null")) {
            t->type = GS_JT_NULL;
            t->len = 4;
            value_done(l);
            return GS_JT_NULL;
        }
        return fail(l, t, "expected a value");
    }
}

bool gs_jlex_skip(gs_jlex *l, const gs_jtok *first)
{
    if (first->type == GS_JT_ERROR)
        return false;
    if (first->type != GS_JT_OBJ && first->type != GS_JT_ARR)
        return true;
    gs_jtok t;
    for (;;) {
        gs_jt k = gs_jlex_next(l, &t);
        if (k == GS_JT_ERROR || k == GS_JT_EOF)
            return false;
        if ((k == GS_JT_OBJ_END || k == GS_JT_ARR_END) && t.depth == first->depth)
            return true;
    }
}

bool gs_jtok_eq(const gs_jtok *t, const char *s)
{
    size_t n = strlen(s);
    return (t->type == GS_JT_STR || t->type == GS_JT_KEY) && t->len == n && memcmp(t->s, s, n) == 0;
}

bool gs_jtok_num(const gs_jtok *t, double *out)
{
    return t->type == GS_JT_NUM && gs_num_parse(t->s, t->len, out);
}
