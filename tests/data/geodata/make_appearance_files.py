#!/usr/bin/env python3
"""Writes the hand-made CityGML and textured CityJSON test files of tests/geodata (run from this directory).

Every building is a box or a gabled house whose areas and triangle counts are easy to compute by hand (see
tests/geodata/test_citygml_import.cpp and test_cityjson_import.cpp for the sums).

facade.png              a 4 x 2 RGBA texture: row 0 (top) red, green, blue, white; row 1 black, yellow, cyan, magenta.
citygml2_city.gml       CityGML 2.0, EPSG:25832, origin (690000, 5336000, 500):
                          b1  LoD1 Solid box x 0..10, y 0..10, z 0..10 (12 triangles, 600 m^2)
                          b2  LoD2 gabled house x 20..28, y 0..6: walls to z 6, ridge along x at y 3, z 9; bounded by
                              Ground/Wall/RoofSurfaces (16 triangles, 301.882 m^2); its south wall textured with
                              facade.png, its roof an X3DMaterial (diffuse 0.8 0.2 0.1)
                          b3  no geometry of its own, two BuildingParts: box x 40..46, y 0..6, z 0..6 and box
                              x 46..50, y 0..4, z 0..12 (24 triangles, 216 + 224 m^2)
                          b4  LoD1 box x 60..65, y 0..5, z 0..3 whose roof names a texture that does not exist
                              (12 triangles, 110 m^2)
citygml1_city.gml       the same city as CityGML 1.0.
citygml2_streets.gml    CityGML 2.0: a 3 x 3 grid of 10 m wide roads (tran:Road, lod1MultiSurface) around 4 square
                        blocks 100 m on a side, with one LoD1 box building in each block and two in the south-west
                        block.
citygml2_truncated.gml  citygml2_city.gml cut in the middle of a polygon.
textured.city.json      CityJSON 2.0 (and textured_v10.city.json, CityJSON 1.0 without a transform): b2 and b4 as
                        above, with appearance.textures (facade.png, a missing file), vertices-texture, a second
                        theme and a diffuseColor material on the roof.
"""
import json
import struct
import zlib

X0, Y0, Z0 = 690000.0, 5336000.0, 500.0


# --- PNG -----------------------------------------------------------------------------------------------------------
def write_png(path, rows):
    raw = b''.join(b'\x00' + bytes(c for px in row for c in px) for row in rows)
    def chunk(tag, data):
        return struct.pack('>I', len(data)) + tag + data + struct.pack('>I', zlib.crc32(tag + data) & 0xffffffff)
    h, w = len(rows), len(rows[0])
    png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 6, 0, 0, 0))
    png += chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b'')
    open(path, 'wb').write(png)


# --- geometry: faces as rings of (x, y, z), counter-clockwise seen from outside ------------------------------------
def box(x0, y0, z0, x1, y1, z1):
    """Six faces of an axis-aligned box, outward."""
    return {
        'ground': [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],
        'roof': [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],
        'wall_s': [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],
        'wall_e': [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],
        'wall_n': [(x1, y1, z0), (x0, y1, z0), (x0, y1, z1), (x1, y1, z1)],
        'wall_w': [(x0, y1, z0), (x0, y0, z0), (x0, y0, z1), (x0, y1, z1)],
    }


def house(x0, y0, x1, y1, eaves, ridge):
    """Gabled house, ridge along x at the middle of y."""
    ym = 0.5 * (y0 + y1)
    return {
        'ground': [(x0, y0, 0), (x0, y1, 0), (x1, y1, 0), (x1, y0, 0)],
        'wall_s': [(x0, y0, 0), (x1, y0, 0), (x1, y0, eaves), (x0, y0, eaves)],
        'wall_n': [(x1, y1, 0), (x0, y1, 0), (x0, y1, eaves), (x1, y1, eaves)],
        'wall_e': [(x1, y0, 0), (x1, y1, 0), (x1, y1, eaves), (x1, ym, ridge), (x1, y0, eaves)],
        'wall_w': [(x0, y1, 0), (x0, y0, 0), (x0, y0, eaves), (x0, ym, ridge), (x0, y1, eaves)],
        'roof_s': [(x0, y0, eaves), (x1, y0, eaves), (x1, ym, ridge), (x0, ym, ridge)],
        'roof_n': [(x1, y1, eaves), (x0, y1, eaves), (x0, ym, ridge), (x1, ym, ridge)],
    }


