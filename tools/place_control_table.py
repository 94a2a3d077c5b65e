#!/usr/bin/env python3
"""The table of scripts/bench_place_control.sh: per budget and path, the placed frames with the budget's impostors
and with none (median, max, frames over t_max), and how many impostors a frame drew.
Usage: tools/place_control_table.py OUT TMAX [TMAX ...]"""
import glob
import json
import os
import sys


def mode(bench_json):
    with open(bench_json) as f:
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
            # The budget's database at whichever bound the script was given (place-bB-tT), and the one without.
            placed = sorted(glob.glob(os.path.join(out, f"control-{path}-t{t}-place-b*-t{t}", "bench.json")))
            none = os.path.join(out, f"control-{path}-t{t}-place-none-t{t}", "bench.json")
            if not placed or not os.path.exists(none):
                continue
            with_imp, none = mode(placed[0]), mode(none)
            info = with_imp["info"]
            frames = max(info.get("frames", 1.0), 1.0)
            print(f"| {t} | {path} | {with_imp['median_ms']:.1f} / {with_imp['max_ms']:.1f}, "
                  f"{with_imp['frames_over_tmax']} | {none['median_ms']:.1f} / {none['max_ms']:.1f}, "
                  f"{none['frames_over_tmax']} | {info.get('impostor_draws', 0.0) / frames:.2f} | "
                  f"{info.get('cpv_frames', 0.0) / frames:.0%} |")


if __name__ == "__main__":
    main()
