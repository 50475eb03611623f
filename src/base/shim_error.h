/* For the C++ shims behind ptr's C interfaces: errors cross into C as a
 * PtrError, a result code and one line of text. Header-only, so that the
 * image module, a shared object of its own, needs nothing from ptr's
 * libraries. */
#ifndef PTR_SHIM_ERROR_H
#define PTR_SHIM_ERROR_H

#ifndef __cplusplus
#error "shim_error.h is for the C++ shims"
#endif

#include <cerrno>
#include <cstdio>
#include <new>
#include <string>
#include <system_error>

#include "base/result.h"

/* Sets err to code and text as one line (line breaks folded, trailing blanks
 * cut). Returns code. */
inline PtrResult ptr_shim_error(PtrError *err, PtrResult code, std::string text)
{
    if (!err)
        return code;
    for (char &c : text)
        if (c == '\n' || c == '\r')
            c = ' ';
    while (!text.empty() && text.back() == ' ')
        text.pop_back();
    err->code = code;
    std::snprintf(err->message, sizeof err->message, "%s", text.c_str());
    return code;
}

/* For a catch (...) block: fills err from the exception being handled,
 * "CONTEXT: what it says". Memory that could not be had (std::bad_alloc, or
 * a thread refused for want of memory) is PTR_ERR_NOMEM, whatever the shim
 * was doing; anything else is code. Returns the code set. */
inline PtrResult ptr_shim_caught(PtrError *err, PtrResult code, const std::string &context)
{
    try {
        throw;
    } catch (const std::bad_alloc &) {
        return ptr_shim_error(err, PTR_ERR_NOMEM, context + ": out of memory");
    } catch (const std::system_error &e) {
        const std::error_category &category = e.code().category();
        const int value = e.code().value();
        const bool is_errno = category == std::generic_category() ||
                              category == std::system_category();
        if (is_errno && (value == ENOMEM || value == EAGAIN))
            return ptr_shim_error(err, PTR_ERR_NOMEM,
                                  context + ": out of memory (" + e.what() + ")");
        return ptr_shim_error(err, code, context + ": " + e.what());
    } catch (const std::exception &e) {
        return ptr_shim_error(err, code, context + ": " + e.what());
    } catch (...) {
        return ptr_shim_error(err, code, context + ": unexpected error");
    }
}

#endif /* PTR_SHIM_ERROR_H */
