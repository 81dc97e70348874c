# Find double- and single-precision MUMPS (Debian: libmumps-dev ships both), the parallel
# build that needs MPI and ScaLAPACK. Upstream CMake has no such module. Defines MUMPS::MUMPS.
# gfortran does not search /usr/include for `include 'dmumps_struc.h'`, so the include
# directory is passed explicitly.
find_path(MUMPS_INCLUDE_DIR dmumps_struc.h)
find_library(MUMPS_DMUMPS_LIBRARY dmumps)
find_library(MUMPS_SMUMPS_LIBRARY smumps)
find_library(MUMPS_COMMON_LIBRARY mumps_common)
find_library(MUMPS_PORD_LIBRARY pord)
find_library(MUMPS_SCALAPACK_LIBRARY NAMES scalapack-openmpi scalapack)
find_package(LAPACK REQUIRED)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(MUMPS REQUIRED_VARS MUMPS_DMUMPS_LIBRARY MUMPS_SMUMPS_LIBRARY
  MUMPS_COMMON_LIBRARY MUMPS_INCLUDE_DIR MUMPS_SCALAPACK_LIBRARY)
if(MUMPS_FOUND AND NOT TARGET MUMPS::MUMPS)
  add_library(MUMPS::MUMPS INTERFACE IMPORTED)
  set(_libs ${MUMPS_DMUMPS_LIBRARY} ${MUMPS_SMUMPS_LIBRARY} ${MUMPS_COMMON_LIBRARY})
  if(MUMPS_PORD_LIBRARY)
    list(APPEND _libs ${MUMPS_PORD_LIBRARY})
  endif()
  list(APPEND _libs ${MUMPS_SCALAPACK_LIBRARY} ${LAPACK_LIBRARIES})
  set_target_properties(MUMPS::MUMPS PROPERTIES INTERFACE_LINK_LIBRARIES "${_libs}"
                        INTERFACE_INCLUDE_DIRECTORIES "${MUMPS_INCLUDE_DIR}")
endif()
mark_as_advanced(MUMPS_INCLUDE_DIR MUMPS_DMUMPS_LIBRARY MUMPS_COMMON_LIBRARY MUMPS_PORD_LIBRARY
                 MUMPS_SCALAPACK_LIBRARY)
