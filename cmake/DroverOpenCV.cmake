# OpenCV from Debian's per-module -dev packages. Their umbrella libopencv-dev (which ships OpenCVConfig.cmake)
# pulls in every module, contrib and VTK: hundreds of packages Drover does not use. So we declare imported
# targets opencv::<module> for just the modules we link.
find_path(DROVER_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
foreach(module core imgproc imgcodecs video features2d calib3d dnn flann)
  find_library(DROVER_OPENCV_${module}_LIBRARY opencv_${module})
  if(DROVER_OPENCV_${module}_LIBRARY AND NOT TARGET opencv::${module})
    add_library(opencv::${module} SHARED IMPORTED)
    set_target_properties(opencv::${module} PROPERTIES
      IMPORTED_LOCATION ${DROVER_OPENCV_${module}_LIBRARY}
      INTERFACE_INCLUDE_DIRECTORIES ${DROVER_OPENCV_INCLUDE_DIR})
  endif()
endforeach()
foreach(module core imgproc imgcodecs)
  if(NOT TARGET opencv::${module})
    message(FATAL_ERROR "OpenCV module ${module} not found: run scripts/install_deps.sh")
  endif()
endforeach()
