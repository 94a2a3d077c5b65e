#!/usr/bin/env python3
"""The table of scripts/bench_dynamic_budget.sh (docs/BENCHMARKS.md): per scene, t_max, occlusion culling of the image
cache (on, or off for runs with OCCLUSION=off) and mode, frame times, frames over t_max, the frames that regenerated
(regenerations_at_frame_K in the modes' info) checked against t_max, and the nodes the occlusion culling hid."""
import csv
import glob
import json
import os
import re
import sys

base=sys.argv[1] if len(sys.argv) > 1 else 'out/bench/dynamic-budget'
budgets=sorted({int(m.group(1)) for m in (re.search(r'-t(\d+)', os.path.basename(p)) for p in glob.glob(base+'/bench-*-t*'))
                 if m})
for sc in ('city','forest'):
  for T in budgets:
   for occ,suffix in (('on',''),('off','-occlusion-off'),('on, invest 0','-invest-0'),('off, invest 0','-occlusion-off-invest-0')):
    run='%s/bench-%s-t%d%s'%(base,sc,T,suffix)
    try:
        d=json.load(open(run+'/bench.json'))
    except FileNotFoundError: continue
    rows=list(csv.DictReader(open(run+'/frames.csv')))
    for m,r in d['modes'].items():
        info=r.get('info',{})
        times={int(x['path_frame']):float(x['wall_ms']) for x in rows if x['mode']==m}
        if 'regenerations_per_frame' not in info:
            print('| %s | %d | %s | %s | %.1f | %.1f | %d/%d | - | - | - | - | - | - |'%(sc,T,occ,m,r['median_ms'],r['max_ms'],r['frames_over_tmax'],len(times)))
            continue
        regen={int(k.split('_')[-1]):v for k,v in info.items() if k.startswith('regenerations_at_frame_')}
        over=[k for k in regen if times.get(k,0)>T]
        mx=max([times[k] for k in regen] or [0])
        print('| %s | %d | %s | %s | %.1f | %.1f | %d/%d | %.2f | %d | %s | %.1f | %.2f | %.1f |'%(sc,T,occ,m,r['median_ms'],r['max_ms'],r['frames_over_tmax'],len(times),info['regenerations_per_frame'],len(regen),'%d/%d'%(len(over),len(regen)), mx, info['deferred_regenerations_per_frame'], info.get('occlusion_hidden_nodes_per_frame',0.0)))
