#!/usr/bin/env python3
"""Tables of scripts/bench_bound.sh: one row per path, bound and mode from OUT/bench-PATH-BOUND/bench.json, with the
impostor store's size on disk. Usage: tools/bound_table.py OUT [OUT...]"""
import json
import os
import sys


def store_bytes(path):
    total = 0
    for root, _, files in os.walk(path):
        total += sum(os.path.getsize(os.path.join(root, f)) for f in files)
    return total


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def rows(out):
    city = os.path.basename(os.path.normpath(out))
    for path in ("drive", "walk"):
        for bound in (10, 5, 2, 1):
            bench = os.path.join(out, "bench-%s-%d" % (path, bound), "bench.json")
            if not os.path.exists(bench):
                continue
            j = json.load(open(bench))
            modes = j["modes"]
            # "vs culled" divides by the frustum-only culling of the earlier runs when the run has it (mode
            # "frustum"), so rows stay comparable; "culled" (occlusion culling) is then a row of its own.
            base = "frustum" if "frustum" in modes else "culled"
            full, culled = modes["full"]["median_ms"], modes[base]["median_ms"]
            store = os.path.join(out, "imp-%s-%d" % (path, 10 if bound >= 5 else 2))
            for name in ("frustum", "culled", "smi", "mmi"):
                m = modes.get(name)
                if m is None:
                    continue
                info = m.get("info", {})
                over = m.get("frames_over_bound")
                checked = m.get("frames_checked_against_bound", 0)
                yield "| %s | %s | %d | %s | %.1f | %.1f | %.2fx | %.2fx | %s | %.3f%% | %s / %s | %s | %s | %s |" % (
                    city, path, bound, name, m["median_ms"], m["p99_ms"], full / m["median_ms"], culled / m["median_ms"],
                    fmt(m.get("psnr_db_mean"), ".1f"), 100.0 * (m.get("crack_share_mean") or 0.0),
                    fmt(m.get("parallax_p99_px_mean"), ".2f"), fmt(m.get("parallax_p99_px_max"), ".1f"),
                    "-" if name in ("frustum", "culled") else "%s of %d" % (over, checked),
                    fmt(m.get("mean_triangles"), ",.0f"),
                    "-" if name in ("frustum", "culled") else "%.1f MB" % (store_bytes(store) / 1e6))


def main():
    print("| city | path | bound px | mode | median ms | p99 ms | vs full | vs culled | PSNR dB | cracks | "
          "parallax p99 mean / max px | frames over bound | triangles drawn | store |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for out in sys.argv[1:]:
        for row in rows(out):
            print(row)


if __name__ == "__main__":
    main()
