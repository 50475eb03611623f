#!/usr/bin/env python3
"""Prints the table of `accuracy denoise`'s CSV as Markdown: for each scene
and sample count, the raw render's relative MSE and seconds, and each
quality's, with the factor by which it lowers the error; then, for each
quality, the first sample count at which the denoised image is no better
than the raw one (or that it stays better up to the largest count).

Usage: denoise_gain.py docs/denoise-accuracy.csv
"""
import csv
import sys


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    qualities = [m for m in dict.fromkeys(r["method"] for r in rows) if m != "raw"]
    print("| scene | spp | raw: rel. MSE, s | " +
          " | ".join(f"{q}: rel. MSE, s, gain" for q in qualities) + " |")
    print("| --- | ---: | ---: |" + " ---: |" * len(qualities))
    crossings = []
    for scene in scenes:
        point = {(r["method"], int(r["spp"])): r for r in rows if r["scene"] == scene}
        counts = sorted({spp for _, spp in point})
        for spp in counts:
            raw = point[("raw", spp)]
            cells = [f"{float(raw['relmse']):.3g}, {float(raw['seconds']):.2f}"]
            for q in qualities:
                r = point[(q, spp)]
                gain = float(raw["relmse"]) / float(r["relmse"])
                cells.append(f"{float(r['relmse']):.3g}, {float(r['seconds']):.2f}, {gain:.1f}x")
            print(f"| {scene} | {spp} | " + " | ".join(cells) + " |")
        for q in qualities:
            worse = [spp for spp in counts
                     if float(point[(q, spp)]["relmse"]) >= float(point[("raw", spp)]["relmse"])]
            crossings.append(f"{scene}, {q}: " + (f"no better from {worse[0]} spp" if worse else
                                                  f"better up to {counts[-1]} spp"))
    print()
    for line in crossings:
        print(line)


if __name__ == "__main__":
    main()
