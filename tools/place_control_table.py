#!/usr/bin/env python3
"""The table of scripts/bench_place_control.sh: per budget and path, the placed frames with the budget's impostors
and with none (median, max, frames over t_max), and how many impostors a frame drew.
Usage: tools/place_control_table.py OUT TMAX [TMAX ...]"""
import json
import os
import sys


def mode(run):
    with open(os.path.join(run, "bench.json")) as f:
        return json.load(f)["modes"]["placed"]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, budgets = sys.argv[1], sys.argv[2:]
    print("| t_max ms | path | with impostors: median / max ms, over t_max | none: median / max ms, over t_max | "
          "impostors drawn per frame | frames in a CPV |")
    print("|---:|---|---|---|---:|---:|")
    for t in budgets:
        for path in ("walk", "drive", "random"):
            runs = [os.path.join(out, f"control-{path}-t{t}-{db}") for db in (f"place-b2-t{t}", f"place-none-t{t}")]
            if not all(os.path.exists(os.path.join(r, "bench.json")) for r in runs):
                continue
            with_imp, none = (mode(r) for r in runs)
            info = with_imp["info"]
            frames = max(info.get("frames", 1.0), 1.0)
            print(f"| {t} | {path} | {with_imp['median_ms']:.1f} / {with_imp['max_ms']:.1f}, "
                  f"{with_imp['frames_over_tmax']} | {none['median_ms']:.1f} / {none['max_ms']:.1f}, "
                  f"{none['frames_over_tmax']} | {info.get('impostor_draws', 0.0) / frames:.2f} | "
                  f"{info.get('cpv_frames', 0.0) / frames:.0%} |")


if __name__ == "__main__":
    main()