B1 = box(0, 0, 0, 10, 10, 10)
B2 = house(20, 0, 28, 6, 6, 9)
B3A = box(40, 0, 0, 46, 6, 6)
B3B = box(46, 0, 0, 50, 4, 12)
B4 = box(60, 0, 0, 65, 5, 3)
# Texture coordinates of b2's south wall (x 20..28, z 0..6): u = (x - 20) / 8, v = z / 6 (v up, as in the files).
B2_WALL_S_UV = [(0, 0), (1, 0), (1, 1), (0, 1)]
B4_ROOF_UV = [(0, 0), (1, 0), (1, 1), (0, 1)]


# --- CityGML ---------------------------------------------------------------------------------------------------------
def ns(version):
    v = '2.0' if version == 2 else '1.0'
    return (f'xmlns:core="http://www.opengis.net/citygml/{v}" xmlns:bldg="http://www.opengis.net/citygml/building/{v}" '
            f'xmlns:app="http://www.opengis.net/citygml/appearance/{v}" '
            f'xmlns:tran="http://www.opengis.net/citygml/transportation/{v}" '
            'xmlns:gml="http://www.opengis.net/gml" xmlns:xlink="http://www.w3.org/1999/xlink"')


def pos_list(ring):
    pts = ring + [ring[0]]
    return ' '.join(f'{X0 + x:.3f} {Y0 + y:.3f} {Z0 + z:.3f}' for x, y, z in pts)


def polygon(pid, ring):
    return (f'<gml:Polygon gml:id="{pid}"><gml:exterior><gml:LinearRing gml:id="{pid}_ring">'
            f'<gml:posList srsDimension="3">{pos_list(ring)}</gml:posList></gml:LinearRing></gml:exterior>'
            '</gml:Polygon>')


def lod1_solid(prefix, faces):
    members = ''.join(f'<gml:surfaceMember>{polygon(f"{prefix}_{name}", ring)}</gml:surfaceMember>'
                      for name, ring in faces.items())
    return (f'<bldg:lod1Solid><gml:Solid><gml:exterior><gml:CompositeSurface>{members}</gml:CompositeSurface>'
            '</gml:exterior></gml:Solid></bldg:lod1Solid>')


def lod2_bounded(prefix, faces):
    kinds = {'ground': 'GroundSurface', 'wall': 'WallSurface', 'roof': 'RoofSurface'}
    out = ''
    for name, ring in faces.items():
        kind = kinds[name.split('_')[0]]
        out += (f'<bldg:boundedBy><bldg:{kind} gml:id="{prefix}_{name}_surface"><bldg:lod2MultiSurface>'
                f'<gml:MultiSurface><gml:surfaceMember>{polygon(f"{prefix}_{name}", ring)}</gml:surfaceMember>'
                f'</gml:MultiSurface></bldg:lod2MultiSurface></bldg:{kind}></bldg:boundedBy>')
    return out


def tex_coords(uv):
    pts = uv + [uv[0]]
    return ' '.join(f'{u:g} {v:g}' for u, v in pts)


