/* The last resort for a C++ exception that nothing caught. The shims catch
 * what their libraries throw; this is for what they cannot reach: a thread of
 * a library's own, or a library's constructor run while ptr loads it (one
 * starts a thread there, and throws when it cannot). Such an exception cannot
 * be resumed from, but it can end the process as every other failure does:
 * one line, the documented code, no partial output, no core dump. */
#include "app/signals.h"
#include "base/shim_error.h"
#include "image/image.h"

#include <cstdio>
#include <exception>
#include <unistd.h>

namespace {

[[noreturn]] void on_terminate()
{
    PtrError err = {};
    if (std::current_exception())
        ptr_shim_caught(&err, PTR_ERR_INTERNAL, "in a library's code");
    else
        ptr_shim_error(&err, PTR_ERR_INTERNAL, "std::terminate called");
    std::fprintf(stderr, "ptr: %s\n", err.message);
    ptr_image_discard_partial();
    // Other threads may still run: exit() would run destructors under them.
    _exit(ptr_result_exit_code(err.code));
}

} // namespace

extern "C" void ptr_uncaught_install(void)
{
    std::set_terminate(on_terminate);
}
