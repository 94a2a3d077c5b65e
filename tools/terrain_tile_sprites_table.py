#!/usr/bin/env python3
"""The lod-sprite-tiles table of docs/BENCHMARKS.md (tile-path figures from lod-sprite-tiles-always) from `farfield terrain bench` runs (their bench.json files)."""
import json
import os
import sys


def row(path):
    bench = json.load(open(path))
    modes = bench["modes"]
    run = os.path.basename(os.path.dirname(path))

    def mode(name):
        return modes.get(name, {}).get("info", {})

    high_ms = modes["high"]["mean_ms"]
    # The tile path's own figures come from the mode that takes it on every frame (older runs: lod-sprite-tiles).
    tiles = mode("lod-sprite-tiles-always") or mode("lod-sprite-tiles")
    choice = mode("lod-sprite-tiles") if "lod-sprite-tiles-always" in modes else {}
    cells = (
        f"{int(tiles['tile_cells'])}" if "tile_cells" in tiles else "?"
    )
    cols = [run, cells, f"{high_ms:.1f}"]
    names = ("lod-sprite", "lod-sprite-always", "lod-sprite-tiles", "lod-sprite-tiles-each-frame",
             "lod-sprite-tiles-always")
    for name in names:
        i = mode(name)
        cols.append(f"{i.get('speedup_vs_high_filtered_total', float('nan')):.2f}x")
    for name in names + ("low",):
        cols.append(f"{mode(name).get('psnr_vs_high_db_mean', float('nan')):.2f}")
    cols.append(f"{100 * choice.get('high_frame_fraction', float('nan')):.1f}%")
    cols.append(f"{100 * mode('lod-sprite-tiles-each-frame').get('high_frame_fraction', float('nan')):.1f}%")
    cols.append(f"{int(choice.get('carried_high_frames', 0))}")
    cols.append(f"{100 * tiles.get('tile_keyframe_fraction', 0):.1f}%")
    cols.append(f"{100 * tiles.get('keyframe_fraction', 0):.1f}%")
    cols.append(f"{100 * mode('lod-sprite-always').get('keyframe_fraction', 0):.1f}%")
    cols.append(f"{tiles.get('keyframe_triangles_per_frame', 0):.0f}")
    cols.append(f"{100 * tiles.get('sprite_triangle_share', 0):.0f}%")
    cols.append(f"{int(tiles.get('view_framed_keyframes', 0))} / {int(tiles.get('tile_keyframes', 0))}")
    cols.append(f"{tiles.get('peak_sprite_bytes', 0) / 2**20:.0f}")
    return "| " + " | ".join(cols) + " |"


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: terrain_tile_sprites_table.py RUN/bench.json...")
    print("| run | tile cells | high mean ms | speedup lod-sprite | speedup always | speedup tiles | "
          "speedup tiles-each-frame | speedup tiles-always | PSNR lod-sprite | PSNR always | PSNR tiles | "
          "PSNR tiles-each-frame | PSNR tiles-always | PSNR low | tiles: frames drawn as high | "
          "tiles-each-frame: frames drawn as high | tiles: high frames carried without deciding | "
          "tile keyframes / tile-frames in view | frames with a tile keyframe | always: keyframe frames | "
          "tile keyframe triangles per frame | low triangles with a sprite (tiles) | "
          "tile keyframes of the frame's view / all | peak sprite MiB |")
    print("|---" + "|---:" * 23 + "|")
    for path in sys.argv[1:]:
        print(row(path))


if __name__ == "__main__":
    main()
