#!/usr/bin/python3
"""Draws the road areas of a CityGML file (grey) under the street graph `farfield import` made from them (streets in
blue, junctions as red dots), for a window of the city: evidence for the road centre lines.

usage: plot_road_centrelines.py CITY.gml IMPORTED.streets.json IMPORTED.georef.json OUT.png
                                [--window X0,Y0,X1,Y1] (scene metres) [--title TEXT]
"""
import argparse
import json
import re

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402


def road_rings(gml):
    text = open(gml).read()
    for road in re.findall(r'<tran:(?:Road|Track|Square|Railway|TrafficArea)\b.*?</tran:(?:Road|Track|Square|Railway)>',
                           text, re.S):
        for pos in re.findall(r'<gml:posList[^>]*>([^<]*)</gml:posList>', road):
            v = [float(t) for t in pos.split()]
            yield [(v[i], v[i + 1]) for i in range(0, len(v) - 2, 3)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('gml')
    ap.add_argument('streets')
    ap.add_argument('georef')
    ap.add_argument('out')
    ap.add_argument('--window', default=None)
    ap.add_argument('--title', default='')
    a = ap.parse_args()
    ox, oy = json.load(open(a.georef))['origin'][:2]
    g = json.load(open(a.streets))
    fig, ax = plt.subplots(figsize=(8, 8), dpi=110)
    for ring in road_rings(a.gml):
        ax.add_patch(Polygon([(x - ox, y - oy) for x, y in ring], closed=True, facecolor='0.85', edgecolor='0.6',
                             linewidth=0.5))
    j = g['junctions']
    for s in g['streets']:
        ax.plot([j[s['a']][0], j[s['b']][0]], [j[s['a']][1], j[s['b']][1]], color='tab:blue', linewidth=1.2)
    ax.plot([p[0] for p in j], [p[1] for p in j], 'o', color='tab:red', markersize=2.5)
    if a.window:
        x0, y0, x1, y1 = (float(t) for t in a.window.split(','))
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
    else:
        ax.autoscale()
    ax.set_aspect('equal')
    ax.set_title(a.title or f'{len(j)} junctions, {len(g["streets"])} streets')
    fig.tight_layout()
    fig.savefig(a.out)


if __name__ == '__main__':
    main()
