# stipplot_io: transports (serial, USB, file, loopback), streaming protocols (grbl,
# HPGL), the resume journal. Included from drivers/CMakeLists.txt.
set(STIPPLOT_IO_DIR ${CMAKE_CURRENT_LIST_DIR})
file(GLOB STIPPLOT_IO_SOURCES CONFIGURE_DEPENDS
  ${STIPPLOT_IO_DIR}/transport/*.cpp
  ${STIPPLOT_IO_DIR}/grbl/*.cpp)
list(APPEND STIPPLOT_IO_SOURCES ${STIPPLOT_IO_DIR}/journal.cpp ${STIPPLOT_IO_DIR}/hpgl/streamer.cpp)
foreach(f ${STIPPLOT_IO_SOURCES})
  if(NOT EXISTS ${f})
    list(REMOVE_ITEM STIPPLOT_IO_SOURCES ${f})
  endif()
endforeach()
add_library(stipplot_io STATIC ${STIPPLOT_IO_SOURCES})
target_include_directories(stipplot_io PUBLIC ${PROJECT_SOURCE_DIR} ${PROJECT_SOURCE_DIR}/src)
target_link_libraries(stipplot_io PUBLIC stipplot_util Threads::Threads
  PRIVATE PkgConfig::SERIALPORT PkgConfig::LIBUSB nlohmann_json::nlohmann_json)
