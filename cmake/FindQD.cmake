# FindQD: locate the QD double-double / quad-double library (Bailey, Hida, Li).
#
# pkg-config is consulted for hints and the version only. Debian's qd.pc (libqd-dev 2.3.23)
# lists a non-existent Fortran module include directory, so an IMPORTED_TARGET made from it
# fails with "includes non-existent path"; the header and library are therefore located with
# find_path / find_library and wrapped in our own imported target.
#
# Result: QD_FOUND, QD_VERSION, QD_INCLUDE_DIR, QD_LIBRARY and the target QD::QD.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(PC_QD QUIET qd)
endif()
find_path(QD_INCLUDE_DIR qd/dd_real.h HINTS ${PC_QD_INCLUDEDIR} ${PC_QD_INCLUDE_DIRS})
find_library(QD_LIBRARY NAMES qd HINTS ${PC_QD_LIBDIR} ${PC_QD_LIBRARY_DIRS})
set(QD_VERSION ${PC_QD_VERSION})
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(QD REQUIRED_VARS QD_LIBRARY QD_INCLUDE_DIR VERSION_VAR QD_VERSION)
if(QD_FOUND AND NOT TARGET QD::QD)
  add_library(QD::QD UNKNOWN IMPORTED)
  set_target_properties(QD::QD PROPERTIES IMPORTED_LOCATION "${QD_LIBRARY}"
                                          INTERFACE_INCLUDE_DIRECTORIES "${QD_INCLUDE_DIR}")
endif()
mark_as_advanced(QD_INCLUDE_DIR QD_LIBRARY)
