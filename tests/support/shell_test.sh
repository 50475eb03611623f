# What the shell tests share, sourced once they have read their arguments: a
# scratch folder $dir removed on exit; fail MESSAGE, which reports a failure
# and makes the test fail at the end; finish SUMMARY, which ends the test,
# saying SUMMARY if nothing failed; wait_until COMMAND, which waits (up to
# 60 s) until COMMAND succeeds.
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failed=0
fail() { echo "FAIL: $1" >&2; failed=1; }
finish() {
    [ $failed = 0 ] && echo "$1"
    exit $failed
}
wait_until() {
    i=0
    while ! eval "$1"; do
        i=$((i + 1))
        [ $i -gt 600 ] && return 1
        sleep 0.1
    done
}
