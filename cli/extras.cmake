# extras.cmake -- optional libraries of the command-line tool (never of the
# library): libpng for --render and --histogram-png, the NIfTI C library
# (libnifti2, which brings zlib for .nii.gz) for medical masks.  Each one
# found defines HD_HAVE_PNG / HD_HAVE_NIFTI and is linked into
# the tool's objects (hd_cli_objects, which hausdorff and hausdorff-mpi
# link); a missing one leaves the tool building, and the tool then
# says the feature is unavailable.  HD_WITH_PNG / HD_WITH_NIFTI (default ON)
# switch them off, to test the build without them.
option(HD_WITH_PNG "Pictures (--render, --histogram-png) with libpng" ON)
option(HD_WITH_NIFTI "NIfTI masks with libnifti2" ON)

if(HD_WITH_PNG)
  find_package(PNG QUIET)
endif()
set(HD_CLI_PNG OFF)
set(HD_CLI_NIFTI OFF)
if(HD_WITH_PNG AND PNG_FOUND)
  set(HD_CLI_PNG ON)
  target_compile_definitions(hd_cli_objects PRIVATE HD_HAVE_PNG=1)
  target_link_libraries(hd_cli_objects PUBLIC PNG::PNG)
  message(STATUS "hausdorff: pictures with libpng ${PNG_VERSION_STRING}")
else()
  message(STATUS "hausdorff: libpng not used: --render and --histogram-png unavailable (Debian: libpng-dev)")
endif()

# Debian 12's NIFTIConfig.cmake names a libznz path that does not exist, so
# the header and the library are found directly; libnifti2.so brings its own
# dependencies (libznz, zlib) as DT_NEEDED entries.
if(HD_WITH_NIFTI)
  find_path(HD_NIFTI_INCLUDE nifti2_io.h PATH_SUFFIXES nifti)
  find_library(HD_NIFTI_LIBRARY nifti2)
endif()
if(HD_WITH_NIFTI AND HD_NIFTI_INCLUDE AND HD_NIFTI_LIBRARY)
  set(HD_CLI_NIFTI ON)
  target_compile_definitions(hd_cli_objects PRIVATE HD_HAVE_NIFTI=1)
  target_include_directories(hd_cli_objects PRIVATE ${HD_NIFTI_INCLUDE})
  target_link_libraries(hd_cli_objects PUBLIC ${HD_NIFTI_LIBRARY} m)
  message(STATUS "hausdorff: NIfTI masks with ${HD_NIFTI_LIBRARY}")
else()
  message(STATUS "hausdorff: libnifti2 not used: NIfTI masks unavailable (Debian: libnifti2-dev)")
endif()
