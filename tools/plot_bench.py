#!/usr/bin/env python3
"""Plots of a `farfield bench` run: reads OUTDIR/frames.csv, writes PNGs into OUTDIR.

  frame_time.png  wall-clock frame time per frame, one line per mode (GPU time dashed when measured)
  error.png       PSNR and share of bad pixels per frame, one line per mode (only with --reference runs)
  parallax.png    parallax error (99th percentile, pixels) per frame, for the modes where it was measured, with the
                  error bound of each mode that has one (bench.json) and the frames over it marked
  popping.png     popping per frame (the mode's image change beyond the reference's, 8-bit units; --reference runs)

Usage: plot_bench.py OUTDIR
Exit codes: 0 plots written, 2 bad input (missing or malformed frames.csv), 3 matplotlib not available.
"""

import csv
import math
import os
import sys


def read_frames(path):
    """Rows of frames.csv grouped by mode, in file order: {mode: {"frame": [...], "wall_ms": [...], ...}}."""
    numeric = ["frame", "path_frame", "wall_ms", "gpu_ms", "triangles", "draw_calls", "objects",
               "psnr_db", "ssim", "bad_pixel_share", "parallax_p99_px", "popping", "governor_level", "predicted_ms",
               "corrected_ms", "bound_scale"]
    modes = {}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [k for k in ["frame", "mode", "wall_ms"] if k not in (reader.fieldnames or [])]
        if missing:
            raise ValueError("%s: missing columns %s" % (path, ", ".join(missing)))
        for line, row in enumerate(reader, start=2):
            series = modes.setdefault(row["mode"], {k: [] for k in numeric})
            for k in numeric:
                text = row.get(k, "")
                if text is None or text == "":
                    series[k].append(math.nan)
                    continue
                try:
                    series[k].append(float(text))
                except ValueError:
                    raise ValueError("%s: line %d: column %s: '%s' is not a number" % (path, line, k, text))
    return modes


def has_values(values):
    return any(not math.isnan(v) for v in values)


def x_of(series):
    """Camera-path frame numbers (frames.csv's path_frame), else the measured frame index."""
    return series["path_frame"] if has_values(series["path_frame"]) else series["frame"]


