#!/usr/bin/env python3
"""The table of scripts/bench_dynamic_budget.sh (docs/BENCHMARKS.md): per scene, t_max, run (default, or the suffix of
a run with OCCLUSION=, INVEST=, PAY_BACK= or MODES= set) and mode, frame times, frames over t_max, the frames that
regenerated (regenerations_at_frame_K in the modes' info) checked against t_max, the image error against the
full-geometry reference and the nodes the occlusion culling hid. With --modes-table: for the runs with MODES=all, every
mode against full and culled with texture memory and bus traffic (the table of issue 15)."""
import csv
import glob
import json
import os
import re
import sys

args = [a for a in sys.argv[1:] if not a.startswith('--')]
base = args[0] if args else 'out/bench/dynamic-budget'


def modes_table(run, T):
    """Every mode of one run: times, speedups, error, budget and the image traffic."""
    d = json.load(open(run + '/bench.json'))
    modes = d['modes']
    full, culled = modes['full']['median_ms'], modes['culled']['median_ms']
    print('| mode | median ms | p95 ms | speedup vs full | vs culled | PSNR mean / min dB | parallax p99 px mean / max | '
          'over bound | over t_max %d ms | regenerations / frame | texture MiB | uploaded KiB / frame | '
          'written KiB / frame |' % T)
    print('|' + '---|' * 13)
    for m, r in modes.items():
        info = r.get('info', {})
        psnr = lambda v: '99' if v is None else '%.1f' % v
        tex = info.get('texture_bytes_max', info.get('texture_bytes', 0.0))
        up = info.get('uploaded_bytes_per_frame', 0.0) + info.get('readback_bytes_per_frame', 0.0)
        bound = '%d/%d' % (r['frames_over_bound'], r['frames_checked_against_bound']) \
            if r.get('frames_checked_against_bound') else '-'
        print('| %s | %.1f | %.1f | %.2fx | %.2fx | %s / %s | %.2f / %.2f | %s | %d | %.2f | %.1f | %.1f | %.0f |' % (
            m, r['median_ms'], r['p95_ms'], full / r['median_ms'], culled / r['median_ms'], psnr(r.get('psnr_db_mean')),
            psnr(r.get('psnr_db_min')), r.get('parallax_p99_px_mean', 0.0), r.get('parallax_p99_px_max', 0.0), bound,
            r['frames_over_tmax'], info.get('regenerations_per_frame', 0.0), tex / 2**20, up / 1024,
            info.get('texels_written_bytes_per_frame', 0.0) / 1024))


if '--modes-table' in sys.argv:
    for p in sorted(glob.glob(base + '/bench-*-t*-all')):
        m = re.fullmatch(r'bench-(\w+)-t(\d+)-all', os.path.basename(p))
        if m and os.path.isdir(p):
            print('\n%s, t_max %s ms:\n' % (m.group(1), m.group(2)))
            modes_table(p, int(m.group(2)))
    sys.exit(0)
runs = []
for p in glob.glob(base + '/bench-*-t*'):
    m = re.fullmatch(r'bench-(\w+)-t(\d+)(.*)', os.path.basename(p))
    if m and os.path.isdir(p):
        runs.append((m.group(1), int(m.group(2)), m.group(3).lstrip('-') or 'default', p))
print('| scene | t_max ms | run | mode | median ms | max ms | frames over t_max | regenerations / frame | '
      'frames with regenerations | of those over t_max | slowest regeneration frame ms | invalid as geometry / frame | '
      'PSNR mean dB | frames over the bound | hidden nodes / frame |')
print('|' + '---|' * 15)
for sc, T, label, run in sorted(runs):
    try:
        d = json.load(open(run + '/bench.json'))
    except FileNotFoundError:
        continue
    rows = list(csv.DictReader(open(run + '/frames.csv')))
    for m, r in d['modes'].items():
        info = r.get('info', {})
        times = {int(x['path_frame']): float(x['wall_ms']) for x in rows if x['mode'] == m}
        psnr = '%.1f' % r['psnr_db_mean'] if r.get('psnr_db_mean') is not None else '-'
        bound = '%d/%d' % (r['frames_over_bound'], r['frames_checked_against_bound']) \
            if r.get('frames_checked_against_bound') else '-'
        head = '| %s | %d | %s | %s | %.1f | %.1f | %d/%d |' % (sc, T, label, m, r['median_ms'], r['max_ms'],
                                                               r['frames_over_tmax'], len(times))
        if 'regenerations_per_frame' not in info:
            print(head + ' - | - | - | - | - | %s | %s | - |' % (psnr, bound))
            continue
        regen = {int(k.split('_')[-1]): v for k, v in info.items() if k.startswith('regenerations_at_frame_')}
        over = [k for k in regen if times.get(k, 0) > T]
        mx = max([times[k] for k in regen] or [0])
        print(head + ' %.2f | %d | %d/%d | %.1f | %.2f | %s | %s | %.1f |' % (
            info['regenerations_per_frame'], len(regen), len(over), len(regen), mx,
            info.get('deferred_regenerations_per_frame', 0.0), psnr, bound, info.get('occlusion_hidden_nodes_per_frame', 0.0)))
