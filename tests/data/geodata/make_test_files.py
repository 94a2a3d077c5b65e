#!/usr/bin/env python3
"""Writes the hand-made OpenStreetMap and CityJSON test files of tests/geodata (run from this directory).

small_city.osm      a 3 x 3 grid of residential streets (lon 7.420..7.423, lat 43.730..43.733, 0.001 degree
                    spacing), a primary road crossing the middle row without shared nodes (split into +3 blocks),
                    a footway across the south-west block (a block more when footways are selected), and buildings
                    with known tags (height, levels, feet, a multipolygon with a courtyard, an outline with two
                    building:part areas, one building outside every block, one building=no).
malformed.osm       one good building, one of each skip reason, one highway with a missing node.
unsorted.osm        the small city with its ways out of id order (osmium needs sorted input).
all_bad.osm         only malformed buildings and no highways: nothing usable.
garbage.osm.pbf     bytes that are not PBF.
cube.city.json      CityJSON 2.0 with a transform: a 10 x 10 x 10 m LoD2 Solid building with semantics and a
                    BuildingPart child (a 4 x 4 x 4 cube on its roof), a road with a hole (MultiSurface), and a
                    LandUse object.
cube_v11.city.json  the same building as CityJSON 1.1 with string LoDs and two LoDs (1 and 2.2).
bad_index.city.json a building with one good face and faces with bad indices (out of range, negative, a string).
all_bad.city.json   only bad faces.
unknown_version.city.json, not_cityjson.city.json, truncated.city.json: errors.
"""
import json

LON0, LAT0, STEP = 7.420, 43.730, 0.001


def osm(nodes, ways, relations, sort=True):
    if sort:  # osmium expects nodes, ways, relations, each sorted by id
        nodes, ways, relations = sorted(nodes), sorted(ways, key=lambda w: w[0]), sorted(relations, key=lambda r: r[0])
    out = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="farfield tests (hand-made)">']
    for nid, lon, lat in nodes:
        out.append(f' <node id="{nid}" version="1" lat="{lat:.7f}" lon="{lon:.7f}"/>')
    for wid, refs, tags in ways:
        out.append(f' <way id="{wid}" version="1">')
        out += [f'  <nd ref="{r}"/>' for r in refs]
        out += [f'  <tag k="{k}" v="{v}"/>' for k, v in tags]
        out.append(' </way>')
    for rid, members, tags in relations:
        out.append(f' <relation id="{rid}" version="1">')
        out += [f'  <member type="way" ref="{r}" role="{role}"/>' for r, role in members]
        out += [f'  <tag k="{k}" v="{v}"/>' for k, v in tags]
        out.append(' </relation>')
    out.append('</osm>')
    return '\n'.join(out) + '\n'


class Ids:
    def __init__(self, start):
        self.next = start

    def take(self):
        self.next += 1
        return self.next - 1


def square(nodes, ids, lon0, lat0, lon1, lat1):
    """Adds the 4 corners (counter-clockwise) and returns the closed ref list."""
    refs = []
    for lon, lat in ((lon0, lat0), (lon1, lat0), (lon1, lat1), (lon0, lat1)):
        nid = ids.take()
        nodes.append((nid, lon, lat))
        refs.append(nid)
    return refs + [refs[0]]