def appearance():
    return (
        '<app:appearanceMember><app:Appearance><app:theme>rgbTexture</app:theme>'
        '<app:surfaceDataMember><app:ParameterizedTexture><app:imageURI>facade.png</app:imageURI>'
        '<app:mimeType>image/png</app:mimeType>'
        f'<app:target uri="#b2_wall_s"><app:TexCoordList><app:textureCoordinates ring="#b2_wall_s_ring">'
        f'{tex_coords(B2_WALL_S_UV)}</app:textureCoordinates></app:TexCoordList></app:target>'
        '</app:ParameterizedTexture></app:surfaceDataMember>'
        '<app:surfaceDataMember><app:ParameterizedTexture><app:imageURI>textures/missing_roof.jpg</app:imageURI>'
        f'<app:target uri="#b4_roof"><app:TexCoordList><app:textureCoordinates ring="#b4_roof_ring">'
        f'{tex_coords(B4_ROOF_UV)}</app:textureCoordinates></app:TexCoordList></app:target>'
        '</app:ParameterizedTexture></app:surfaceDataMember>'
        '<app:surfaceDataMember><app:X3DMaterial><app:diffuseColor>0.8 0.2 0.1</app:diffuseColor>'
        '<app:target>#b2_roof_s</app:target><app:target>#b2_roof_n</app:target></app:X3DMaterial>'
        '</app:surfaceDataMember></app:Appearance></app:appearanceMember>')


def envelope(lo, hi):
    return (f'<gml:boundedBy><gml:Envelope srsName="EPSG:25832" srsDimension="3">'
            f'<gml:lowerCorner>{X0 + lo[0]:.3f} {Y0 + lo[1]:.3f} {Z0 + lo[2]:.3f}</gml:lowerCorner>'
            f'<gml:upperCorner>{X0 + hi[0]:.3f} {Y0 + hi[1]:.3f} {Z0 + hi[2]:.3f}</gml:upperCorner>'
            '</gml:Envelope></gml:boundedBy>')


def member(body):
    return f'<core:cityObjectMember>{body}</core:cityObjectMember>\n'


def city_gml(version):
    parts = ''.join(
        f'<bldg:consistsOfBuildingPart><bldg:BuildingPart gml:id="b3_{k}">{lod1_solid(f"b3{k}", faces)}'
        '</bldg:BuildingPart></bldg:consistsOfBuildingPart>' for k, faces in (('a', B3A), ('b', B3B)))
    body = (member(f'<bldg:Building gml:id="b1">{lod1_solid("b1", B1)}</bldg:Building>') +
            member(f'<bldg:Building gml:id="b2">{lod2_bounded("b2", B2)}</bldg:Building>') +
            member(f'<bldg:Building gml:id="b3">{parts}</bldg:Building>') +
            member(f'<bldg:Building gml:id="b4">{lod1_solid("b4", B4)}</bldg:Building>'))
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<core:CityModel {ns(version)}>\n'
            f'{envelope((0, 0, 0), (65, 10, 12))}\n{body}{appearance()}\n</core:CityModel>\n')


def streets_gml():
    # Roads: the centre lines x = 0, 110, 220 and y = 0, 110, 220 (10 m wide, from -5 to 225), as rectangles that
    # overlap at the crossings (each road one tran:Road with one polygon).
    roads = []
    for c in (0, 110, 220):
        roads.append([(c - 5, -5, 0), (c + 5, -5, 0), (c + 5, 225, 0), (c - 5, 225, 0)])   # north-south
        roads.append([(-5, c - 5, 0), (225, c - 5, 0), (225, c + 5, 0), (-5, c + 5, 0)])   # east-west
    body = ''
    for i, ring in enumerate(roads):
        body += member(f'<tran:Road gml:id="road{i}"><tran:lod1MultiSurface><gml:MultiSurface><gml:surfaceMember>'
                       f'{polygon(f"road{i}_p", ring)}</gml:surfaceMember></gml:MultiSurface></tran:lod1MultiSurface>'
                       '</tran:Road>')
    # Blocks span 5..105 and 115..215 on each axis: one 20 x 20 x 15 building in each, two in the south-west one.
    buildings = [(45, 45), (155, 45), (45, 155), (155, 155), (15, 15)]
    for i, (x, y) in enumerate(buildings):
        body += member(f'<bldg:Building gml:id="s{i}">{lod1_solid(f"s{i}", box(x, y, 0, x + 20, y + 20, 15))}'
                       '</bldg:Building>')
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<core:CityModel {ns(2)}>\n'
            f'{envelope((-5, -5, 0), (225, 225, 15))}\n{body}</core:CityModel>\n')


