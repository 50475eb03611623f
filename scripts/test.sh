#!/bin/sh
# Installs the dependencies, then builds and runs the whole test suite, in a
# Release build and again under AddressSanitizer and UndefinedBehaviorSanitizer;
# in each, at this CPU's level, then with the assembly intersectors disabled
# (PTR_CPUMASK=none), then the tests whose code depends on the CPU level (ctest
# label cpu_level) at every level between. Then fuzzes both importers for a
# minute each. On x86-64 the assembly is required: a build that silently fell
# back to C only would test less than it claims. The last lines say which CPU
# levels the run covered and which ones this CPU cannot reach.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc)
case "$(uname -m)" in
    x86_64|amd64) require_asm=ON ;;
    *) require_asm=OFF ;;
esac

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPTR_REQUIRE_ASM=$require_asm
cmake --build build -j "$jobs"

# ptr's levels, lowest first; this CPU's own is the one --print-dispatch
# marks in use when nothing caps it.
native=$(env -u PTR_CPUMASK build/src/ptr --print-dispatch | sed -n 's/^\([a-z0-9]*\) .*<- in use.*/\1/p')
below=
above=
for level in $(build/src/ptr --print-dispatch | cut -d' ' -f1); do
    if [ "$level" = "$native" ]; then
        seen=1
    elif [ -n "${seen:-}" ]; then
        above="$above $level"
    else
        below="$below $level"
    fi
done

# Build $1's suite at this CPU's level, then at each level below: the whole
# suite again without the assembly (none), the level-dependent tests alone
# at the levels between.
suite_at_every_level() {
    echo "== $1: the whole suite at this CPU's level ($native)"
    ctest --test-dir "$1" --output-on-failure -j "$jobs"
    for level in $below; do
        if [ "$level" = none ]; then
            echo "== $1: the whole suite with the assembly disabled (PTR_CPUMASK=none)"
            PTR_CPUMASK=none ctest --test-dir "$1" --output-on-failure -j "$jobs"
        else
            echo "== $1: the CPU-level tests at PTR_CPUMASK=$level"
            PTR_CPUMASK=$level ctest --test-dir "$1" --output-on-failure -j "$jobs" -L cpu_level
        fi
    done
}

suite_at_every_level build
# GCC 12's sanitizer runtime (and LLVM's before 17) takes a thread's dynamic
# TLS block that happens to start 16 bytes into a page for a glibc 2.19
# header, reads the words before it as a range, and LeakSanitizer's tracer
# then dies of SIGSEGV at exit ("Tracer caught signal 11"), at random, after
# a test has passed (google/sanitizers#1322). glibc allocates those blocks
# with malloc, so without the interceptor they are still scanned as heap.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}intercept_tls_get_addr=0"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DPTR_SANITIZE=ON -DPTR_REQUIRE_ASM=$require_asm
cmake --build build-sanitize -j "$jobs"
suite_at_every_level build-sanitize

echo "== fuzzing the importers, a minute each"
scripts/fuzz.sh 60

echo "== CPU levels tested:$below $native"
echo "== CPU levels this CPU cannot reach, not tested here:${above:- none}"