def small_city(sort=True):
    nodes, ways, rels = [], [], []
    for k in range(4):
        for i in range(4):
            nodes.append((1 + k * 4 + i, LON0 + i * STEP, LAT0 + k * STEP))
    for k in range(4):
        ways.append((101 + k, [1 + k * 4 + i for i in range(4)], [("highway", "residential"), ("name", f"Row {k}")]))
    for i in range(4):
        ways.append((111 + i, [1 + k * 4 + i for k in range(4)], [("highway", "residential")]))
    # Footway on the diagonal of block (0, 0): from node 1 (7.420, 43.730) to node 6 (7.421, 43.731).
    ways.append((120, [1, 6], [("highway", "footway")]))
    # Primary road across the middle row at lat 43.73155, from lon 7.4195 to 7.4235: no shared nodes.
    nodes.append((50, 7.4195, 43.73155))
    nodes.append((51, 7.4235, 43.73155))
    ways.append((130, [50, 51], [("highway", "primary")]))
    # A tunnel (left out by default) along the middle of block (1, 0)'s row.
    nodes.append((52, 7.4211, 43.7305))
    nodes.append((53, 7.4219, 43.7305))
    ways.append((140, [52, 53], [("highway", "residential"), ("tunnel", "yes")]))

    ids = Ids(1000)
    ways.append((201, square(nodes, ids, 7.4213, 43.7303, 7.4215, 43.7305), [("building", "yes"), ("height", "12 m")]))
    ways.append((202, square(nodes, ids, 7.4223, 43.7303, 7.4225, 43.7305),
                 [("building", "apartments"), ("building:levels", "5"), ("roof:levels", "1")]))
    ways.append((203, square(nodes, ids, 7.4203, 43.7323, 7.4205, 43.7325), [("building", "yes")]))
    # Multipolygon with a courtyard in block (2, 2).
    ways.append((211, square(nodes, ids, 7.4223, 43.7323, 7.4227, 43.7327), []))
    ways.append((212, square(nodes, ids, 7.4224, 43.7324, 7.4226, 43.7326), []))
    rels.append((301, [(211, "outer"), (212, "inner")], [("type", "multipolygon"), ("building", "yes"), ("height", "20")]))
    ways.append((204, square(nodes, ids, 7.4213, 43.7323, 7.4215, 43.7325), [("building", "yes"), ("height", "40 ft")]))
    # Outline with two parts in the upper half of block (2, 1).
    ways.append((205, square(nodes, ids, 7.4223, 43.7316, 7.4227, 43.7319), [("building", "yes"), ("height", "30")]))
    ways.append((206, square(nodes, ids, 7.4223, 43.7316, 7.4225, 43.7319), [("building:part", "yes"), ("height", "30")]))
    ways.append((207, square(nodes, ids, 7.4225, 43.7316, 7.4227, 43.7319),
                 [("building:part", "yes"), ("min_height", "10"), ("height", "20")]))
    # Outside every block (south-west of the grid).
    ways.append((208, square(nodes, ids, 7.4183, 43.7283, 7.4185, 43.7285), [("building", "yes")]))
    # Not a building.
    ways.append((209, square(nodes, ids, 7.4213, 43.7313, 7.4215, 43.7315), [("building", "no")]))
    return osm(nodes, ways, rels, sort)


def malformed(with_good=True, with_highway=True):
    nodes, ways, rels = [], [], []
    ids = Ids(1)
    if with_good:
        ways.append((401, square(nodes, ids, 7.4213, 43.7303, 7.4215, 43.7305), [("building", "yes")]))
    # Missing nodes: the way refers to node 9999 that the file does not have.
    refs = square(nodes, ids, 7.4223, 43.7303, 7.4225, 43.7305)
    ways.append((402, refs[:2] + [9999] + refs[2:], [("building", "yes")]))
    # Unclosed ring.
    refs = square(nodes, ids, 7.4233, 43.7303, 7.4235, 43.7305)
    ways.append((403, refs[:-1], [("building", "yes")]))
    # Self-intersecting (a bow tie): corners 0, 1, 3, 2 of a square.
    refs = square(nodes, ids, 7.4243, 43.7303, 7.4245, 43.7305)
    ways.append((404, [refs[0], refs[1], refs[3], refs[2], refs[0]], [("building", "yes")]))
    # Tiny: about 0.4 x 0.4 m.
    ways.append((405, square(nodes, ids, 7.4253, 43.7303, 7.425305, 43.730304), [("building", "yes")]))
    # Closed with fewer than 3 distinct nodes.
    refs = square(nodes, ids, 7.4263, 43.7303, 7.4265, 43.7305)
    ways.append((406, [refs[0], refs[1], refs[0]], [("building", "yes")]))
    # A multipolygon whose outer way is not in the file.
    rels.append((501, [(9998, "outer")], [("type", "multipolygon"), ("building", "yes")]))
    if with_highway:
        a, b = ids.take(), ids.take()
        nodes.append((a, 7.4200, 43.7300))
        nodes.append((b, 7.4300, 43.7300))
        ways.append((601, [a, 9997, b], [("highway", "residential")]))
        c = ids.take()
        nodes.append((c, 7.4300, 43.7310))
        ways.append((602, [b, c], [("highway", "residential")]))
    return osm(nodes, ways, rels)


