# Layering: each library exposes only its own headers. They are linked into
# build/include/<target>/ under the path they are included by ("plan/planner.hpp" for
# src/plan/planner.hpp, "svg/svg_reader.hpp" for svg/svg_reader.hpp), and that folder
# is the target's only public include directory. A header of a library you do not link
# is not on your include path, so a wrong include fails to build.
#
#   stipplot_expose_headers(TARGET DIR_OR_HEADER...)   paths relative to the project root
function(stipplot_expose_headers target)
  set(inc ${CMAKE_BINARY_DIR}/include/${target})
  file(REMOVE_RECURSE ${inc})
  foreach(entry ${ARGN})
    if(entry MATCHES "\\.hpp$")
      set(hdrs ${PROJECT_SOURCE_DIR}/${entry})
      get_filename_component(dir ${entry} DIRECTORY)
    else()
      file(GLOB hdrs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${entry}/*.hpp)
      set(dir ${entry})
    endif()
    string(REGEX REPLACE "^src/" "" rel ${dir})
    file(MAKE_DIRECTORY ${inc}/${rel})
    foreach(h ${hdrs})
      get_filename_component(name ${h} NAME)
      file(CREATE_LINK ${h} ${inc}/${rel}/${name} SYMBOLIC)
    endforeach()
  endforeach()
  target_include_directories(${target} PUBLIC ${inc})
endfunction()
