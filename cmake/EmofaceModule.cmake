# emoface_add_module(<name> SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# One library target per module folder (DESIGN.md): emoface_<name>, alias
# emoface::<name>, public headers under <name>/include/emoface/<name>/.
function(emoface_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(emoface_${name} STATIC ${ARG_SOURCES})
  add_library(emoface::${name} ALIAS emoface_${name})
  target_include_directories(emoface_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
  target_link_libraries(emoface_${name} PUBLIC emoface::common ${ARG_PUBLIC_DEPS}
                                        PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_options(emoface_${name} PRIVATE
    $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic>)
endfunction()

# emoface_add_test(<name> SOURCES ... DEPS ...): a GoogleTest executable whose
# tests ctest discovers; the test's working directory is the build tree.
function(emoface_add_test name)
  cmake_parse_arguments(ARG "" "COST" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    EMOFACE_DATA_DIR="${EMOFACE_DATA_DIR}"
    EMOFACE_REALDATA_DIR="${EMOFACE_REALDATA_DIR}"
    EMOFACE_TEST_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  # The label "noleak" opts a test out of leak checking (scripts/test): GL
  # drivers keep allocations until exit, in libraries unloaded before the
  # leak report, so those leaks can be neither attributed nor suppressed.
  set(env "")
  if("noleak" IN_LIST ARG_LABELS)
    set(env ENVIRONMENT "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1")
  endif()
  # COST: seconds a test of this binary may take. ctest starts the costly
  # ones first; CI's fresh build tree has no timings of its own, and a
  # minute-long test started last ran alone on one of the two cores.
  set(cost "")
  if(ARG_COST)
    set(cost COST ${ARG_COST})
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES LABELS "${ARG_LABELS}" ${env} ${cost})
endfunction()
