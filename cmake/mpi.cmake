# mpi.cmake -- the optional MPI scale-out (docs/scale-out.md): the library
# hausdorff_mpi (src/mpi/, public header include/hausdorff_mpi.h) and the
# tool hausdorff-mpi (cli/mpi/), built when CMake finds MPI for C (Debian:
# libopenmpi-dev, openmpi-bin; scripts/deps.sh mpi).  HD_WITH_MPI=OFF skips
# them.  The library is static: it uses the core's internal geometry
# (points/points.h), which the shared library does not export.
option(HD_WITH_MPI "The MPI library and tool (hausdorff_mpi, hausdorff-mpi)" ON)
set(HD_MPI OFF)
if(HD_WITH_MPI)
  find_package(MPI COMPONENTS C QUIET)
endif()
if(HD_WITH_MPI AND MPI_C_FOUND)
  set(HD_MPI ON)
  message(STATUS "hausdorff: MPI ${MPI_C_VERSION}: hausdorff_mpi and hausdorff-mpi")
  file(GLOB HD_MPI_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/mpi/*.c)
  add_library(hausdorff_mpi STATIC ${HD_MPI_SOURCES})
  target_include_directories(hausdorff_mpi PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_include_directories(hausdorff_mpi PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
  target_link_libraries(hausdorff_mpi PUBLIC hausdorff_static MPI::MPI_C m)
  # The tool: cli/mpi/main.c over the tool's shared objects (report, tiles,
  # options) and the MPI library.
  add_executable(hausdorff_mpi_cli ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/main.c ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/writer.c
    ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/figures.c)
  set_target_properties(hausdorff_mpi_cli PROPERTIES OUTPUT_NAME hausdorff-mpi
    RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR})
  target_include_directories(hausdorff_mpi_cli PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/cli)
  target_link_libraries(hausdorff_mpi_cli PRIVATE hd_cli_objects hausdorff_mpi)
  install(TARGETS hausdorff_mpi hausdorff_mpi_cli
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/include/hausdorff_mpi.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
else()
  message(STATUS "hausdorff: MPI not found: no hausdorff_mpi, hausdorff-mpi (Debian: libopenmpi-dev openmpi-bin)")
endif()