# --- CityJSON --------------------------------------------------------------------------------------------------------
def city_json(version):
    vertices, index = [], {}
    def vid(p):
        if p not in index:
            index[p] = len(vertices)
            vertices.append(p)
        return index[p]
    order2 = ['ground', 'wall_s', 'wall_n', 'wall_e', 'wall_w', 'roof_s', 'roof_n']
    order4 = ['ground', 'roof', 'wall_s', 'wall_e', 'wall_n', 'wall_w']
    uv = [list(p) for p in B2_WALL_S_UV] + [list(p) for p in B4_ROOF_UV]
    # Texture 0: facade.png on b2's south wall (uv 0..3); texture 1: a missing file on b4's roof (uv 4..7); in the
    # second theme ("winter") b2's south wall has texture 1. Material 0 (roof) in theme "summer".
    def geometry(faces, order, texture_faces, material_faces):
        shell = [[[vid((X0 + x, Y0 + y, Z0 + z)) for x, y, z in faces[name]]] for name in order]
        g = {'type': 'Solid', 'lod': '2' if version != '1.0' else 2, 'boundaries': [shell]}
        themes = {}
        for theme, per_face in texture_faces.items():
            themes[theme] = {'values': [[[[t] + uvs] if t is not None else [[None]] for t, uvs in
                                        (per_face.get(name, (None, None)) for name in order)]]}
        if themes:
            g['texture'] = themes
        if material_faces:
            g['material'] = {'summer': {'values': [[material_faces.get(name) for name in order]]}}
        return g
    b2 = geometry(B2, order2, {'summer': {'wall_s': (0, [0, 1, 2, 3])}, 'winter': {'wall_s': (1, [0, 1, 2, 3])}},
                  {'roof_s': 0, 'roof_n': 0})
    b4 = geometry(B4, order4, {'summer': {'roof': (1, [4, 5, 6, 7])}}, {})
    doc = {'type': 'CityJSON', 'version': version,
           'metadata': {'referenceSystem': 'https://www.opengis.net/def/crs/EPSG/0/25832'},
           'CityObjects': {'b2': {'type': 'Building', 'geometry': [b2]}, 'b4': {'type': 'Building', 'geometry': [b4]}},
           'appearance': {
               'textures': [{'type': 'PNG', 'image': 'facade.png'}, {'type': 'JPG', 'image': 'textures/missing_roof.jpg'}],
               'vertices-texture': uv,
               'materials': [{'name': 'roof tiles', 'diffuseColor': [0.8, 0.2, 0.1]}]}}
    if version == '1.0':
        doc['vertices'] = [list(p) for p in vertices]
    else:
        doc['transform'] = {'scale': [0.001, 0.001, 0.001], 'translate': [X0, Y0, Z0]}
        doc['vertices'] = [[round((p[0] - X0) * 1000), round((p[1] - Y0) * 1000), round((p[2] - Z0) * 1000)]
                           for p in vertices]
    return json.dumps(doc, indent=1)


if __name__ == '__main__':
    write_png('facade.png', [[(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (255, 255, 255, 255)],
                             [(0, 0, 0, 255), (255, 255, 0, 255), (0, 255, 255, 255), (255, 0, 255, 255)]])
    open('citygml2_city.gml', 'w').write(city_gml(2))
    open('citygml1_city.gml', 'w').write(city_gml(1))
    open('citygml2_streets.gml', 'w').write(streets_gml())
    text = city_gml(2)
    cut = text.index('b3a_wall_e')
    open('citygml2_truncated.gml', 'w').write(text[:cut + 200])
    open('textured.city.json', 'w').write(city_json('2.0'))
    open('textured_v10.city.json', 'w').write(city_json('1.0'))
