#!/usr/bin/env python3
"""Writes a CityGML 2.0 city of N x N blocks whose streets are road areas (tran:Road, lod1MultiSurface), for timing
the road centre lines of `farfield import` on a network the tests never see.

Each street is one rectangle per grid line; the lines are jittered and each street has its own width (6-14 m),
drawn from the seed. One 20 x 20 x 15 m LoD1 building stands in each block.

usage: make_citygml_road_grid.py N SEED OUT.gml [--spacing METRES]
"""
import argparse
import random

HEADER = ('<?xml version="1.0" encoding="UTF-8"?>\n<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" '
          'xmlns:bldg="http://www.opengis.net/citygml/building/2.0" '
          'xmlns:tran="http://www.opengis.net/citygml/transportation/2.0" xmlns:gml="http://www.opengis.net/gml">\n')
X0, Y0, Z0 = 690000.0, 5336000.0, 500.0


def ring(points):
    pts = points + [points[0]]
    return ' '.join(f'{X0 + x:.3f} {Y0 + y:.3f} {Z0 + z:.3f}' for x, y, z in pts)


def polygon(pid, points):
    return (f'<gml:surfaceMember><gml:Polygon gml:id="{pid}"><gml:exterior><gml:LinearRing><gml:posList '
            f'srsDimension="3">{ring(points)}</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>'
            '</gml:surfaceMember>')


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('n', type=int)
    ap.add_argument('seed', type=int)
    ap.add_argument('out')
    ap.add_argument('--spacing', type=float, default=110.0)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    lines = [k * a.spacing + (rng.uniform(-8, 8) if 0 < k < a.n else 0.0) for k in range(a.n + 1)]
    extent = a.n * a.spacing
    out = [HEADER]
    road = 0
    for vertical in (True, False):
        for c in lines:
            h = rng.uniform(3.0, 7.0)
            if vertical:
                pts = [(c - h, -7, 0), (c + h, -7, 0), (c + h, extent + 7, 0), (c - h, extent + 7, 0)]
            else:
                pts = [(-7, c - h, 0), (extent + 7, c - h, 0), (extent + 7, c + h, 0), (-7, c + h, 0)]
            out.append(f'<core:cityObjectMember><tran:Road gml:id="road{road}"><tran:lod1MultiSurface><gml:MultiSurface>'
                       f'{polygon(f"road{road}_p", pts)}</gml:MultiSurface></tran:lod1MultiSurface></tran:Road>'
                       '</core:cityObjectMember>\n')
            road += 1
    for i in range(a.n):
        for j in range(a.n):
            cx, cy = (lines[i] + lines[i + 1]) / 2, (lines[j] + lines[j + 1]) / 2
            x0, x1, y0, y1, top = cx - 10, cx + 10, cy - 10, cy + 10, 15.0
            faces = [[(x0, y0, 0), (x0, y1, 0), (x1, y1, 0), (x1, y0, 0)],
                     [(x0, y0, top), (x1, y0, top), (x1, y1, top), (x0, y1, top)],
                     [(x0, y0, 0), (x1, y0, 0), (x1, y0, top), (x0, y0, top)],
                     [(x1, y0, 0), (x1, y1, 0), (x1, y1, top), (x1, y0, top)],
                     [(x1, y1, 0), (x0, y1, 0), (x0, y1, top), (x1, y1, top)],
                     [(x0, y1, 0), (x0, y0, 0), (x0, y0, top), (x0, y1, top)]]
            b = f'b{i}_{j}'
            out.append(f'<core:cityObjectMember><bldg:Building gml:id="{b}"><bldg:lod1Solid><gml:Solid><gml:exterior>'
                       '<gml:CompositeSurface>' + ''.join(polygon(f'{b}_{k}', f) for k, f in enumerate(faces)) +
                       '</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod1Solid></bldg:Building>'
                       '</core:cityObjectMember>\n')
    out.append('</core:CityModel>\n')
    open(a.out, 'w').write(''.join(out))


if __name__ == '__main__':
    main()
