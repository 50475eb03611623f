#!/bin/sh
# Installs the dependencies, then builds and runs the whole test suite three
# times: a Release build; the same build with the assembly intersectors
# disabled through PTR_CPUMASK=none; and a build under AddressSanitizer and
# UndefinedBehaviorSanitizer. Then fuzzes both importers for a minute each. On x86-64 the assembly is required: a build
# that silently fell back to C only would test less than it claims.
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
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== again with the assembly intersectors disabled (PTR_CPUMASK=none)"
PTR_CPUMASK=none ctest --test-dir build --output-on-failure -j "$jobs"

cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DPTR_SANITIZE=ON -DPTR_REQUIRE_ASM=$require_asm
cmake --build build-sanitize -j "$jobs"
ctest --test-dir build-sanitize --output-on-failure -j "$jobs"

echo "== fuzzing the importers, a minute each"
scripts/fuzz.sh 60
