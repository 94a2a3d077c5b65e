// Checks of a 3D Tiles 1.0/1.1 tileset against rules of the specification, written in Farfield (the Cesium 3D Tiles
// validator is not in any registry Farfield installs from). Used by exportTiles before it reports success and by the
// tests, which hand-break tilesets to see each rule refuse them.
//
// Rules checked (each problem names the file and the tile, e.g. "tileset.json: root.children[1].children[0]: ..."):
//   - the file is JSON with "asset" (an object with "version" "1.0" or "1.1"), a finite, non-negative top-level
//     "geometricError" that is not below the root's, and "root";
//   - every tile has one bounding volume ("box": 12 numbers, or "sphere": 4 numbers with a non-negative radius; a
//     "region" is reported as not checkable), a finite, non-negative "geometricError", an optional "transform" of 16
//     finite numbers, "refine" "ADD" or "REPLACE" (required on the root, inherited below), "children" an array;
//   - a child's geometricError does not exceed its parent's;
//   - a child's bounding volume lies inside its parent's (both taken to the root's frame through the tiles'
//     transforms; tolerance 1e-6 of the parent's size plus 1 mm);
//   - every content "uri" (1.0/1.1 "content", 1.1 "contents") resolves to a file relative to the tileset; a .glb
//     content must be glTF 2.0 binary whose meshes, through its node matrices and the y-up to z-up turn of glTF
//     content, lie inside the tile's bounding volume (from the POSITION accessors' min and max).
#pragma once

#include <string>
#include <vector>

namespace farfield::store {

// Every problem found in the tileset at `tileset_path` (tileset.json); empty when it passes. A file that cannot be
// read or parsed is one problem.
std::vector<std::string> checkTileset(const std::string& tileset_path);

// Throws farfield::Error naming the tileset with the first problems (and their count) when checkTileset finds any.
void requireValidTileset(const std::string& tileset_path);

}  // namespace farfield::store
