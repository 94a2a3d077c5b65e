# Every dependency is a Debian package (scripts/install-deps.sh); nothing is downloaded at build time.
find_package(PkgConfig REQUIRED)
find_package(glm REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenGL REQUIRED COMPONENTS EGL OpenGL)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(GLFW REQUIRED IMPORTED_TARGET glfw3)
find_package(PNG REQUIRED)
find_package(assimp REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(CLI11 REQUIRED)
find_package(TBB REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
# xxHash: the terrain tile cache's row checksums (terrain/tile_cache.h), inlined from its header.
pkg_check_modules(XXHASH REQUIRED libxxhash)

if(FF_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(FF_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

# CGAL (header-only in Debian 12): constrained Delaunay triangulation of impostor depth meshes.
find_package(CGAL REQUIRED)

# GDAL: DEM input (GeoTIFF, netCDF, 16-bit PNG) for the terrain module.
find_package(GDAL REQUIRED)

# libosmium's readers need expat (XML), bzip2 and zlib (compressed blocks).
find_package(EXPAT REQUIRED)
find_package(BZip2 REQUIRED)
find_package(ZLIB REQUIRED)
# tinygltf, stb, libosmium: no CMake config in Debian 12; wrapped as ff_tinygltf, ff_stb, ff_osmium.
include(${CMAKE_CURRENT_LIST_DIR}/FarfieldSystemTargets.cmake)
if(FF_SYSTEM_TARGETS_MISSING)
  message(FATAL_ERROR "not found: ${FF_SYSTEM_TARGETS_MISSING} (run scripts/install-deps.sh)")
endif()

# meshoptimizer: simplification of the 3D Tiles export's heightfield impostors (store/export_tiles.h).
find_package(meshoptimizer REQUIRED)

# PROJ: geographic coordinates (OSM) to local metres (UTM) in the geodata module.
pkg_check_modules(PROJ REQUIRED IMPORTED_TARGET proj)
