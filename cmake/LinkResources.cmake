# cmake -DSOURCE=<resources> -DDEST=<build>/share/pneuma -P LinkResources.cmake
# Gives the build tree the install layout: one symbolic link in DEST per entry of SOURCE (anatomy, presets, ...),
# so programs run from build/bin find the source tree's resources, edits included, at ../share/pneuma.
file(MAKE_DIRECTORY "${DEST}")
file(GLOB entries RELATIVE "${SOURCE}" "${SOURCE}/*")
foreach(entry IN LISTS entries)
  if(NOT EXISTS "${DEST}/${entry}" AND NOT IS_SYMLINK "${DEST}/${entry}")
    file(CREATE_LINK "${SOURCE}/${entry}" "${DEST}/${entry}" SYMBOLIC)
  endif()
endforeach()
