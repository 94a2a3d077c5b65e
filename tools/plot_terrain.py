#!/usr/bin/env python3
"""Figures of a `farfield terrain bench` run (Chen et al. 1999, Figures 6 and 9-14), from the CSV files in
OUTDIR/figures, written next to them as PNG:

  fig08_path.png                   the camera path over the terrain (Figure 8)
  fig06_views.png                  Figure 6/7 panels: low, high, LOD-sprite and the two difference images per view,
                                   then each tile mode's frame and its difference to high
  fig09_triangles.png              triangles per frame, semi-log (high, low, LOD-sprite)
  fig10_error.png                  LOD-sprite error (pixels) per frame
  fig11_time.png                   frame time per frame for every mode (red ticks: frames where lod-sprite
                                   chose the high LOD)
  fig12_keyframes_vs_frames.png    keyframe fraction against the number of frames over the same path
  fig13_keyframes_vs_epsilon.png   keyframe fraction against the error threshold
  fig14_speedup_vs_epsilon.png     speedup over high resolution against the error threshold
  quality.png                      PSNR against the high-resolution frame per frame

Usage: plot_terrain.py FIGURES_DIR
Exit codes: 0 plots written, 2 bad input (missing directory or malformed CSV), 3 matplotlib not available.
"""

import csv
import math
import os
import sys


def psnr(a, b):
    """PSNR in dB of two images read by matplotlib (floats in 0..1) on their RGB channels, 8-bit scale; capped at 99."""
    diff = (a[..., :3].astype(float) - b[..., :3].astype(float)) * 255.0
    mse = float((diff * diff).mean())
    return 99.0 if mse <= 0.0 else min(99.0, 10.0 * math.log10(255.0 * 255.0 / mse))


def read_csv(path):
    """Columns of a CSV file as lists: numbers where they parse, text otherwise; None when the file is missing."""
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    columns = {}
    for row in rows:
        for key, text in row.items():
            try:
                value = float(text) if text not in ("", None) else math.nan
            except ValueError:
                value = text
            columns.setdefault(key, []).append(value)
    return columns


