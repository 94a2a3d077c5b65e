#!/usr/bin/env bash
# Fills BUILD/corpus/<target>/ with the seed inputs of the fuzz targets (docs/FUZZING.md): the project's test files
# (tests/data), small files in the formats the targets read (written here), and what make_seeds writes with
# Farfield's own writers (stores, placement, cost profile, camera paths, street graph, DEMs, OSM PBF). Inputs the
# fuzzers added to a corpus before are kept; seeds are rewritten. Usage: fuzz/seed_corpus.sh [BUILD_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/fuzz}"
corpus="$build/corpus"
data="$root/tests/data"
mkdir -p "$corpus"

# With a leading byte: the targets that read the first byte as a choice of format and options.
prefixed() {  # prefixed TARGET BYTE FILE [NAME]
  local dir="$corpus/$1" name="${4:-$(basename "$3")}"
  mkdir -p "$dir"
  { printf "\\x$2"; cat "$3"; } > "$dir/seed_$name"
}
plain() {  # plain TARGET FILE [NAME]
  mkdir -p "$corpus/$1"
  cp "$2" "$corpus/$1/seed_${3:-$(basename "$2")}"
}

if [ -x "$build/bin/make_seeds" ]; then
  "$build/bin/make_seeds" "$corpus" "$data"
else
  echo "seed_corpus: $build/bin/make_seeds not built: no seeds of Farfield's own formats, DEMs or OSM PBF" >&2
fi

# CityJSON: the test files as they are.
for f in "$data"/geodata/*.city.json; do plain cityjson "$f"; done

# OSM: XML test files (bit 0 set), read only and whole import (bit 1); the PBF seeds come from make_seeds.
for f in "$data"/geodata/*.osm; do
  prefixed osm 01 "$f" "read_$(basename "$f")"
  prefixed osm 03 "$f" "import_$(basename "$f")"
done
prefixed osm 00 "$data/geodata/garbage.osm.pbf"

# assimp formats: byte 0 = 0 .obj, 1 .ac, 2 .ply, 3 .stl, 4 .off.
for f in "$data"/scene/*.obj; do prefixed assimp 00 "$f"; done
for f in "$data"/scene/*.ac; do if [ -e "$f" ]; then prefixed assimp 01 "$f"; fi; done
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/quad.ac" <<'AC'
AC3Db
MATERIAL "red" rgb 1 0 0  amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0
OBJECT world
kids 1
OBJECT poly
name "quad"
loc 0 0 0
numvert 4
0 0 0
1 0 0
1 1 0
0 1 0
numsurf 1
SURF 0x10
mat 0
refs 4
0 0 0
1 1 0
2 1 1
3 0 1
kids 0
AC
prefixed assimp 01 "$tmp/quad.ac"
cat > "$tmp/tri.ply" <<'PLY'
ply
format ascii 1.0
element vertex 3
property float x
property float y
property float z
element face 1
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
3 0 1 2
PLY
prefixed assimp 02 "$tmp/tri.ply"
python3 - "$tmp/tri_bin.ply" <<'PY'
import struct, sys
head = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n" \
       b"element face 1\nproperty list uchar int vertex_indices\nend_header\n"
body = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)
open(sys.argv[1], "wb").write(head + body)
PY
prefixed assimp 02 "$tmp/tri_bin.ply"
cat > "$tmp/tri.stl" <<'STL'
solid tri
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 1 0
endloop
endfacet
endsolid tri
STL
prefixed assimp 03 "$tmp/tri.stl"
printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n' > "$tmp/quad.off"
prefixed assimp 04 "$tmp/quad.off"

# glTF: a textured quad as .gltf (buffer and image as data: URIs) and as .glb.
python3 - "$tmp" <<'PY'
import base64, json, struct, sys, zlib
out = sys.argv[1]
pos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
uv = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
buf = pos + uv + idx
def png():  # 2 x 2 RGBA
    raw = b"".join(b"\x00" + bytes([255, 0, 0, 255, 0, 255, 0, 255]) for _ in range(2))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 6, 0, 0, 0)) + \
        chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
def gltf(uri):
    return {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "quad", "translation": [1, 0, 0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 1, 1, 1]}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(png()).decode()}],
        "buffers": [{"byteLength": len(buf)} | ({"uri": uri} if uri else {})],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]}
open(out + "/quad.gltf", "w").write(json.dumps(gltf("data:application/octet-stream;base64," + base64.b64encode(buf).decode())))
j = json.dumps(gltf(None)).encode()
j += b" " * (-len(j) % 4)
b = buf + b"\0" * (-len(buf) % 4)
body = struct.pack("<II", len(j), 0x4E4F534A) + j + struct.pack("<II", len(b), 0x004E4942) + b
open(out + "/quad.glb", "wb").write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
PY
plain gltf "$tmp/quad.gltf"
plain gltf "$tmp/quad.glb"

# Skinned glTF: the shared data's two animated models (read from ../shared/data, never copied into the repository),
# and the static quads (no skin: an error the target expects).
for f in "$root/../shared/data/models"/*.glb; do if [ -e "$f" ]; then plain gltf_skin "$f"; fi; done
plain gltf_skin "$tmp/quad.glb"

# CityGML (once the importer exists): the project's CityGML test files.
if [ -x "$build/bin/fuzz_citygml" ]; then
  for f in "$data"/geodata/*.gml "$data"/geodata/*.citygml; do if [ -e "$f" ]; then plain citygml "$f"; fi; done
fi

# Files that once crashed a reader (the regression tests read them) stay in the corpora.
for f in "$data"/terrain/fuzz/*.asc; do if [ -e "$f" ]; then prefixed dem 03 "$f"; fi; done

for d in "$corpus"/*/; do
  printf '%-16s %4d inputs\n' "$(basename "$d")" "$(find "$d" -type f | wc -l)"
done
