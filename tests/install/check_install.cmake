# `cmake --install` into a scratch prefix, then a program built against it two ways — with
# find_package(synthvis CONFIG) and with pkg-config — renders the demo scene, and the image must be
# the CLI's, byte for byte. Run by CTest (tests/install/CMakeLists.txt) with -D BUILD_DIR, SOURCE_DIR,
# WORK_DIR, CLI, CXX, CXX_FLAGS.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(f include/synthvis/render.h include/synthvis/scene.h bin/synthvis)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "cmake --install did not install ${f}")
  endif()
endforeach()
if(EXISTS ${prefix}/include/synthvis/raster OR EXISTS ${prefix}/include/raster)
  message(FATAL_ERROR "internal stage headers were installed")
endif()

# The reference image: the installed CLI's.
run(${prefix}/bin/synthvis render -o ${WORK_DIR}/cli.png --width 160 --height 90)

# 1. CMake: find_package(synthvis CONFIG).
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/consumer -B ${WORK_DIR}/cmake-build -G Ninja
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX} "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}")
run(${CMAKE_COMMAND} --build ${WORK_DIR}/cmake-build)
run(${WORK_DIR}/cmake-build/consumer ${WORK_DIR}/cmake.png)
if(NOT run_output STREQUAL "160x90\n")
  message(FATAL_ERROR "the CMake consumer printed '${run_output}'")
endif()

# 2. pkg-config.
file(GLOB pc_dirs ${prefix}/lib*/pkgconfig ${prefix}/lib/*/pkgconfig)
set(ENV{PKG_CONFIG_PATH} "${pc_dirs}")
run(pkg-config --cflags --libs synthvis)
string(STRIP "${run_output}" flags)
separate_arguments(flags UNIX_COMMAND "${flags}")
separate_arguments(extra UNIX_COMMAND "${CXX_FLAGS}")
run(${CXX} ${extra} ${SOURCE_DIR}/consumer/main.cpp ${flags} -o ${WORK_DIR}/pkg-consumer)
run(${WORK_DIR}/pkg-consumer ${WORK_DIR}/pkg.png)

foreach(png cmake.png pkg.png)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK_DIR}/cli.png ${WORK_DIR}/${png}
                  RESULT_VARIABLE differ)
  if(differ)
    message(FATAL_ERROR "${png} is not the CLI's image of the same frame")
  endif()
endforeach()
message(STATUS "installed package: CMake and pkg-config consumers render the CLI's image")
