# The CMake package test (tests/package/CMakeLists.txt registers it; docs/cmake_package.md):
#   1. installs the build tree into a fresh prefix (`cmake --install BUILD --prefix PREFIX`);
#   2. checks that the installed package files hold no path of this machine (build or source
#      tree, /usr/lib, /usr/include: dependencies are found again by name on the user's machine);
#   3. configures tests/package/consumer/ with -DCMAKE_PREFIX_PATH=PREFIX, the same compiler,
#      generator and build type (and, in a sanitized build, the same sanitizer flags: the
#      installed static libraries call the sanitizer runtime, which the program must link),
#      builds it and runs its two programs, which check results known by hand;
#   4. runs the installed bin/hybrid on an installed model (PREFIX/share/hybrid/spec/);
#   5. checks what is installed: one bin/hybrid, headers only under include/hybrid/, none of them
#      naming Z3, PPL or SUNDIALS (the outside project compiles one file including them all);
#   6. builds the outside project's first program against the build tree's package
#      (-Dhybrid_DIR=BUILD, no install);
#   7. configures an outside project that includes hybrid with add_subdirectory
#      (tests/package/subproject/) and checks that it would build no test, benchmark, Python
#      module or program of hybrid.
# Run as `cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -DMAKE_PROGRAM=...
# -DCXX_COMPILER=... -DBUILD_TYPE=... -DSANITIZE=ON|OFF -P package_test.cmake`.
cmake_minimum_required(VERSION 3.25)

foreach(name BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${name} OR "${${name}}" STREQUAL "")
    message(FATAL_ERROR "package test: ${name} not given")
  endif()
endforeach()

set(prefix ${WORK_DIR}/prefix)
set(consumer ${WORK_DIR}/consumer)

