# ff_tinygltf, ff_stb, ff_osmium: Debian packages without a CMake config of their own, found here and wrapped as
# imported targets that the modules link. Included by cmake/Dependencies.cmake (the build) and by the installed
# farfieldConfig.cmake (a program using the package), so both find the same libraries on their own machine and no
# path of the build machine is written into the package. Needs Threads, EXPAT, BZip2 and ZLIB found before.
# Sets FF_SYSTEM_TARGETS_MISSING to the names of what was not found (empty when all were).
set(FF_SYSTEM_TARGETS_MISSING "")
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h)
find_library(TINYGLTF_LIBRARY tinygltf)
find_path(STB_INCLUDE_DIR stb_image.h PATH_SUFFIXES stb)
find_library(STB_LIBRARY stb)
find_path(OSMIUM_INCLUDE_DIR osmium/version.hpp)
find_path(PROTOZERO_INCLUDE_DIR protozero/version.hpp)
foreach(var TINYGLTF_INCLUDE_DIR TINYGLTF_LIBRARY STB_INCLUDE_DIR STB_LIBRARY OSMIUM_INCLUDE_DIR PROTOZERO_INCLUDE_DIR)
  if(NOT ${var})
    list(APPEND FF_SYSTEM_TARGETS_MISSING ${var})
  endif()
endforeach()

if(NOT FF_SYSTEM_TARGETS_MISSING AND NOT TARGET ff_tinygltf)
  # tinygltf ships a shared library and a header (libtinygltf-dev).
  add_library(ff_tinygltf INTERFACE IMPORTED)
  set_target_properties(ff_tinygltf PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${TINYGLTF_INCLUDE_DIR}"
                                               INTERFACE_LINK_LIBRARIES "${TINYGLTF_LIBRARY}")
  # stb: Debian builds the implementations into libstb (libstb-dev).
  add_library(ff_stb INTERFACE IMPORTED)
  set_target_properties(ff_stb PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${STB_INCLUDE_DIR}"
                                          INTERFACE_LINK_LIBRARIES "${STB_LIBRARY}")
  # libosmium (header-only, with protozero); its readers need expat (XML), bzip2 and zlib (compressed blocks) and
  # threads (parallel decoding).
  add_library(ff_osmium INTERFACE IMPORTED)
  set_target_properties(ff_osmium PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${OSMIUM_INCLUDE_DIR};${PROTOZERO_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "EXPAT::EXPAT;BZip2::BZip2;ZLIB::ZLIB;Threads::Threads")
endif()
