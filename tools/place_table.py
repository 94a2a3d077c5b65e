#!/usr/bin/env python3
"""Tables of scripts/bench_place.sh: placement rows (as Jeschke et al. 2005, Table 1) and, per frame budget and path,
the walkthrough's frame times against t_max with the image error against full geometry."""
import json
import os
import re
import sys


def disk_bytes(directory):
    return sum(os.path.getsize(os.path.join(root, f)) for root, _, files in os.walk(directory) for f in files)


def placement_rows(out):
    rows = []
    for name in sorted(os.listdir(out)):
        index = os.path.join(out, name, "placement.json")
        if not name.startswith("place-") or not os.path.isfile(index):
            continue
        d = json.load(open(index))
        s, o = d["summary"], d["options"]
        wall = open(os.path.join(out, name + ".time")).read().split(",")[0] if os.path.isfile(
            os.path.join(out, name + ".time")) else "?"
        fallback = "%d / %d" % (s["unsolved_at_bound"], s["fallback_impostors"]) if o.get("fallback_bound_factors") else "-"
        rows.append("| %s | %.0f | %.0f | %d | %d | %d | %s | %d | %.1f | %.1f | %d | %.1f | %.1f | %.1f | %.1f | %s |" % (
            name, o["t_max_ms"], o["error_px"], s["cpvs"], s["candidates_kept"] - s["candidates_unplannable"],
            s["impostors"], fallback, s["unsolved_cpvs"], s["memory_bytes"] / 2**20, disk_bytes(os.path.join(out, name)) / 2**20,
            s["impostors_freed"], s["visibility_s"] if s.get("visibility_cached", 0) == 0 else float("nan"), s["view_space_s"] - s["visibility_s"], s["candidates_s"],
            s["greedy_s"] + s["capture_s"], wall))
    head = ("| run | t_max ms | bound px | CPVs | candidates | impostors | over t_max at the bound / fallback impostors | "
            "unsolved CPVs | GPU MB | disk MB | freed | visibility s (nan: cached) | view space s | candidates s | "
            "greedy + capture s | wall |\n|" + "---|" * 16)
    return head + "\n" + "\n".join(rows)


def bench_rows(out):
    rows = []
    for name in sorted(os.listdir(out)):
        m = re.match(r"bench-(\w+)-t(\d+)$", name)
        f = os.path.join(out, name, "bench.json")
        if not m or not os.path.isfile(f):
            continue
        d = json.load(open(f))
        for mode in ("full", "culled", "placed"):
            r = d["modes"].get(mode)
            if not r:
                continue
            n = len(d["frames"]) if isinstance(d["frames"], list) else d["frames"]
            rows.append("| %s | %s | %s | %.1f | %.1f | %.1f | %s/%s | %.0f%% | %.2fx | %s | %s | %s | %s |" % (
                m.group(1), m.group(2), mode, r["median_ms"], r["p99_ms"], r["max_ms"], r["frames_over_tmax"], n,
                100.0 * (n - r["frames_over_tmax"]) / max(n, 1),
                r["speedup_vs_full"],
                "%.1f" % r["psnr_db_mean"] if r.get("psnr_db_mean") is not None else "-",
                "%.3f%%" % (100 * r["crack_share_mean"]) if r.get("crack_share_mean") is not None else "-",
                "%.2f" % r["parallax_p99_px_max"] if r.get("parallax_p99_px_max") is not None else "-",
                "%s" % r["frames_over_bound"] if r.get("frames_over_bound") is not None else "-"))
    head = ("| path | t_max ms | mode | median ms | p99 ms | max ms | frames over t_max | at or under t_max | "
            "speedup vs full | PSNR dB | cracks | parallax p99 max px | frames over bound |\n|" + "---|" * 13)
    return head + "\n" + "\n".join(rows)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "out/bench/place"
    text = "### Placement\n\n" + placement_rows(out) + "\n\n### Walkthroughs\n\n" + bench_rows(out) + "\n"
    open(os.path.join(out, "tables.md"), "w").write(text)
    print(text)
