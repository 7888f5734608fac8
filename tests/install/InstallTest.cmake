# cmake -DBUILD_DIR=<build> -DSOURCE_DIR=<source> -DEXPECT_MAN=ON|OFF -P InstallTest.cmake
#
# Installs the build into a temporary prefix, moves the installed tree to another folder (so nothing can be
# found through the prefix it was installed to) and runs the moved `pneuma-cli validate --quick` from a
# temporary working directory with a clean environment: no PNEUMA_* variables, no path into the source tree
# or the build tree. Passes when the installed layout is complete and the program finds its presets,
# anatomy and default model relative to itself.

# check(<message> <condition...>): fails the test with <message> unless the if() condition holds
function(check message)
  if(NOT (${ARGN}))
    message(FATAL_ERROR "install test: ${message}")
  endif()
endfunction()

string(RANDOM LENGTH 10 tag)
set(root "/tmp/pneuma-install-test-${tag}")
file(REMOVE_RECURSE "${root}")
file(MAKE_DIRECTORY "${root}/work")

execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${root}/prefix"
                RESULT_VARIABLE rc OUTPUT_QUIET)
check("cmake --install failed (${rc})" rc EQUAL 0)

# the installed tree, moved elsewhere: the programs must find their data relative to themselves
file(RENAME "${root}/prefix" "${root}/moved")
set(p "${root}/moved")
foreach(f IN ITEMS bin/pneuma bin/pneuma-cli share/pneuma/presets/calm.json share/pneuma/presets/affect/neutral.json
               share/pneuma/anatomy/male.json share/pneuma/anatomy/muscle_gains.json share/pneuma/scenarios/calm.json
               share/pneuma/models/default/model.json share/applications/pneuma.desktop
               share/icons/hicolor/scalable/apps/pneuma.svg)
  check("${f} is not installed" EXISTS ${p}/${f})
endforeach()
if(EXPECT_MAN)
  foreach(program IN ITEMS pneuma pneuma-cli)
    set(f share/man/man1/${program}.1)
    check("${f} (or ${f}.gz) is not installed" EXISTS ${p}/${f} OR EXISTS ${p}/${f}.gz)
  endforeach()
  file(READ "${BUILD_DIR}/man/pneuma-cli.1" page)
  string(FIND "${page}" "validate" at)
  check("pneuma-cli.1 does not mention the validate subcommand" NOT at EQUAL -1)
endif()

# no path into the source tree's resources compiled into the programs
foreach(program IN ITEMS pneuma pneuma-cli)
  file(STRINGS "${p}/bin/${program}" hits REGEX "${SOURCE_DIR}/resources")
  check("bin/${program} holds the source-tree path ${SOURCE_DIR}/resources" NOT hits)
endforeach()

execute_process(COMMAND env -i "HOME=${root}/work" "PATH=/usr/bin:/bin" "${p}/bin/pneuma-cli" validate --quick
                        --out "${root}/work/validation"
                WORKING_DIRECTORY "${root}/work"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
check("installed pneuma-cli validate --quick exited ${rc}\n${out}\n${err}" rc EQUAL 0)
check("validate wrote no report.json" EXISTS ${root}/work/validation/report.json)

file(REMOVE_RECURSE "${root}")
message(STATUS "installed, moved and validated: ${out}")
