# Finds the OpenCV 4 modules dicestack uses and defines imported targets named as OpenCV's own
# config does (opencv_core, opencv_imgproc, opencv_videoio, opencv_ml).
# Debian ships OpenCVConfig.cmake only in the libopencv-dev meta package, which pulls in every
# contrib module; the per-module -dev packages we install have headers and libraries only.
find_package(OpenCV 4 QUIET CONFIG COMPONENTS core imgproc videoio ml)
if(OpenCV_FOUND)
  set(OpenCVModules_FOUND TRUE)
  return()
endif()

find_path(OpenCVModules_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(_ocv_required OpenCVModules_INCLUDE_DIR)
foreach(_m core imgproc videoio ml)
  find_library(OpenCVModules_${_m}_LIBRARY opencv_${_m})
  list(APPEND _ocv_required OpenCVModules_${_m}_LIBRARY)
  if(OpenCVModules_${_m}_LIBRARY AND OpenCVModules_INCLUDE_DIR AND NOT TARGET opencv_${_m})
    add_library(opencv_${_m} SHARED IMPORTED)
    set_target_properties(opencv_${_m} PROPERTIES
      IMPORTED_LOCATION ${OpenCVModules_${_m}_LIBRARY}
      INTERFACE_INCLUDE_DIRECTORIES ${OpenCVModules_INCLUDE_DIR})
  endif()
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVModules REQUIRED_VARS ${_ocv_required})
