# Fuzz targets (tests/fuzz/README.md, tools/fuzz.sh). Each target is one source file
# defining LLVMFuzzerTestOneInput around one of the project's readers, built
#  - with GI_FUZZ=ON (clang only): as fuzz_<name>, a libFuzzer program; the whole project is
#    then compiled with coverage instrumentation, ASan and UBSan (float-cast-overflow
#    included), every report fatal; tools/fuzz.sh builds only the fuzz targets;
#  - otherwise, in a build with tests: as fuzz_<name>_replay with tests/fuzz/replay_main.cpp,
#    a ctest (Fuzz.<name>.ReplaysSeedsAndRegressions) feeding it the seed corpus
#    tests/fuzz/corpus/<name>/ and the inputs of fixed findings tests/fuzz/regressions/<name>/.
option(GI_FUZZ "Build the libFuzzer targets (clang; instruments the project with ASan + UBSan)" OFF)

if(GI_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "GI_FUZZ=ON needs clang: configure with CC=clang CXX=clang++ (tools/fuzz.sh does)")
  endif()
  if(GI_SANITIZE)
    message(FATAL_ERROR "GI_FUZZ=ON brings its own sanitizers: leave GI_SANITIZE off")
  endif()
  set(_gi_fuzz_sanitizers address,undefined,float-cast-overflow)
  add_compile_options(-fsanitize=fuzzer-no-link,${_gi_fuzz_sanitizers} -fno-sanitize-recover=all
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${_gi_fuzz_sanitizers})
endif()

set(GI_FUZZ_CORPUS_DIR ${PROJECT_SOURCE_DIR}/tests/fuzz/corpus)
set(GI_FUZZ_REGRESSIONS_DIR ${PROJECT_SOURCE_DIR}/tests/fuzz/regressions)

# gi_fuzz_target(<name> <source> <library>...)
function(gi_fuzz_target name source)
  if(GI_FUZZ)
    add_executable(fuzz_${name} ${source})
    target_link_libraries(fuzz_${name} PRIVATE ${ARGN})
    target_include_directories(fuzz_${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/fuzz)
    target_link_options(fuzz_${name} PRIVATE -fsanitize=fuzzer)
    set_property(GLOBAL APPEND PROPERTY GI_FUZZ_TARGETS ${name})
  elseif(GI_BUILD_TESTS)
    add_executable(fuzz_${name}_replay ${source} ${PROJECT_SOURCE_DIR}/tests/fuzz/replay_main.cpp)
    target_link_libraries(fuzz_${name}_replay PRIVATE ${ARGN} gi_warnings gi_sanitize)
    target_include_directories(fuzz_${name}_replay PRIVATE ${PROJECT_SOURCE_DIR}/tests/fuzz)
    add_test(NAME Fuzz.${name}.ReplaysSeedsAndRegressions
             COMMAND fuzz_${name}_replay --seeds ${GI_FUZZ_CORPUS_DIR}/${name}
                     --regressions ${GI_FUZZ_REGRESSIONS_DIR}/${name})
    set_tests_properties(Fuzz.${name}.ReplaysSeedsAndRegressions PROPERTIES LABELS fuzz TIMEOUT ${GI_TEST_TIMEOUT})
  endif()
endfunction()

# After every gi_fuzz_target: the target `fuzz_targets` building them all, and
# fuzz_targets.txt in the build directory, one "<name> <program>" line each (tools/fuzz.sh).
function(gi_fuzz_finish)
  if(NOT GI_FUZZ)
    return()
  endif()
  get_property(_names GLOBAL PROPERTY GI_FUZZ_TARGETS)
  set(_lines "")
  set(_programs "")
  foreach(_n ${_names})
    string(APPEND _lines "${_n} $<TARGET_FILE:fuzz_${_n}>\n")
    list(APPEND _programs fuzz_${_n})
  endforeach()
  add_custom_target(fuzz_targets DEPENDS ${_programs})
  file(GENERATE OUTPUT ${PROJECT_BINARY_DIR}/fuzz_targets.txt CONTENT "${_lines}")
endfunction()
