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

# tinygltf ships a shared library and a header (no CMake config in Debian 12).
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
find_library(TINYGLTF_LIBRARY tinygltf REQUIRED)
add_library(ff_tinygltf INTERFACE)
target_include_directories(ff_tinygltf SYSTEM INTERFACE ${TINYGLTF_INCLUDE_DIR})
target_link_libraries(ff_tinygltf INTERFACE ${TINYGLTF_LIBRARY})

# stb: Debian builds the implementations into libstb.
find_path(STB_INCLUDE_DIR stb_image.h PATH_SUFFIXES stb REQUIRED)
find_library(STB_LIBRARY stb REQUIRED)
add_library(ff_stb INTERFACE)
target_include_directories(ff_stb SYSTEM INTERFACE ${STB_INCLUDE_DIR})
target_link_libraries(ff_stb INTERFACE ${STB_LIBRARY})

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

# libosmium (header-only, with protozero) for OpenStreetMap PBF/XML input in the geodata module; its readers need
# expat (XML), bzip2 and zlib (compressed blocks) and threads (parallel decoding).
find_path(OSMIUM_INCLUDE_DIR osmium/version.hpp REQUIRED)
find_path(PROTOZERO_INCLUDE_DIR protozero/version.hpp REQUIRED)
find_package(EXPAT REQUIRED)
find_package(BZip2 REQUIRED)
find_package(ZLIB REQUIRED)
add_library(ff_osmium INTERFACE)
target_include_directories(ff_osmium SYSTEM INTERFACE ${OSMIUM_INCLUDE_DIR} ${PROTOZERO_INCLUDE_DIR})
target_link_libraries(ff_osmium INTERFACE EXPAT::EXPAT BZip2::BZip2 ZLIB::ZLIB Threads::Threads)

# PROJ: geographic coordinates (OSM) to local metres (UTM) in the geodata module.
pkg_check_modules(PROJ REQUIRED IMPORTED_TARGET proj)
