# Install rules, man pages and the Debian package (README.md, "Install").
#
#   cmake --install build --prefix PREFIX    PREFIX/bin/pneuma, pneuma-cli; PREFIX/share/pneuma (resources and
#                                            models/default); desktop entry, icon and man pages under PREFIX/share
#   cd build && cpack -G DEB                 pneuma_<version>_<arch>.deb, installing under /usr
#
# Programs find their data at <bindir>/../share/pneuma (PNEUMA_DATA_FROM_BIN), so an installed tree can be moved.

if(NOT PNEUMA_BUILD_APP)
  return()
endif()

install(TARGETS pneuma pneuma-cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PNEUMA_RESOURCE_DIR}/ DESTINATION ${PNEUMA_INSTALL_DATADIR})
install(DIRECTORY ${PNEUMA_DEFAULT_MODEL_DIR}/ DESTINATION ${PNEUMA_INSTALL_DATADIR}/models/default)
install(FILES ${CMAKE_SOURCE_DIR}/packaging/pneuma.desktop DESTINATION ${CMAKE_INSTALL_DATADIR}/applications)
install(FILES ${CMAKE_SOURCE_DIR}/packaging/pneuma.svg DESTINATION ${CMAKE_INSTALL_DATADIR}/icons/hicolor/scalable/apps)
install(FILES ${CMAKE_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/pneuma RENAME copyright)

# man pages from each program's --help, written to a temporary file and renamed (help2man: Debian's help2man)
find_program(PNEUMA_HELP2MAN help2man)
find_program(PNEUMA_GZIP gzip)
if(PNEUMA_HELP2MAN)
  set(pneuma_man_pages)
  foreach(program IN ITEMS pneuma pneuma-cli)
    if(program STREQUAL "pneuma")
      set(summary "simulated human breathing, the desktop app")
    else()
      set(summary "simulated human breathing, headless: simulate, validate, bench, scenarios, models")
    endif()
    set(page ${CMAKE_BINARY_DIR}/man/${program}.1)
    add_custom_command(
      OUTPUT ${page}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/man
      COMMAND ${PNEUMA_HELP2MAN} --no-info --no-discard-stderr --version-string=${PROJECT_VERSION}
              --name=${summary} --section=1 --output=${page}.tmp $<TARGET_FILE:${program}>
      COMMAND ${CMAKE_COMMAND} -E rename ${page}.tmp ${page}
      DEPENDS ${program}
      COMMENT "Writing the man page ${program}.1 from ${program} --help"
      VERBATIM)
    if(PNEUMA_GZIP)
      # installed compressed, as Debian's policy asks (gzip -n: no name or time stamp, reproducible)
      add_custom_command(
        OUTPUT ${page}.gz
        COMMAND ${PNEUMA_GZIP} -9 -n -k -f ${page}
        DEPENDS ${page}
        VERBATIM)
      set(page ${page}.gz)
    endif()
    list(APPEND pneuma_man_pages ${page})
  endforeach()
  add_custom_target(pneuma_man_pages ALL DEPENDS ${pneuma_man_pages})
  install(FILES ${pneuma_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(WARNING "help2man not found: no man pages (Debian: apt-get install help2man)")
endif()

# Debian package: cpack -G DEB in the build directory
set(CPACK_PACKAGE_NAME pneuma)
set(CPACK_PACKAGE_VENDOR "Pneuma developers")
set(CPACK_PACKAGE_CONTACT "Pneuma developers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "simulated human breathing: ribcage, muscles, gut and diaphragm")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
    "Pneuma simulates human breathing from the inside out: an articulated ribcage, about 1,500 spring muscle elements "
    "and a volume-preserving gut with a diaphragm (after Zordan et al., SCA 2004), driven by respiration patterns and "
    "affective states (de Melo et al., CAVW 2010). The desktop app pneuma shows it live; pneuma-cli runs it headless.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_RESOURCE_FILE_LICENSE ${CMAKE_SOURCE_DIR}/LICENSE)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_LICENSE AGPL-3.0-or-later)
# the Debian 12 packages of the libraries the two programs link (objdump -p build/bin/pneuma* | grep NEEDED, then
# dpkg -S); CGAL, Eigen, nlohmann-json and CLI11 are header-only, the pneuma libraries static
set(pneuma_deb_depends
    "libc6 (>= 2.36)" "libgcc-s1" "libstdc++6 (>= 12)"
    "libqt5core5a (>= 5.15)" "libqt5gui5 (>= 5.15)" "libqt5widgets5 (>= 5.15)" "libqt5svg5 (>= 5.15)"
    "libvtk9.1" "libvtk9.1-qt" "libtet1.5" "libassimp5" "libgmp10" "libmpfr6")
list(JOIN pneuma_deb_depends ", " CPACK_DEBIAN_PACKAGE_DEPENDS)
# the plots' font (viz::Plot falls back to VTK's Arial without it); ffmpeg for MP4 movies (viz::MovieWriter:
# without it the app refuses .mp4 with the reason, and Ogg and PNG exports still work)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "fonts-dejavu-core, ffmpeg")
include(CPack)
