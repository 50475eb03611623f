#!/bin/sh
# What a live view costs the render: rays per second of renders without
# --live and of renders with --live and a page open, alternating run by run
# so that both see the same machine; the ratio of each pair (with a page
# over without) and their median, and the same for the CPU time the process
# took (user + system: the encoder's work shows there even on a machine
# whose load from elsewhere makes wall times vary), and the share of that
# CPU time the live view's own threads took (the encoder, the server's:
# read from /proc while ptr runs), the cost that does not depend on the
# machine's other load. The page is a script that does what the page does (follows the
# event stream and fetches every new frame: tests/support/live_client.py),
# or with --browser, the page itself in headless Chromium on the same
# machine (its drawing competes with the render too; Chromium stays open on
# an empty page during the renders without --live: it costs a core 5% idle).
# With --preview, the page has its denoised preview on (/denoise?on=1)
# before the render's first pass: the ratios then say what the live view
# costs with its preview (whose thread, ptr-live-oidn, counts among the live
# view's), and each run says how many denoised frames the page got.
# Usage: bench/live.sh PTR [RUNS] [--browser] [--preview] [-- RENDER OPTIONS]
#   (from the source folder; default RUNS 7 and options
#    scenes/seed.gltf --width 500 --height 500 --samples 400)
set -eu
ptr=$1
shift
runs=7
browser=0
preview=0
while [ $# -gt 0 ]; do
    case $1 in
        --browser) browser=1 ;;
        --preview) preview=1 ;;
        --) shift; break ;;
        *) runs=$1 ;;
    esac
    shift
done
[ $# -gt 0 ] || set -- scenes/seed.gltf --width 500 --height 500 --samples 400
python=python3
# Debian's python3-selenium is for Debian's python3.
[ $browser = 0 ] || [ ! -x /usr/bin/python3 ] || python=/usr/bin/python3
exec $python - "$ptr" "$runs" "$browser" "$preview" "$@" <<'PY'
import glob, json, os, resource, statistics, sys, tempfile, threading, time
sys.path.insert(0, "tests/support")
from live_client import Ptr, Page, get

ptr, runs, browser, preview = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", sys.argv[4] == "1"
args = sys.argv[5:]
web = None
if browser:
    sys.path.insert(0, "tests/live")
    import test_browser
    b, d, why = test_browser.find_browser()
    if why:
        sys.exit("bench/live.sh --browser: " + why)
    web = test_browser.start_browser(b, d)


def cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def thread_cpu(pid, seen):
    """Polls the CPU time (ticks) of each of pid's threads until it ends:
    seen[tid] = (name, ticks)."""
    while True:
        tasks = glob.glob("/proc/%d/task/*" % pid)
        if not tasks:
            return
        for task in tasks:
            try:
                stat = open(task + "/stat").read()
                name = stat[stat.index("(") + 1:stat.rindex(")")]
                fields = stat[stat.rindex(")") + 2:].split()
                seen[task] = (name, int(fields[11]) + int(fields[12]))
            except (OSError, ValueError):
                pass
        time.sleep(0.05)


def run(live, out):
    if web and not live:
        web.get("about:blank")  # the browser runs in both: what the page costs, not Chromium
    before = cpu()
    p = Ptr([ptr, *args, "-o", out, "--json", "--quiet"] + (["--live", "0"] if live else []))
    page = None
    frames = denoised = 0
    seen = {}
    poller = threading.Thread(target=thread_cpu, args=(p.process.pid, seen), daemon=True)
    poller.start()
    if live:
        url = p.url()
        if preview:
            get(url, "/denoise?on=1")
        if web:
            web.get(url)
        else:
            page = Page(url)
    if p.wait() != 0:
        sys.exit("ptr failed: " + p.stderr)
    seconds = cpu() - before
    poller.join(5)
    total = sum(t for _, t in seen.values())
    mine = sum(t for name, t in seen.values() if name.startswith(("ptr-live", "MHD")))
    share = mine / total if total else 0
    if page:
        page.close()
        frames = len(page.frames)
        denoised = sum(1 for f in page.frames if f[2])
    if web:
        frames = web.execute_script("const e = document.getElementById('image');"
                                    "return e ? Number(e.dataset.frame) : 0")
    rays = json.loads(p.stdout.splitlines()[-1])["rays_per_second"]
    shown = "%d frames" % frames + (", %d denoised" % denoised if page and preview else "")
    return rays, shown, seconds, share


with tempfile.TemporaryDirectory() as d:
    speed, cpu_ratio, shares = [], [], []
    for i in range(runs):
        r0, _, c0, _ = run(False, os.path.join(d, "plain.exr"))
        r1, f, c1, share = run(True, os.path.join(d, "live.exr"))
        speed.append(r1 / r0)
        cpu_ratio.append(c0 / c1)
        shares.append(share)
        print("run %d: %.2f Mrays/s and %.2f CPU s without --live, %.2f Mrays/s and %.2f CPU s "
              "with a page open (%s, %.1f%% of the CPU time in the live view's threads): "
              "ratios %.3f, %.3f" % (i + 1, r0 / 1e6, c0, r1 / 1e6, c1, f, 100 * share,
                                     speed[-1], cpu_ratio[-1]), flush=True)
if web:
    web.quit()
print("median of %d pairs, with a page open%s%s over without --live: rays per second %.3f, "
      "CPU time (inverse) %.3f; the live view's threads took %.1f%% of ptr's CPU time"
      % (runs, " in Chromium" if browser else "", ", its preview on," if preview else "",
         statistics.median(speed),
         statistics.median(cpu_ratio), 100 * statistics.median(shares)))
PY