def cityjson_cube(version="2.0"):
    # Integer vertices with scale 0.01: 1000 = 10 m. Translate puts the cube at large RD-like coordinates.
    v = [[0, 0, 0], [1000, 0, 0], [1000, 1000, 0], [0, 1000, 0],
         [0, 0, 1000], [1000, 0, 1000], [1000, 1000, 1000], [0, 1000, 1000]]
    # Part: a 4 x 4 x 4 m cube on the roof, x, y in 3..7 m, z in 10..14 m.
    p = [[300, 300, 1000], [700, 300, 1000], [700, 700, 1000], [300, 700, 1000],
         [300, 300, 1400], [700, 300, 1400], [700, 700, 1400], [300, 700, 1400]]
    base = len(v)
    v += p
    # Road: a 30 x 20 m rectangle at z = 0 beside the building with a 10 x 5 m hole.
    r0 = len(v)
    v += [[2000, 0, 0], [5000, 0, 0], [5000, 2000, 0], [2000, 2000, 0],
          [3000, 500, 0], [3000, 1000, 0], [4000, 1000, 0], [4000, 500, 0]]
    lu = len(v)
    v += [[0, 3000, 0], [1000, 3000, 0], [1000, 4000, 0]]

    def cube_faces(o):
        # Outward, counter-clockwise seen from outside: bottom, top, 4 walls.
        return [[[o + 0, o + 3, o + 2, o + 1]], [[o + 4, o + 5, o + 6, o + 7]],
                [[o + 0, o + 1, o + 5, o + 4]], [[o + 1, o + 2, o + 6, o + 5]],
                [[o + 2, o + 3, o + 7, o + 6]], [[o + 3, o + 0, o + 4, o + 7]]]

    sem = {"surfaces": [{"type": "GroundSurface"}, {"type": "RoofSurface"}, {"type": "WallSurface"}],
           "values": [[0, 1, 2, 2, 2, 2]]}
    lod_main = "2.2" if version != "1.0" else 2
    doc = {
        "type": "CityJSON", "version": version,
        "transform": {"scale": [0.01, 0.01, 0.01], "translate": [85000.0, 445000.0, 1.5]},
        "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/7415"},
        "CityObjects": {
            "house": {"type": "Building", "children": ["house-part"],
                      "geometry": [{"type": "Solid", "lod": lod_main, "boundaries": [cube_faces(0)], "semantics": sem}]},
            "house-part": {"type": "BuildingPart", "parents": ["house"],
                           "geometry": [{"type": "Solid", "lod": lod_main, "boundaries": [cube_faces(base)]}]},
            "road": {"type": "Road", "geometry": [{"type": "MultiSurface", "lod": "1" if version != "1.0" else 1,
                                                   "boundaries": [[[r0, r0 + 1, r0 + 2, r0 + 3],
                                                                   [r0 + 4, r0 + 5, r0 + 6, r0 + 7]]]}]},
            "field": {"type": "LandUse", "geometry": [{"type": "MultiSurface", "lod": "1" if version != "1.0" else 1,
                                                       "boundaries": [[[lu, lu + 1, lu + 2]]]}]},
        },
        "vertices": v,
    }
    if version == "1.1":
        # A second, coarser LoD of the house: a flat 10 x 10 m square (LoD 1) that the importer must not use.
        doc["CityObjects"]["house"]["geometry"].append(
            {"type": "MultiSurface", "lod": "1", "boundaries": [[[0, 1, 2, 3]]]})
    return doc


def write(name, text):
    with open(name, "w") as f:
        f.write(text)


def main():
    write("small_city.osm", small_city())
    write("unsorted.osm", small_city(sort=False))
    write("malformed.osm", malformed())
    write("all_bad.osm", malformed(with_good=False, with_highway=False))
    with open("garbage.osm.pbf", "wb") as f:
        f.write(bytes((i * 37 + 11) % 256 for i in range(4096)))
    write("cube.city.json", json.dumps(cityjson_cube("2.0"), indent=1))
    write("cube_v11.city.json", json.dumps(cityjson_cube("1.1"), indent=1))
    bad = cityjson_cube("2.0")
    bad["CityObjects"] = {"house": {"type": "Building", "geometry": [{"type": "MultiSurface", "lod": "1", "boundaries": [
        [[0, 1, 2, 3]],            # good
        [[0, 1, 99999]],           # out of range
        [[0, -1, 2]],              # negative
        [[0, "one", 2]],           # not an integer
        [[0, 1]],                  # too few vertices
        [[0, 1, 1, 0]],            # no area
    ]}]}}
    write("bad_index.city.json", json.dumps(bad, indent=1))
    all_bad = json.loads(json.dumps(bad))
    all_bad["CityObjects"]["house"]["geometry"][0]["boundaries"] = [[[0, 1, 99999]], [[7, 7, 7]]]
    write("all_bad.city.json", json.dumps(all_bad, indent=1))
    unknown = cityjson_cube("2.0")
    unknown["version"] = "3.7"
    write("unknown_version.city.json", json.dumps(unknown, indent=1))
    write("not_cityjson.city.json", json.dumps({"type": "FeatureCollection", "features": []}))
    text = json.dumps(cityjson_cube("2.0"), indent=1)
    write("truncated.city.json", text[: len(text) // 2])


if __name__ == "__main__":
    main()