def main(argv):
    if len(argv) != 2 or not os.path.isdir(argv[1]):
        sys.stderr.write("usage: plot_terrain.py FIGURES_DIR\n")
        return 2
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.stderr.write("plot_terrain.py: matplotlib not available\n")
        return 3
    d = argv[1]
    written = []

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(os.path.join(d, name), dpi=110)
        plt.close(fig)
        written.append(name)

    def keyframe_marks(ax, frames, keys):
        for f, k in zip(frames, keys):
            if k == 1:
                ax.axvline(f, color="0.85", linewidth=0.6, zorder=0)

    try:
        p = read_csv(os.path.join(d, "fig08_path.csv"))
        if p:
            import matplotlib.image as mpimg

            fig, ax = plt.subplots(figsize=(8, 8 * p["extent_y"][0] / p["extent_x"][0] + 0.5))
            terrain_png = os.path.join(d, "fig08_terrain.png")
            if os.path.exists(terrain_png):
                ax.imshow(mpimg.imread(terrain_png), extent=[0, p["extent_x"][0], 0, p["extent_y"][0]])
            ax.plot(p["eye_x"], p["eye_y"], color="red", linewidth=1.5, label="eye")
            step = max(1, len(p["frame"]) // 12)
            for i in range(0, len(p["frame"]), step):
                ax.annotate("", xy=(p["at_x"][i], p["at_y"][i]), xytext=(p["eye_x"][i], p["eye_y"][i]),
                            arrowprops=dict(arrowstyle="->", color="white", linewidth=0.8))
                ax.text(p["eye_x"][i], p["eye_y"][i], str(int(p["frame"][i])), color="yellow", fontsize=7)
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
            ax.set_title("Camera path (Fig. 8): eye track, arrows to the look-at point, frame numbers")
            save(fig, "fig08_path.png")

        t = read_csv(os.path.join(d, "fig09_triangles.csv"))
        if t:
            fig, ax = plt.subplots(figsize=(7, 4))
            ax.semilogy(t["frame"], t["high"], label="high resolution")
            ax.semilogy(t["frame"], t["low"], label="low resolution")
            ax.semilogy(t["frame"], t["lod_sprite"], label="LOD-sprite", linestyle="--")
            ax.set_xlabel("frame")
            ax.set_ylabel("triangles")
            ax.set_title("Triangles per frame (Fig. 9)")
            ax.legend()
            save(fig, "fig09_triangles.png")

        e = read_csv(os.path.join(d, "fig10_error.csv"))
        if e:
            fig, ax = plt.subplots(figsize=(7, 4))
            keyframe_marks(ax, e["frame"], e["keyframe"])
            ax.plot(e["frame"], e["error_px"], label="error of the sprite in use")
            if "path" in e:
                high = [(f, v) for f, p, v in zip(e["frame"], e["path"], e["trigger_error_px"]) if p == "high"]
                if high:
                    ax.plot([f for f, _ in high], [0.0] * len(high), linestyle="none", marker="|", color="red",
                            label="high LOD drawn (per-frame choice)")
                ax.legend(fontsize=8)
            ax.set_xlabel("frame")
            ax.set_ylabel("error (pixels)")
            ax.set_title("LOD-sprite error per frame (Fig. 10; grey lines: keyframes)")
            save(fig, "fig10_error.png")

        tm = read_csv(os.path.join(d, "fig11_time.csv"))
        if tm:
            fig, ax = plt.subplots(figsize=(7, 4))
            for key in tm:
                if key.endswith("_ms"):
                    style = "--" if key.startswith("lod-sprite-") else "-"
                    ax.plot(tm["frame"], tm[key], label=key[:-3], linestyle=style, linewidth=0.9)
            ax.set_yscale("log")
            ax.set_xlabel("frame")
            ax.set_ylabel("time (ms)")
            if "lod_sprite_path" in tm:
                high = [f for f, p in zip(tm["frame"], tm["lod_sprite_path"]) if p == "high"]
                if high:
                    lo = min(v for key in tm if key.endswith("_ms") for v in tm[key] if v == v and v > 0)
                    ax.plot(high, [lo * 0.8] * len(high), linestyle="none", marker="|", color="red", markersize=6,
                            label="lod-sprite drew the high LOD (%d frames)" % len(high))
            ax.set_title("Frame time (Fig. 11)")
            ax.legend(fontsize=8)
            save(fig, "fig11_time.png")

        k = read_csv(os.path.join(d, "fig12_keyframes_vs_frames.csv"))
        if k:
            fig, ax = plt.subplots(figsize=(6, 4))
            ax.plot(k["frames"], k["keyframe_fraction"], marker="o")
            ax.set_xscale("log")
            ax.set_xlabel("total frames over the path")
            ax.set_ylabel("keyframe fraction")
            ax.set_title("Keyframes vs frame count (Fig. 12)")
            save(fig, "fig12_keyframes_vs_frames.png")

        k = read_csv(os.path.join(d, "fig13_keyframes_vs_epsilon.csv"))
        if k:
            fig, ax = plt.subplots(figsize=(6, 4))
            ax.plot(k["epsilon_px"], k["keyframe_fraction"], marker="o")
            ax.set_xlabel("error threshold (pixels)")
            ax.set_ylabel("keyframe fraction")
            ax.set_title("Keyframes vs threshold (Fig. 13)")
            save(fig, "fig13_keyframes_vs_epsilon.png")

        s = read_csv(os.path.join(d, "fig14_speedup_vs_epsilon.csv"))
        if s:
            fig, ax = plt.subplots(figsize=(6, 4))
            ax.plot(s["epsilon_px"], s["speedup_total"], marker="o", label="total time")
            ax.plot(s["epsilon_px"], s["speedup_median"], marker="s", linestyle="--", label="median frame")
            ax.set_xlabel("error threshold (pixels)")
            ax.set_ylabel("speedup over high resolution")
            ax.set_title("Speedup vs threshold (Fig. 14)")
            ax.legend()
            save(fig, "fig14_speedup_vs_epsilon.png")

        q = read_csv(os.path.join(d, "quality.csv"))
        if q:
            fig, ax = plt.subplots(figsize=(7, 4))
            for key in q:
                if key.startswith("psnr_"):
                    ax.plot(q["path_frame"], q[key], label=key[5:-11], linewidth=0.9)
            ax.set_xlabel("path frame")
            ax.set_ylabel("PSNR vs high resolution (dB)")
            ax.set_title("Image quality against the high-resolution frame")
            ax.legend(fontsize=8)
            save(fig, "quality.png")

        views = read_csv(os.path.join(d, "fig06_views.csv"))
        if views and "view" in views:
            import matplotlib.image as mpimg

            panels = [("a_low", "(a) low"), ("b_high", "(b) high"), ("c_lod_sprite", "(c) LOD-sprite"),
                      ("d_diff_low_high", "(d) |low - high| x4"), ("e_diff_high_lod_sprite", "(e) |high - LOD-sprite| x4")]
            # The tile modes' frames of the same views (view1_f_MODE.png), with their difference to high (g).
            fig06 = os.path.join(d, "fig06")
            tile_modes = sorted({f[len("view1_f_"):-4] for f in os.listdir(fig06) if f.startswith("view1_f_")}
                                if os.path.isdir(fig06) else [])
            for m in tile_modes:
                panels += [("f_" + m, "(f) " + m), ("g_diff_high_" + m, "(g) |high - %s| x4" % m)]
            n = len(views["view"])
            fig, axes = plt.subplots(n, len(panels), figsize=(3 * len(panels), 3.2 * n), squeeze=False)
            for r in range(n):
                v = int(views["view"][r])
                high = None
                for c, (suffix, title) in enumerate(panels):
                    path = os.path.join(fig06, "view%d_%s.png" % (v, suffix))
                    ax = axes[r][c]
                    ax.axis("off")
                    image = mpimg.imread(path) if os.path.exists(path) else None
                    if image is not None:
                        ax.imshow(image)
                    label = title
                    if suffix == "a_low":
                        label += " %d tris, %.1f dB" % (views["low_triangles"][r], views["psnr_low_vs_high_db"][r])
                    if suffix == "b_high":
                        label += " %d tris" % views["high_triangles"][r]
                        high = image
                    if suffix == "c_lod_sprite":
                        label += " %.1f dB" % views["psnr_lod_sprite_vs_high_db"][r]
                    if suffix.startswith("f_") and image is not None and high is not None:
                        label += " %.1f dB" % psnr(high, image)
                    ax.set_title(label, fontsize=8)
            save(fig, "fig06_views.png")
    except (KeyError, ValueError, TypeError) as err:
        sys.stderr.write("plot_terrain.py: malformed CSV in %s: %s\n" % (d, err))
        return 2
    print("plot_terrain.py: wrote " + ", ".join(written))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
