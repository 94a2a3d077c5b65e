#!/usr/bin/env python3
"""The table of scripts/bench_dynamic_budget.sh (docs/BENCHMARKS.md): per scene, t_max and mode, frame times, frames over
t_max, and the frames that regenerated (regenerations_at_frame_K in the modes' info) checked against t_max."""
import csv
import json
import sys

base=sys.argv[1] if len(sys.argv) > 1 else 'out/bench/dynamic-budget'
for sc in ('city','forest'):
  for T in (200,600):
    try:
        d=json.load(open('%s/bench-%s-t%d/bench.json'%(base,sc,T)))
    except FileNotFoundError: continue
    rows=list(csv.DictReader(open('%s/bench-%s-t%d/frames.csv'%(base,sc,T))))
    for m,r in d['modes'].items():
        info=r.get('info',{})
        times={int(x['path_frame']):float(x['wall_ms']) for x in rows if x['mode']==m}
        if 'regenerations_per_frame' not in info:
            print('| %s | %d | %s | %.1f | %.1f | %d/%d | - | - | - | - | - |'%(sc,T,m,r['median_ms'],r['max_ms'],r['frames_over_tmax'],len(times)))
            continue
        regen={int(k.split('_')[-1]):v for k,v in info.items() if k.startswith('regenerations_at_frame_')}
        over=[k for k in regen if times.get(k,0)>T]
        mx=max([times[k] for k in regen] or [0])
        print('| %s | %d | %s | %.1f | %.1f | %d/%d | %.2f | %d | %s | %.1f | %.2f |'%(sc,T,m,r['median_ms'],r['max_ms'],r['frames_over_tmax'],len(times),info['regenerations_per_frame'],len(regen),'%d/%d'%(len(over),len(regen)), mx, info['deferred_regenerations_per_frame']))
