#!/bin/sh
# Fuzzes the glTF, OBJ and structure (PDB, mmCIF) importers with libFuzzer under AddressSanitizer and
# UndefinedBehaviorSanitizer, each for SECONDS (default 60), starting from the
# test fixtures and the hostile corpus. A crash leaves crash-* files in
# build-fuzz/ and fails; add such a file to tests/fixtures/hostile/ (and fix
# the importer) so that the ordinary suite keeps it fixed.
# The seed is fixed (FUZZ_SEED, default 1) so that a run can be repeated.
# Usage: scripts/fuzz.sh [SECONDS]
set -eu
cd "$(dirname "$0")/.."
seconds=${1:-60}
if ! command -v clang >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
    run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
    run apt-get update -qq
    DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends \
        clang libclang-rt-14-dev >/dev/null
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPTR_FUZZ=ON \
    -DPTR_BUILD_TESTS=OFF >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target fuzz_gltf fuzz_obj fuzz_structure >/dev/null

for format in gltf obj structure; do
    corpus=build-fuzz/corpus-$format
    mkdir -p "$corpus"
    case $format in
    gltf) find tests/fixtures scenes -name '*.gltf' -o -name '*.glb' | xargs -I{} cp {} "$corpus"/ ;;
    obj) find tests/fixtures -name '*.obj' -size -200k -o -name '*.mtl' | xargs -I{} cp {} "$corpus"/ ;;
    structure) find tests/fixtures \( -name '*.pdb' -o -name '*.cif' -o -name '*.gz' \) -size -64k |
        xargs -I{} cp {} "$corpus"/
        head -c 60000 scenes/1tii.pdb >"$corpus"/1tii_head.pdb
        head -c 60000 tests/fixtures/structures/1tii.cif >"$corpus"/1tii_head.cif
        # The assemblies' tables come before the atoms in both; whole lines.
        head -c 60000 tests/fixtures/structures/assembly.pdb | sed '$d' >"$corpus"/assembly_head.pdb
        head -c 60000 tests/fixtures/structures/assembly.cif | sed '$d' >"$corpus"/assembly_head.cif ;;
    esac
    echo "== fuzz_$format, $seconds s"
    (cd build-fuzz && ASAN_OPTIONS=detect_leaks=1:intercept_tls_get_addr=0 tests/fuzz/fuzz_$format -max_total_time="$seconds" \
        -seed="${FUZZ_SEED:-1}" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
        "corpus-$format" \
        2>"fuzz_$format.log") || { tail -40 "build-fuzz/fuzz_$format.log"; exit 1; }
    grep -E "^Done|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb" \
        "build-fuzz/fuzz_$format.log"
done
