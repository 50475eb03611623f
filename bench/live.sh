#!/bin/sh
# What a live view costs the render: rays per second of renders without
# --live and of renders with --live and a page open, alternating run by run
# so that both see the same machine, then the median of each and their
# ratio. The page is a script that does what the page does (follows the
# event stream and fetches every new frame: tests/support/live_client.py),
# or with --browser, the page itself in headless Chromium on the same
# machine (its drawing competes with the render too).
# Usage: bench/live.sh PTR [RUNS] [--browser] [-- RENDER OPTIONS]
#   (from the source folder; default RUNS 7 and options
#    scenes/seed.gltf --width 500 --height 500 --samples 400)
set -eu
ptr=$1
shift
runs=7
browser=0
while [ $# -gt 0 ]; do
    case $1 in
        --browser) browser=1 ;;
        --) shift; break ;;
        *) runs=$1 ;;
    esac
    shift
done
[ $# -gt 0 ] || set -- scenes/seed.gltf --width 500 --height 500 --samples 400
exec python3 - "$ptr" "$runs" "$browser" "$@" <<'PY'
import json, os, statistics, sys, tempfile
sys.path.insert(0, "tests/support")
from live_client import Ptr, Page

ptr, runs, browser, args = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", sys.argv[4:]
web = None
if browser:
    sys.path.insert(0, "tests/live")
    import test_browser
    b, d, why = test_browser.find_browser()
    if why:
        sys.exit("bench/live.sh --browser: " + why)
    web = test_browser.start_browser(b, d)


def run(live, out):
    p = Ptr([ptr, *args, "-o", out, "--json", "--quiet"] + (["--live", "0"] if live else []))
    page = None
    frames = 0
    if live:
        url = p.url()
        if web:
            web.get(url)
        else:
            page = Page(url)
    if p.wait() != 0:
        sys.exit("ptr failed: " + p.stderr)
    if page:
        page.close()
        frames = len(page.frames)
    if web:
        frames = int(web.execute_script("return document.getElementById('image').dataset.frame"))
    return json.loads(p.stdout.splitlines()[-1])["rays_per_second"], frames


with tempfile.TemporaryDirectory() as d:
    plain, live, frames = [], [], []
    for i in range(runs):
        plain.append(run(False, os.path.join(d, "plain.exr"))[0])
        r, f = run(True, os.path.join(d, "live.exr"))
        live.append(r)
        frames.append(f)
        print("run %d: %.2f Mrays/s without --live, %.2f with a page open (%d frames)"
              % (i + 1, plain[-1] / 1e6, live[-1] / 1e6, f), flush=True)
if web:
    web.quit()
a, b = statistics.median(plain), statistics.median(live)
print("median: %.2f Mrays/s without --live, %.2f with a page open%s: ratio %.3f"
      % (a / 1e6, b / 1e6, " in Chromium" if browser else "", b / a))
PY
