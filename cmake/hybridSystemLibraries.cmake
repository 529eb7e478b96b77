# The system libraries without a CMake package of their own that the static hybrid libraries
# link privately (a program linking them must link these too): Z3 for hybrid::verification and
# the Parma Polyhedra Library with GMP for hybrid::reachability. Included by hybridConfig.cmake,
# which finds them on the consumer's machine, by name, and defines
#   hybrid::z3    libz3 (and the directory of z3++.h, which no installed header includes);
#   hybrid::ppl   libppl with libgmpxx and libgmp (and the directory of ppl.hh).
# The exported targets name these instead of the build machine's library paths. When one is
# missing, hybrid_SYSTEM_LIBRARIES_MISSING lists what is missing (its Debian package in brackets).

set(hybrid_SYSTEM_LIBRARIES_MISSING "")

if(NOT TARGET hybrid::z3)
  find_library(hybrid_Z3_LIBRARY z3)
  find_path(hybrid_Z3_INCLUDE_DIR z3++.h)
  mark_as_advanced(hybrid_Z3_LIBRARY hybrid_Z3_INCLUDE_DIR)
  if(hybrid_Z3_LIBRARY)
    add_library(hybrid::z3 UNKNOWN IMPORTED)
    set_target_properties(hybrid::z3 PROPERTIES IMPORTED_LOCATION "${hybrid_Z3_LIBRARY}")
    if(hybrid_Z3_INCLUDE_DIR)
      set_target_properties(hybrid::z3 PROPERTIES
        INTERFACE_INCLUDE_DIRECTORIES "${hybrid_Z3_INCLUDE_DIR}")
    endif()
  else()
    list(APPEND hybrid_SYSTEM_LIBRARIES_MISSING "z3 (libz3-dev)")
  endif()
endif()

if(NOT TARGET hybrid::ppl)
  find_library(hybrid_PPL_LIBRARY ppl)
  find_library(hybrid_GMPXX_LIBRARY gmpxx)
  find_library(hybrid_GMP_LIBRARY gmp)
  find_path(hybrid_PPL_INCLUDE_DIR ppl.hh PATH_SUFFIXES ${CMAKE_LIBRARY_ARCHITECTURE})
  mark_as_advanced(hybrid_PPL_LIBRARY hybrid_GMPXX_LIBRARY hybrid_GMP_LIBRARY
                   hybrid_PPL_INCLUDE_DIR)
  if(hybrid_PPL_LIBRARY AND hybrid_GMPXX_LIBRARY AND hybrid_GMP_LIBRARY)
    add_library(hybrid::ppl UNKNOWN IMPORTED)
    set_target_properties(hybrid::ppl PROPERTIES
      IMPORTED_LOCATION "${hybrid_PPL_LIBRARY}"
      INTERFACE_LINK_LIBRARIES "${hybrid_GMPXX_LIBRARY};${hybrid_GMP_LIBRARY}")
    if(hybrid_PPL_INCLUDE_DIR)
      set_target_properties(hybrid::ppl PROPERTIES
        INTERFACE_INCLUDE_DIRECTORIES "${hybrid_PPL_INCLUDE_DIR}")
    endif()
  else()
    foreach(name ppl gmpxx gmp)
      string(TOUPPER ${name} upper)
      if(NOT hybrid_${upper}_LIBRARY)
        list(APPEND hybrid_SYSTEM_LIBRARIES_MISSING "${name} (libppl-dev, libgmp-dev)")
      endif()
    endforeach()
  endif()
endif()
