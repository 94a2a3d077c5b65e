#!/usr/bin/env python3
"""Frame times of a loaded machine rescaled to a quiet run's (scripts/bench_place.sh outputs): per path frame, the
placed time times the quiet run's full-geometry time of the same frame over this run's (full and placed are rendered
interleaved, so both see the same load). An estimate that assumes the load slows every mode alike; the measured
numbers stay the ones in tables.md.
Usage: tools/place_load_adjusted.py LOADED_OUT QUIET_OUT"""
import csv
import os
import re
import sys


def frames(path):
    out = {}
    for row in csv.DictReader(open(path)):
        out.setdefault(row["mode"], {})[int(row["path_frame"])] = float(row["wall_ms"])
    return out


def main(loaded, quiet):
    print("| path | t_max ms | full now / quiet (median) | placed at or under t_max, measured | load-adjusted |")
    print("|---|---|---|---|---|")
    for name in sorted(os.listdir(loaded)):
        m = re.match(r"bench-(\w+)-t(\d+)$", name)
        if not m:
            continue
        now_f = os.path.join(loaded, name, "frames.csv")
        quiet_f = os.path.join(quiet, name, "frames.csv")
        if not (os.path.isfile(now_f) and os.path.isfile(quiet_f)):
            continue
        now, before = frames(now_f), frames(quiet_f)
        t_max = float(m.group(2))
        keys = sorted(set(now["placed"]) & set(now["full"]) & set(before["full"]))
        ratios = sorted(now["full"][k] / before["full"][k] for k in keys)
        measured = sum(now["placed"][k] <= t_max for k in keys)
        adjusted = sum(now["placed"][k] * before["full"][k] / now["full"][k] <= t_max for k in keys)
        print("| %s | %s | %.2f | %d/%d | %d/%d |" % (m.group(1), m.group(2), ratios[len(ratios) // 2], measured,
                                                     len(keys), adjusted, len(keys)))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "out/bench/place")
