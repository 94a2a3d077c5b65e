# `cmake --install BUILD --prefix P`: a relocatable package for programs that embed Farfield (docs/EMBEDDING.md).
#   P/lib/libfarfield_<module>.a          one static library per module (ff_module)
#   P/include/farfield/<module>/*.h       the public headers, included as "farfield/<module>/<file>.h"
#   P/lib/cmake/farfield/                 find_package(farfield CONFIG): farfield::<module>, farfield::farfield
#   P/bin/farfield, P/share/farfield/     the command-line tool and the plot scripts it and eval look for
# Every path in the exported files is relative to P; the dependencies (Debian packages) are found again on the
# machine that uses the package, by farfieldConfig.cmake.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FF_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/farfield)
get_property(ff_installed_modules GLOBAL PROPERTY FF_MODULES)
set_target_properties(farfield PROPERTIES EXPORT_NAME farfield)
add_library(farfield::farfield ALIAS farfield)

install(TARGETS ${ff_installed_modules} farfield EXPORT farfieldTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/farfield/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/farfield
        FILES_MATCHING PATTERN "*.h")
install(EXPORT farfieldTargets NAMESPACE farfield:: DESTINATION ${FF_INSTALL_CMAKEDIR})

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/farfieldConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/farfieldConfig.cmake INSTALL_DESTINATION ${FF_INSTALL_CMAKEDIR})
# Before 1.0 a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/farfieldConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/farfieldConfig.cmake ${PROJECT_BINARY_DIR}/farfieldConfigVersion.cmake
              ${CMAKE_CURRENT_LIST_DIR}/FarfieldSystemTargets.cmake
        DESTINATION ${FF_INSTALL_CMAKEDIR})

install(TARGETS farfield_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES ${PROJECT_SOURCE_DIR}/tools/plot_bench.py ${PROJECT_SOURCE_DIR}/tools/plot_terrain.py
        DESTINATION ${CMAKE_INSTALL_DATADIR}/farfield)
