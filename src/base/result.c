#include "base/result.h"

#include <stdarg.h>
#include <stdio.h>

int ptr_result_exit_code(PtrResult result)
{
    switch (result) {
#define PTR_RESULT_EXIT(name, code, text) case name: return code;
    PTR_RESULT_MAP(PTR_RESULT_EXIT)
#undef PTR_RESULT_EXIT
    case PTR_RESULT_COUNT:
        break;
    }
    return 1;
}

const char *ptr_result_description(PtrResult result)
{
    switch (result) {
#define PTR_RESULT_TEXT(name, code, text) case name: return text;
    PTR_RESULT_MAP(PTR_RESULT_TEXT)
#undef PTR_RESULT_TEXT
    case PTR_RESULT_COUNT:
        break;
    }
    return "unknown error";
}

/* Length of the valid UTF-8 sequence at s, or 0 if it is not one. */
static size_t utf8_sequence(const unsigned char *s)
{
    size_t n = s[0] >= 0xf0 && s[0] <= 0xf4 ? 4 : s[0] >= 0xe0 ? 3 : s[0] >= 0xc2 ? 2 : 0;
    if (s[0] > 0xf4)
        return 0;
    for (size_t i = 1; i < n; i++)
        if ((s[i] & 0xc0) != 0x80)
            return 0;
    return n;
}

/* Messages quote parsers that quote the file, which may be binary garbage:
 * keep one line of printable text. */
static void sanitize_line(char *text)
{
    unsigned char *c = (unsigned char *)text;
    while (*c) {
        if (*c < 0x80) {
            if (*c < 0x20 || *c == 0x7f)
                *c = *c == '\n' || *c == '\r' || *c == '\t' ? ' ' : '?';
            c++;
            continue;
        }
        size_t n = utf8_sequence(c);
        if (n == 0)
            *c++ = '?';
        else
            c += n;
    }
}

PtrResult ptr_error_set(PtrError *err, PtrResult code, const char *fmt, ...)
{
    if (!err)
        return code;
    err->code = code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    sanitize_line(err->message);
    return code;
}
