# Small helpers shared by every Pneuma target.

# pneuma_target_defaults(<target>): warnings, sanitizers and the version/resource definitions.
function(pneuma_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(PNEUMA_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

# pneuma_add_gtest(<name> LABEL <label> SOURCES <files...> LIBS <targets...>)
# One GoogleTest executable whose tests are discovered into ctest with the given label
# (unit, validation, gui or bench-smoke).
function(pneuma_add_gtest name)
  cmake_parse_arguments(T "" "LABEL" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    PNEUMA_RESOURCE_DIR="${PNEUMA_RESOURCE_DIR}"
    PNEUMA_DEFAULT_MODEL_DIR="${PNEUMA_DEFAULT_MODEL_DIR}"
    PNEUMA_BIN_DIR="${CMAKE_BINARY_DIR}/bin")
  pneuma_target_defaults(${name})
  # discover at test time, so GUI suites are listed under the same xvfb-run as they run
  gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST PROPERTIES LABELS ${T_LABEL} DISCOVERY_TIMEOUT 60)
endfunction()
