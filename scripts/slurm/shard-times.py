#!/usr/bin/env python3
"""Per-shard work and scheduling overhead of a sharded bake run by bake-array.sh.

    scripts/slurm/shard-times.py OUT.imp.shards [--slots C] [--json FILE]

Reads the logs bake-array.sh's jobs write (logs/submit.log, logs/task-K.log, logs/merge.log): each task's start and
end (epoch seconds), the bake's own wall time ("wall: X s for N cells", which leaves out loading the scene and the
street cells), and the merge's start and end. Reports, per task: cells, bake wall, fixed cost (task time - bake
wall: process start, scene load, cell map, GL context) and the queue wait; and for the run: the makespan (submit to
merge end), the total task time, and the scheduling overhead = makespan - the makespan the same task durations would
have on C slots (C = --slots, the CPUs the cluster runs tasks on) with no scheduler latency, in the same order, plus
the merge.
"""
import argparse
import json
import re
import sys
from pathlib import Path


def read_task(path):
    text = path.read_text()
    start = re.search(r"^ff-task (\d+) start ([0-9.]+)", text, re.M)
    end = re.search(r"^ff-task \d+ end ([0-9.]+) status (\d+)", text, re.M)
    wall = re.search(r"^wall: +([0-9.]+) s for (\d+) cells", text, re.M)
    if not (start and end):
        sys.exit(f"{path}: no ff-task start/end lines (did the task run?)")
    return {"task": int(start.group(1)), "start": float(start.group(2)), "end": float(end.group(1)),
            "status": int(end.group(2)), "bake_wall_s": float(wall.group(1)) if wall else 0.0,
            "cells": int(wall.group(2)) if wall else 0}


def ideal_makespan(durations, slots):
    free = [0.0] * slots
    for d in durations:
        k = min(range(slots), key=lambda i: free[i])
        free[k] += d
    return max(free) if free else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("shards_dir")
    ap.add_argument("--slots", type=int, default=2)
    ap.add_argument("--json")
    a = ap.parse_args()
    logs = Path(a.shards_dir) / "logs"
    submit = float(re.search(r"ff-submit ([0-9.]+)", (logs / "submit.log").read_text()).group(1))
    tasks = sorted((read_task(p) for p in logs.glob("task-*.log")), key=lambda t: t["task"])
    merge_text = (logs / "merge.log").read_text()
    m0 = float(re.search(r"ff-merge start ([0-9.]+)", merge_text).group(1))
    m1 = float(re.search(r"ff-merge end ([0-9.]+)", merge_text).group(1))
    for t in tasks:
        t["task_s"] = t["end"] - t["start"]
        t["fixed_s"] = t["task_s"] - t["bake_wall_s"]
    makespan = m1 - submit
    ideal = ideal_makespan([t["task_s"] for t in tasks], a.slots) + (m1 - m0)
    out = {"shards": len(tasks), "slots": a.slots, "makespan_s": makespan, "merge_s": m1 - m0,
           "task_s_total": sum(t["task_s"] for t in tasks), "task_s_max": max(t["task_s"] for t in tasks),
           "bake_wall_s_total": sum(t["bake_wall_s"] for t in tasks),
           "fixed_s_total": sum(t["fixed_s"] for t in tasks), "cells": sum(t["cells"] for t in tasks),
           "ideal_makespan_s": ideal, "scheduling_overhead_s": makespan - ideal,
           "first_start_wait_s": min(t["start"] for t in tasks) - submit,
           "merge_wait_s": m0 - max(t["end"] for t in tasks), "tasks": tasks}
    print(f"{'task':>4} {'cells':>5} {'task s':>8} {'bake s':>8} {'fixed s':>8} {'start at':>9}")
    for t in tasks:
        print(f"{t['task']:>4} {t['cells']:>5} {t['task_s']:8.1f} {t['bake_wall_s']:8.1f} {t['fixed_s']:8.1f} "
              f"{t['start'] - submit:9.1f}")
    print(f"makespan {makespan:.1f} s (ideal on {a.slots} slots {ideal:.1f} s, scheduling overhead "
          f"{makespan - ideal:.1f} s); tasks {out['task_s_total']:.1f} s in all, bake {out['bake_wall_s_total']:.1f} s, "
          f"fixed {out['fixed_s_total']:.1f} s; merge {out['merge_s']:.1f} s; first task started after "
          f"{out['first_start_wait_s']:.1f} s, merge {out['merge_wait_s']:.1f} s after the last task")
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
