#!/bin/sh
# libptr exports the functions of include/ptr/ptr.h and nothing else: the
# internal functions, named ptr_* too, stay hidden in libptr.so (its dynamic
# symbols, the version node aside) and local in libptr.a (whose other
# global symbols are only the C++ library's weak template instances).
# Usage: check_exports.sh SOURCE_DIR LIBPTR_SO LIBPTR_A
set -u
src=$1 so=$2 archive=$3
. "$src/tests/support/shell_test.sh"

# Every PTR_PUBLIC declaration's name: the word before its "(".
sed -n 's/^PTR_PUBLIC [^(]*[ *]\(ptr_[a-z0-9_]*\)(.*/\1/p' "$src/include/ptr/ptr.h" | sort \
    > "$dir/declared"
[ -s "$dir/declared" ] || fail "no PTR_PUBLIC function found in ptr.h"
nm -D --defined-only "$so" | awk '$3 != "PTR_1" { sub(/@.*/, "", $3); print $3 }' | sort \
    > "$dir/exported"
diff "$dir/declared" "$dir/exported" > "$dir/so.diff" ||
    fail "libptr.so exports other than ptr.h's functions: $(cat "$dir/so.diff")"
nm --defined-only -g "$archive" | awk 'NF == 3 && $2 ~ /^[A-UX-Z]$/ { print $3 }' | sort -u \
    > "$dir/archived"
diff "$dir/declared" "$dir/archived" > "$dir/a.diff" ||
    fail "libptr.a has other strong global symbols than ptr.h's functions: $(cat "$dir/a.diff")"
# The SONAME carries the API version.
version=$(sed -n 's/^#define PTR_API_VERSION \([0-9]*\)$/\1/p' "$src/include/ptr/ptr.h")
objdump -p "$so" | grep -q "SONAME *libptr.so.$version\$" ||
    fail "libptr.so's SONAME is not libptr.so.$version"
finish "libptr exports the $(wc -l < "$dir/declared") functions of ptr.h alone"
