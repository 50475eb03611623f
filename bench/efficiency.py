#!/usr/bin/env python3
"""Prints the efficiency table of `accuracy estimators`' CSV as Markdown: for
each scene and sample count, each estimator's time, RMSE and efficiency
1 / (MSE x time) relative to the first estimator (independent numbers without
light sampling).

Usage: efficiency.py docs/estimators.csv [SPP...]   (default 64 256)
"""
import csv
import sys


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    counts = sys.argv[2:] or ["64", "256"]
    print("| scene | spp | estimator | seconds | RMSE | relative MSE | efficiency |")
    print("| --- | ---: | --- | ---: | ---: | ---: | ---: |")
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for spp in counts:
            point = [r for r in rows if r["scene"] == scene and r["spp"] == spp]
            if not point:
                continue
            base = 1 / (float(point[0]["rmse"]) ** 2 * float(point[0]["seconds"]))
            for r in point:
                eff = 1 / (float(r["rmse"]) ** 2 * float(r["seconds"])) / base
                print(f"| {scene} | {spp} | {r['method']} | {float(r['seconds']):.2f} | "
                      f"{float(r['rmse']):.4f} | {float(r['relmse']):.4f} | {eff:.2f} |")


if __name__ == "__main__":
    main()
