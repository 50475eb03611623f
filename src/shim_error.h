/* For the C++ shims behind ptr's C interfaces: errors cross into C as one
 * line of text in a caller's buffer. */
#ifndef PTR_SHIM_ERROR_H
#define PTR_SHIM_ERROR_H

#ifndef __cplusplus
#error "shim_error.h is for the C++ shims"
#endif

#include <cstddef>
#include <cstdio>
#include <string>

/* Copies text into err as one line: line breaks folded, trailing blanks cut. */
inline void ptr_shim_error(char *err, std::size_t size, std::string text)
{
    if (!err || size == 0)
        return;
    for (char &c : text)
        if (c == '\n' || c == '\r')
            c = ' ';
    while (!text.empty() && text.back() == ' ')
        text.pop_back();
    std::snprintf(err, size, "%s", text.c_str());
}

#endif /* PTR_SHIM_ERROR_H */
