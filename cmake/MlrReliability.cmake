# Sanitizer and fuzzing builds. Included by the top-level CMakeLists.txt before any
# target is defined, so that the flags reach Core, the CGAL translation unit, the filter module
# and the tests alike. VTK, ParaView, Embree, TBB and CGAL's libraries stay uninstrumented
# (they are Debian's builds): only our code is checked.
#
#   -DMLR_SANITIZE=address,undefined   ASan + UBSan, every UB report fatal
#   -DMLR_FUZZ=ON                      libFuzzer targets (clang only), with MLR_SANITIZE
#
# Tools/run-tests.sh configures build-asan (RelWithDebInfo, gcc) and build-fuzz (clang) this
# way and builds only the test and fuzz executables there.

set(MLR_SANITIZE "" CACHE STRING
  "Comma-separated sanitizers for Core, Filters and the tests (e.g. address,undefined); empty for none")
option(MLR_FUZZ "Build the libFuzzer targets of Testing/Fuzz (needs clang)" OFF)

if(MLR_FUZZ AND NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "MLR_FUZZ needs clang (libFuzzer): configure with CC=clang CXX=clang++")
endif()

if(MLR_SANITIZE)
  # Frame pointers and line tables make the reports readable; -O0 would make CGAL ~20x
  # slower, so the build type's optimisation level is kept (RelWithDebInfo in the test script).
  add_compile_options("-fsanitize=${MLR_SANITIZE}" -fno-omit-frame-pointer -g)
  add_link_options("-fsanitize=${MLR_SANITIZE}")
  if(MLR_SANITIZE MATCHES "undefined")
    # Undefined behaviour stops the program, so that a test cannot pass over it.
    add_compile_options(-fno-sanitize-recover=undefined)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # Not part of gcc's -fsanitize=undefined: double -> integer conversions out of range.
      add_compile_options(-fsanitize=float-cast-overflow -fno-sanitize-recover=float-cast-overflow)
      add_link_options(-fsanitize=float-cast-overflow)
    endif()
  endif()
endif()

if(MLR_FUZZ)
  # Coverage for libFuzzer in everything we compile; only the fuzz targets link its main().
  add_compile_options(-fsanitize=fuzzer-no-link)
  add_compile_definitions(MLR_FUZZING_BUILD=1)
endif()

# Default runtime options (suppressions, fatal reports) compiled into a test executable, so
# that running it by hand or through ctest needs no environment. Environment variables
# (ASAN_OPTIONS, LSAN_OPTIONS, UBSAN_OPTIONS) still override them.
function(mlr_add_sanitizer_defaults target)
  if(MLR_SANITIZE AND TARGET ${target})
    target_sources(${target} PRIVATE "${PROJECT_SOURCE_DIR}/Testing/Reliability/SanitizerDefaults.cxx")
    target_compile_definitions(${target} PRIVATE
      "MLR_SANITIZER_SUPPRESSIONS=\"${PROJECT_SOURCE_DIR}/Testing/Reliability/Sanitizers\"")
  endif()
endfunction()
