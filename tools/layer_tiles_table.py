#!/usr/bin/env python3
"""The tables of scripts/bench_layer_tiles.sh: per budget, placement with the layers' fill charged over their tiles and
over whole quads (CPVs, left unsolved by the model, impostors, GPU MB, seconds), then per path the placed frames of
each database drawn its way (median, p99, max, frames over t_max; the tiles run's image error against full geometry).
Usage: tools/layer_tiles_table.py OUT TMAX [TMAX ...]"""
import json
import os
import sys


def load(path):
    with open(path) as f:
        return json.load(f)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, budgets = sys.argv[1], sys.argv[2:]
    print("| t_max ms | layers charged over | CPVs | unsolved by the model | impostors (fallback) | GPU MB | "
          "candidates s | greedy + capture s |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    for t in budgets:
        for kind in ("tiles", "whole"):
            dbs = [d for d in os.listdir(out) if d.startswith(f"lt-{kind}-b") and d.endswith(f"-t{t}")]
            if not dbs or not os.path.exists(os.path.join(out, dbs[0], "placement.json")):
                continue
            s = load(os.path.join(out, dbs[0], "placement.json"))["summary"]
            print(f"| {t} | {'tiles' if kind == 'tiles' else 'whole quads'} | {s['cpvs']:,} | {s['unsolved_cpvs']:,} | "
                  f"{s['impostors']:,} ({s['fallback_impostors']:,}) | {s['memory_bytes'] / 2**20:.1f} | "
                  f"{s['candidates_s']:.1f} | {s['greedy_s'] + s['capture_s']:.1f} |")
    print()
    print("| t_max ms | path | tiles: median / p99 / max ms, over t_max | whole quads: median / p99 / max ms, over "
          "t_max | impostors drawn per frame | tiles: PSNR dB, cracks, frames over the bound |")
    print("|---:|---|---|---|---:|---|")
    for t in budgets:
        for path in ("walk", "drive", "random"):
            runs = {k: os.path.join(out, f"lt-bench-{path}-t{t}-{k}", "bench.json") for k in ("tiles", "whole")}
            if not all(os.path.exists(p) for p in runs.values()):
                continue
            tiles, whole = (load(runs[k])["modes"]["placed"] for k in ("tiles", "whole"))
            info = tiles["info"]
            frames = max(info.get("frames", 1.0), 1.0)
            error = "-"
            if tiles.get("psnr_db_mean") is not None:
                error = (f"{tiles['psnr_db_mean']:.1f}, {100 * tiles['crack_share_mean']:.3f} %, "
                         f"{tiles.get('frames_over_bound', '-')}")
            print(f"| {t} | {path} | {tiles['median_ms']:.1f} / {tiles['p99_ms']:.1f} / {tiles['max_ms']:.1f}, "
                  f"{tiles['frames_over_tmax']} | {whole['median_ms']:.1f} / {whole['p99_ms']:.1f} / "
                  f"{whole['max_ms']:.1f}, {whole['frames_over_tmax']} | "
                  f"{info.get('impostor_draws', 0.0) / frames:.2f} | {error} |")


if __name__ == "__main__":
    main()