def main(argv):
    if len(argv) != 2:
        print("usage: plot_bench.py OUTDIR", file=sys.stderr)
        return 2
    out_dir = argv[1]
    csv_path = os.path.join(out_dir, "frames.csv")
    if not os.path.exists(csv_path):
        print("plot_bench.py: %s: no such file" % csv_path, file=sys.stderr)
        return 2
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import MaxNLocator
    except ImportError:
        print("plot_bench.py: matplotlib is not installed for %s" % sys.executable, file=sys.stderr)
        return 3
    try:
        modes = read_frames(csv_path)
    except (ValueError, OSError) as e:
        print("plot_bench.py: %s" % e, file=sys.stderr)
        return 2
    if not modes:
        print("plot_bench.py: %s has no frames" % csv_path, file=sys.stderr)
        return 2

    threshold, cap, bounds, t_max = 8, 99, {}, None
    try:
        import json
        with open(os.path.join(out_dir, "bench.json")) as f:
            info = json.load(f)
        threshold = info.get("bad_pixel_threshold", threshold)
        cap = info.get("psnr_cap_db", cap)
        for m in (info.get("modes") or {}).values():
            if isinstance(m, dict) and isinstance(m.get("t_max_ms"), (int, float)):
                t_max = float(m["t_max_ms"])
        for name, m in (info.get("modes") or {}).items():
            if isinstance(m, dict) and isinstance(m.get("error_bound_px"), (int, float)):
                bounds[name] = float(m["error_bound_px"])
    except (OSError, ValueError, AttributeError):
        pass  # bench.json is optional here: the labels fall back to the defaults, no bound lines

    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]

    fig, ax = plt.subplots(figsize=(10, 4.5))
    for i, (name, s) in enumerate(modes.items()):
        color = colors[i % len(colors)]
        ax.plot(x_of(s), s["wall_ms"], label=name + " wall", color=color, linewidth=1.2)
        if has_values(s["gpu_ms"]) and any(v > 0 for v in s["gpu_ms"] if not math.isnan(v)):
            ax.plot(x_of(s), s["gpu_ms"], label=name + " GPU", color=color, linewidth=0.8, linestyle="--")
    ax.set_xlabel("camera path frame")
    ax.set_ylabel("frame time (ms)")
    ax.set_title("Frame time per frame")
    ax.set_ylim(bottom=0)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "frame_time.png"), dpi=110)
    plt.close(fig)
    written = ["frame_time.png"]

    if any(has_values(s["psnr_db"]) for s in modes.values()):
        fig, (ax_psnr, ax_bad) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True)
        for i, (name, s) in enumerate(modes.items()):
            color = colors[i % len(colors)]
            if has_values(s["psnr_db"]):
                ax_psnr.plot(x_of(s), s["psnr_db"], label=name, color=color, linewidth=1.2)
                ax_bad.plot(x_of(s), [100.0 * v for v in s["bad_pixel_share"]], label=name, color=color,
                            linewidth=1.2)
        ax_psnr.set_ylabel("PSNR (dB, %g = identical)" % cap)
        ax_psnr.set_title("Image error against the full-geometry reference")
        ax_psnr.grid(True, alpha=0.3)
        ax_psnr.legend(fontsize="small")
        ax_bad.set_xlabel("camera path frame")
        ax_bad.set_ylabel("pixels off by > %d/255 (%%)" % threshold)
        ax_bad.set_ylim(bottom=0)
        ax_bad.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax_bad.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, "error.png"), dpi=110)
        plt.close(fig)
        written.append("error.png")

    measured = {name: s for name, s in modes.items() if has_values(s["parallax_p99_px"])}
    if measured:
        fig, ax = plt.subplots(figsize=(10, 4.0))
        for i, (name, s) in enumerate(modes.items()):
            if name in measured:
                color = colors[i % len(colors)]
                ax.plot(x_of(s), s["parallax_p99_px"], label=name, color=color, linewidth=1.2)
                if name in bounds:
                    bound = bounds[name]
                    ax.axhline(bound, color=color, linewidth=0.8, linestyle=":", label="%s bound %g px" % (name, bound))
                    over = [(x, v) for x, v in zip(x_of(s), s["parallax_p99_px"]) if not math.isnan(v) and v > bound]
                    if over:
                        ax.scatter([x for x, _ in over], [v for _, v in over], color=color, marker="x", s=18,
                                   label="%s over bound (%d)" % (name, len(over)))
        ax.set_xlabel("camera path frame")
        ax.set_ylabel("parallax error, 99th pct (px)")
        ax.set_title("Visibility error from object ids: how far objects are drawn from where they are seen")
        ax.set_ylim(bottom=0)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", ncol=2)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, "parallax.png"), dpi=110)
        plt.close(fig)
        written.append("parallax.png")

    popped = {name: s for name, s in modes.items() if has_values(s["popping"])}
    if popped:
        fig, ax = plt.subplots(figsize=(10, 4.0))
        for i, (name, s) in enumerate(modes.items()):
            if name in popped:
                ax.plot(x_of(s), s["popping"], label=name, color=colors[i % len(colors)], linewidth=1.2)
        ax.set_xlabel("camera path frame")
        ax.set_ylabel("popping (mean |RGB change| beyond the reference's, /255)")
        ax.set_title("Popping: frame-to-frame image change beyond the reference's own change")
        ax.set_ylim(bottom=0)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", ncol=2)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, "popping.png"), dpi=110)
        plt.close(fig)
        written.append("popping.png")

    governed = {name: s for name, s in modes.items() if has_values(s["governor_level"])}
    if governed:
        # The governor's loop: measured time against what it expected (the corrected prediction), and its level.
        fig, (ax_t, ax_l) = plt.subplots(2, 1, figsize=(10, 6.0), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
        for i, (name, s) in enumerate(modes.items()):
            if name not in governed:
                continue
            color = colors[i % len(colors)]
            ax_t.plot(x_of(s), s["wall_ms"], label=name + " measured", color=color, linewidth=1.2)
            ax_t.plot(x_of(s), s["corrected_ms"], label=name + " expected (corrected prediction)", color=color,
                      linewidth=0.8, linestyle="--")
            ax_l.step(x_of(s), s["governor_level"], where="mid", label=name, color=color, linewidth=1.2)
        if t_max is not None:
            ax_t.axhline(t_max, color="black", linewidth=0.8, linestyle=":", label="t_max %g ms" % t_max)
        ax_t.set_ylabel("frame time (ms)")
        ax_t.set_title("Frame governor: measured and expected frame time, and the level it chose")
        ax_t.set_ylim(bottom=0)
        ax_t.grid(True, alpha=0.3)
        ax_t.legend(fontsize="small")
        ax_l.set_xlabel("camera path frame")
        top = max(max(v for v in s["governor_level"] if not math.isnan(v)) for s in governed.values())
        ax_l.set_ylim(-0.5, top + 0.5)
        ax_l.set_ylabel("level (0 = full)")
        ax_l.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax_l.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, "governor.png"), dpi=110)
        plt.close(fig)
        written.append("governor.png")

    for name in written:
        print("wrote %s" % os.path.join(out_dir, name))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
