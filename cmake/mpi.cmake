# mpi.cmake -- the optional MPI scale-out (docs/scale-out.md): the library
# hausdorff_mpi (src/mpi/, public header include/hausdorff_mpi.h) and the
# tool hausdorff-mpi (cli/mpi/), built when CMake finds MPI for C (Debian:
# libopenmpi-dev, openmpi-bin; scripts/deps.sh mpi).  HD_WITH_MPI=OFF skips
# them.
#
# src/mpi/ uses the core's internal names (hd__*), which libhausdorff.so does
# not export.  So the library comes in two forms from one set of objects:
#  - libhausdorff_mpi.so (target hausdorff_mpi_shared, installed as
#    hausdorff::hausdorff_mpi): the MPI objects with the parts of the core
#    they use linked in privately from the static core; it exports the
#    hd_mpi_* calls only (cmake/hausdorff_mpi.map), and a program links it
#    with libhausdorff.so for its own hd_* calls (-lhausdorff_mpi
#    -lhausdorff, hausdorff_mpi.pc);
#  - libhausdorff_mpi.a (target hausdorff_mpi, installed as
#    hausdorff::hausdorff_mpi_static): the MPI objects, to link before
#    libhausdorff.a, which holds the internal names.  The tool, the tests
#    and the benchmarks link this one (the white-box tests see src/mpi/).
option(HD_WITH_MPI "The MPI library and tool (hausdorff_mpi, hausdorff-mpi)" ON)
set(HD_MPI OFF)
if(HD_WITH_MPI)
  find_package(MPI COMPONENTS C QUIET)
endif()
if(HD_WITH_MPI AND MPI_C_FOUND)
  set(HD_MPI ON)
  message(STATUS "hausdorff: MPI ${MPI_C_VERSION}: hausdorff_mpi and hausdorff-mpi")
  file(GLOB HD_MPI_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/mpi/*.c)
  add_library(hd_mpi_objects OBJECT ${HD_MPI_SOURCES})
  set_target_properties(hd_mpi_objects PROPERTIES POSITION_INDEPENDENT_CODE ON)
  target_include_directories(hd_mpi_objects PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(hd_mpi_objects PUBLIC hausdorff_static MPI::MPI_C)

  add_library(hausdorff_mpi STATIC $<TARGET_OBJECTS:hd_mpi_objects>)
  add_library(hausdorff_mpi_shared SHARED $<TARGET_OBJECTS:hd_mpi_objects>)
  set_target_properties(hausdorff_mpi PROPERTIES EXPORT_NAME hausdorff_mpi_static)
  set_target_properties(hausdorff_mpi_shared PROPERTIES OUTPUT_NAME hausdorff_mpi EXPORT_NAME hausdorff_mpi
    VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}
    LINK_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/cmake/hausdorff_mpi.map)
  target_link_options(hausdorff_mpi_shared PRIVATE
    -Wl,--version-script=${CMAKE_CURRENT_SOURCE_DIR}/cmake/hausdorff_mpi.map -Wl,--no-undefined)
  foreach(t hausdorff_mpi hausdorff_mpi_shared)
    target_include_directories(${t} PUBLIC
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  endforeach()
  target_link_libraries(hausdorff_mpi PUBLIC hausdorff_static MPI::MPI_C m)
  # The core's objects it uses come from the static core, privately; the
  # program's own hd_* calls from libhausdorff.so.
  target_link_libraries(hausdorff_mpi_shared PRIVATE hausdorff_static PUBLIC MPI::MPI_C INTERFACE hausdorff)

  # The tool: cli/mpi/main.c over the tool's shared objects (report, tiles,
  # options) and the MPI library.
  add_executable(hausdorff_mpi_cli ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/main.c ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/writer.c ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/writeback.c
    ${CMAKE_CURRENT_SOURCE_DIR}/cli/mpi/figures.c)
  set_target_properties(hausdorff_mpi_cli PROPERTIES OUTPUT_NAME hausdorff-mpi
    RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR})
  target_include_directories(hausdorff_mpi_cli PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/cli)
  target_link_libraries(hausdorff_mpi_cli PRIVATE hd_cli_objects hausdorff_mpi)
  install(TARGETS hausdorff_mpi hausdorff_mpi_shared EXPORT hausdorffMpiTargets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(TARGETS hausdorff_mpi_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(EXPORT hausdorffMpiTargets NAMESPACE hausdorff:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/hausdorff)
  install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/include/hausdorff_mpi.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  list(APPEND HD_INSTALLED hausdorff_mpi hausdorff_mpi_shared hausdorff_mpi_cli)
else()
  message(STATUS "hausdorff: MPI not found: no hausdorff_mpi, hausdorff-mpi (Debian: libopenmpi-dev openmpi-bin)")
endif()
