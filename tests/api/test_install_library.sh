#!/bin/sh
# A program builds against an installed tree alone: `cmake --install` into a
# temporary prefix, then examples/render_spheres.c compiled with pkg-config
# (ptr.pc; shared, then static) and with CMake (find_package(ptr), ptr::ptr),
# each run from outside the build tree. The shared ones save a PNG, which
# needs the image module the library finds in PREFIX/lib/ptr from its own
# folder.
# Usage: test_install_library.sh CMAKE BUILD_DIR SOURCE_DIR C_COMPILER
set -u
cmake=$1 build=$2 src=$3 cc=$4
. "$src/tests/support/shell_test.sh"

prefix=$dir/prefix
"$cmake" --install "$build" --prefix "$prefix" >/dev/null || { echo "FAIL: cmake --install" >&2; exit 1; }
for file in include/ptr/ptr.h lib/libptr.so lib/libptr.a lib/pkgconfig/ptr.pc \
    lib/cmake/ptr/ptrConfig.cmake; do
    [ -f "$prefix/$file" ] || fail "$file not installed"
done
# The example, copied out of the source tree: nothing but the prefix is found.
mkdir "$dir/example"
cp "$src/examples/render_spheres.c" "$dir/example/"
cd "$dir/example" || exit 1

# check NAME COMMAND...: COMMAND prints the image's size and mean colour.
check() {
    name=$1
    shift
    "$@" >"$dir/out" 2>"$dir/err" || fail "$name: exit code $?: $(cat "$dir/err")"
    grep -q "^160x90, mean 0\.[0-9]* 0\.[0-9]* 0\.[0-9]*$" "$dir/out" ||
        fail "$name: printed '$(cat "$dir/out")'"
}

export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
# shellcheck disable=SC2046 # pkg-config's words are separate arguments
"$cc" -std=c11 -Wall -Wextra -pedantic -Werror render_spheres.c $(pkg-config --cflags --libs ptr) \
    -lm -Wl,-rpath,"$prefix/lib" -o shared || fail "pkg-config: the shared build failed"
check "pkg-config, shared" ./shared "$dir/shared.png" "$dir/shared.exr"
[ -s "$dir/shared.png" ] && [ -s "$dir/shared.exr" ] || fail "pkg-config, shared: no images"
# shellcheck disable=SC2046
"$cc" -std=c11 render_spheres.c $(pkg-config --cflags ptr) "$prefix/lib/libptr.a" \
    $(pkg-config --static --libs-only-other --libs-only-l ptr | sed 's/-lptr//') \
    -o static || fail "pkg-config: the static build failed"
cp "$dir/out" "$dir/shared.out"
check "pkg-config, static" ./static "$dir/static.exr"
cmp -s "$dir/shared.out" "$dir/out" || fail "static and shared differ: $(cat "$dir/out")"

mkdir cmake_project
cat >cmake_project/CMakeLists.txt <<CMAKE
cmake_minimum_required(VERSION 3.16)
project(render_spheres C)
find_package(ptr 0.1 REQUIRED)
add_executable(render_spheres ../render_spheres.c)
target_link_libraries(render_spheres PRIVATE ptr::ptr m)
CMAKE
"$cmake" -S cmake_project -B cmake_build -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" \
    >"$dir/cmake.log" 2>&1 && "$cmake" --build cmake_build >>"$dir/cmake.log" 2>&1 ||
    fail "CMake: the build failed: $(tail -5 "$dir/cmake.log")"
check "CMake" ./cmake_build/render_spheres "$dir/cmake.png"
[ -s "$dir/cmake.png" ] || fail "CMake: no image"
finish "render_spheres built against the installed tree with pkg-config and CMake"