# Runs a command; on failure prints what it wrote and stops the test. The output is returned in
# `out_var` (stdout and stderr together).
function(run_step what out_var)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "package test: ${what} failed (${result}):\n${output}")
  endif()
  message(STATUS "package test: ${what}: done")
  set(${out_var} "${output}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

# 1. Install.
run_step("cmake --install" output ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# 2. No path of this machine in the package files.
# (lib/ or, with a multiarch CMAKE_INSTALL_LIBDIR, lib/<arch>/)
file(GLOB_RECURSE config_file ${prefix}/lib*/hybridConfig.cmake)
if(NOT config_file)
  message(FATAL_ERROR "package test: no hybridConfig.cmake installed under ${prefix}/lib")
endif()
get_filename_component(package_dir "${config_file}" DIRECTORY)
file(GLOB package_files ${package_dir}/*.cmake)
foreach(file ${package_files})
  file(READ ${file} text)
  foreach(path ${BUILD_DIR} ${SOURCE_DIR} /usr/lib /usr/include)
    string(FIND "${text}" "${path}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "package test: ${file} names the path ${path} of this machine")
    endif()
  endforeach()
endforeach()
message(STATUS "package test: ${package_dir} names no path of this machine")

# 5. What is installed: the program once, the public headers only, free of the engines' libraries.
string(REGEX MATCHALL "Installing: [^\n]*/bin/hybrid\n" installs "${output}")
list(LENGTH installs count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "package test: bin/hybrid installed ${count} times (expected once)")
endif()
file(GLOB include_entries RELATIVE ${prefix}/include ${prefix}/include/*)
if(NOT include_entries STREQUAL "hybrid")
  message(FATAL_ERROR "package test: include/ holds '${include_entries}', expected only hybrid/")
endif()
file(GLOB_RECURSE headers ${prefix}/include/*)
set(all_headers "")
foreach(header ${headers})
  if(NOT header MATCHES "\\.h$")
    message(FATAL_ERROR "package test: ${header} installed under include/ is not a header")
  endif()
  # Their includes, types and names, as words (not "applied" or "opposite").
  file(STRINGS ${header} hits REGEX
       "(^|[^A-Za-z_])(z3|Z3|ppl|PPL|sundials|SUNDIALS|cvode|CVODE|CVode)([^A-Za-z_]|$)|z3::|Z3_|Parma_Polyhedra|N_Vector|SUNContext|z3\\+\\+|ppl\\.hh")
  if(hits)
    message(FATAL_ERROR "package test: ${header} names a solver library: ${hits}")
  endif()
  file(RELATIVE_PATH relative ${prefix}/include ${header})
  string(APPEND all_headers "#include \"${relative}\"\n")
endforeach()
list(LENGTH headers count)
message(STATUS "package test: ${count} public headers, none naming Z3, PPL or SUNDIALS")
file(WRITE ${WORK_DIR}/all_headers.cc "${all_headers}")

# 3. The outside project: configure, build, run.
set(configure ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/consumer -B ${consumer}
    -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DHYBRID_ALL_HEADERS=${WORK_DIR}/all_headers.cc)
if(MAKE_PROGRAM)
  list(APPEND configure -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM})
endif()
if(SANITIZE)
  list(APPEND configure
       "-DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
       "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined -fno-sanitize-recover=all")
endif()
run_step("configuring the outside project" output ${configure})
# The package found must be the one just installed (not one elsewhere on the machine).
file(STRINGS ${consumer}/CMakeCache.txt hybrid_dir REGEX "^hybrid_DIR:")
string(FIND "${hybrid_dir}" "${prefix}/" at)
if(NOT at GREATER -1)
  message(FATAL_ERROR "package test: the outside project found another hybrid: ${hybrid_dir}")
endif()
run_step("building the outside project" output ${CMAKE_COMMAND} --build ${consumer} --parallel 2)

foreach(program tank every_library)
  run_step("running ${program}" output ${consumer}/${program})
  message("${output}")
  if(NOT output MATCHES ": all checks passed")
    message(FATAL_ERROR "package test: ${program} did not report that all checks passed")
  endif()
endforeach()

# 4. The installed program on an installed model.
set(model ${prefix}/share/hybrid/spec/thermostat.ha)
run_step("installed hybrid info" output ${prefix}/bin/hybrid info ${model})
message("${output}")
if(NOT output MATCHES "modes \\(2\\): off, on" OR NOT output MATCHES "property comfortable")
  message(FATAL_ERROR "package test: `hybrid info` on the installed thermostat printed no modes "
                      "off, on and property comfortable")
endif()
# The documentation every --help names (cli.md) and the licences, in share/doc/hybrid/.
foreach(file cli.md python.md schemas/check.schema.json README.md CHANGELOG.md LICENSE
             LICENSE.GPL-3.0)
  if(NOT EXISTS ${prefix}/share/doc/hybrid/${file})
    message(FATAL_ERROR "package test: share/doc/hybrid/${file} is not installed")
  endif()
endforeach()
message(STATUS "package test: the documentation is installed in share/doc/hybrid/")
# 6. The build tree's package, without installing: the first program of the outside project.
set(configure_build_tree ${configure})
list(FILTER configure_build_tree EXCLUDE REGEX "^-DCMAKE_PREFIX_PATH=|^-B|^-DHYBRID_ALL_HEADERS=")
list(REMOVE_ITEM configure_build_tree ${consumer})
run_step("configuring the outside project on the build tree" output ${configure_build_tree}
         -B ${WORK_DIR}/consumer_build_tree -Dhybrid_DIR=${BUILD_DIR})
run_step("building tank on the build tree" output
         ${CMAKE_COMMAND} --build ${WORK_DIR}/consumer_build_tree --target tank --parallel 2)
run_step("running tank built on the build tree" output ${WORK_DIR}/consumer_build_tree/tank)
if(NOT output MATCHES ": all checks passed")
  message(FATAL_ERROR "package test: tank on the build tree did not pass its checks")
endif()

# 7. hybrid in an outside project by add_subdirectory: the libraries, nothing else.
set(subproject ${WORK_DIR}/subproject)
set(configure_sub ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/subproject -B ${subproject}
    -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DHYBRID_SOURCE_DIR=${SOURCE_DIR})
if(MAKE_PROGRAM)
  list(APPEND configure_sub -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM})
endif()
run_step("configuring a project with add_subdirectory(hybrid)" output ${configure_sub})
file(READ ${subproject}/CMakeCache.txt cache)
foreach(option HYBRID_BUILD_TESTS HYBRID_BUILD_BENCHMARKS HYBRID_BUILD_PYTHON HYBRID_BUILD_PROGRAM)
  if(NOT cache MATCHES "${option}:BOOL=OFF")
    message(FATAL_ERROR "package test: ${option} is not OFF in a project using add_subdirectory")
  endif()
endforeach()
if(EXISTS ${subproject}/hybrid/tests OR EXISTS ${subproject}/hybrid/benchmarks
   OR EXISTS ${subproject}/hybrid/python OR EXISTS ${subproject}/hybrid/cli)
  message(FATAL_ERROR "package test: add_subdirectory(hybrid) set up tests, benchmarks, Python "
                      "or the program")
endif()
message(STATUS "package test: add_subdirectory(hybrid) gives the libraries and builds no test")

# Passed: the installed copy goes (about 450 MB in the sanitized Debug build); a failed run keeps
# it for a look.
file(REMOVE_RECURSE ${WORK_DIR})
message(STATUS "package test: passed")
