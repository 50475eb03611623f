#include "result.h"

#include <stdarg.h>
#include <stdio.h>

int ptr_result_exit_code(PtrResult result)
{
    switch (result) {
#define PTR_RESULT_EXIT(name, code, text) case name: return code;
    PTR_RESULT_MAP(PTR_RESULT_EXIT)
#undef PTR_RESULT_EXIT
    }
    return 1;
}

const char *ptr_result_description(PtrResult result)
{
    switch (result) {
#define PTR_RESULT_TEXT(name, code, text) case name: return text;
    PTR_RESULT_MAP(PTR_RESULT_TEXT)
#undef PTR_RESULT_TEXT
    }
    return "unknown error";
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
    for (char *c = err->message; *c; c++)
        if (*c == '\n' || *c == '\r' || *c == '\t')
            *c = ' ';
    return code;
}
