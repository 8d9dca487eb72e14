# Layering by the build (docs/ARCHITECTURE.md, "Layering"). Each stage library publishes only its
# own headers: its include root in the build tree, stage-include/<library>/, holds a link to its
# own folder (src/<stage>, included as "<stage>/…") and links to the public headers it owns
# (include/synthvis/<h>, included as "synthvis/<h>"). A library sees its own root and those of the
# libraries it links PUBLIC (transitively), nothing else — so an include that crosses the pipeline
# the wrong way names a file that is not there, and the build fails (tests/layering holds it).
include(GNUInstallDirs)

# sv_publish_headers(TARGET [STAGE dir] [PUBLIC_HEADERS h…] [NOT_INSTALLED]): TARGET's include
# root as above. The public headers are installed under include/synthvis (the stage's own headers
# are internal and stay in the source tree) — unless NOT_INSTALLED: the library is not installed
# (the IG, the bench harness, prep, the cluster: the CLI's, apps/synthvis), so neither are its
# headers, which are public to the programs of this tree.
function(sv_publish_headers target)
  cmake_parse_arguments(P "NOT_INSTALLED" "STAGE" "PUBLIC_HEADERS" ${ARGN})
  set(root "${PROJECT_BINARY_DIR}/stage-include/${target}")
  file(REMOVE_RECURSE "${root}")
  file(MAKE_DIRECTORY "${root}")
  if(P_STAGE)
    file(CREATE_LINK "${PROJECT_SOURCE_DIR}/src/${P_STAGE}" "${root}/${P_STAGE}" SYMBOLIC)
  endif()
  set(installed "")
  foreach(h IN LISTS P_PUBLIC_HEADERS)
    file(MAKE_DIRECTORY "${root}/synthvis")
    file(CREATE_LINK "${PROJECT_SOURCE_DIR}/include/synthvis/${h}" "${root}/synthvis/${h}" SYMBOLIC)
    list(APPEND installed "${PROJECT_SOURCE_DIR}/include/synthvis/${h}")
  endforeach()
  if(installed AND NOT P_NOT_INSTALLED)
    install(FILES ${installed} DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/synthvis")
  endif()
  get_target_property(type ${target} TYPE)
  set(scope PUBLIC)
  if(type STREQUAL "INTERFACE_LIBRARY")  # header-only: its users see the root, it has no sources
    set(scope INTERFACE)
  endif()
  target_include_directories(${target} ${scope} "$<BUILD_INTERFACE:${root}>"
                                                "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
endfunction()
