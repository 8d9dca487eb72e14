# `cmake --install`: the public headers (include/synthvis, installed by sv_publish_headers), the
# stage libraries (static) with a CMake package — find_package(synthvis CONFIG) gives
# synthvis::synthvis, what a program links — and a pkg-config file, synthvis.pc. The stage targets
# (synthvis::<stage>) are exported because synthvis::synthvis links them; their own headers are
# internal and not installed, so they carry libraries, not an API. The CLI installs
# itself (apps/synthvis). tests/install builds a small program against an installed copy.
include(CMakePackageConfigHelpers)

set(SV_INSTALLED_STAGES sv_core sv_texture sv_scene_records sv_scene sv_formats sv_generators
    sv_traversal sv_geometry sv_shade sv_raster sv_terrain sv_freeform sv_lights sv_lines
    sv_segments sv_volume sv_display sv_output sv_render)
foreach(lib IN LISTS SV_INSTALLED_STAGES)
  string(REPLACE "sv_" "" stage ${lib})
  set_target_properties(${lib} PROPERTIES EXPORT_NAME ${stage})
endforeach()
install(TARGETS synthvis ${SV_INSTALLED_STAGES} EXPORT synthvisTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
set(SV_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/synthvis)
install(EXPORT synthvisTargets NAMESPACE synthvis:: DESTINATION ${SV_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/synthvisConfig.cmake.in
  ${PROJECT_BINARY_DIR}/synthvisConfig.cmake INSTALL_DESTINATION ${SV_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/synthvisConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/synthvisConfig.cmake
              ${PROJECT_BINARY_DIR}/synthvisConfigVersion.cmake DESTINATION ${SV_CMAKE_DIR})

# pkg-config: the libraries in link order (each before what it uses); the dependencies' own .pc
# files in Requires, since the libraries are static.
set(SV_PC_LIBS "")
foreach(lib sv_generators sv_render sv_traversal sv_display sv_output sv_volume sv_segments
            sv_lines sv_lights sv_freeform sv_formats sv_terrain sv_raster sv_shade sv_geometry
            sv_scene sv_texture sv_core)
  string(APPEND SV_PC_LIBS " -l${lib}")
endforeach()
# Relocatable: the prefix is found from the .pc file's own place, wherever --prefix put it.
file(RELATIVE_PATH SV_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${PROJECT_SOURCE_DIR}/cmake/synthvis.pc.in ${PROJECT_BINARY_DIR}/synthvis.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/synthvis.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
