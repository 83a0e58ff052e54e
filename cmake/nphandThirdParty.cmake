# The two dependencies Debian ships without a CMake package, as imported targets. Included
# by the build (cmake/Dependencies.cmake) and by an installed nphandConfig.cmake.
if(NOT TARGET nphand_deps::flann)
  # FLANN: its pkg-config file drags in HDF5; flann_cpp and lz4 are all it needs.
  find_path(FLANN_INCLUDE_DIR flann/flann.hpp REQUIRED)
  find_library(FLANN_CPP_LIBRARY flann_cpp REQUIRED)
  find_library(LZ4_LIBRARY lz4 REQUIRED)
  add_library(nphand_deps::flann INTERFACE IMPORTED)
  target_include_directories(nphand_deps::flann SYSTEM INTERFACE ${FLANN_INCLUDE_DIR})
  target_link_libraries(nphand_deps::flann INTERFACE ${FLANN_CPP_LIBRARY} ${LZ4_LIBRARY})
endif()
if(NOT TARGET nphand_deps::tinygltf)
  # tinygltf: Debian ships the compiled library; its header includes <stb_image.h> unqualified.
  find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
  find_library(TINYGLTF_LIBRARY tinygltf REQUIRED)
  find_path(STB_INCLUDE_DIR stb_image.h PATHS /usr/include/stb REQUIRED)
  add_library(nphand_deps::tinygltf INTERFACE IMPORTED)
  target_include_directories(nphand_deps::tinygltf SYSTEM INTERFACE ${TINYGLTF_INCLUDE_DIR} ${STB_INCLUDE_DIR})
  target_link_libraries(nphand_deps::tinygltf INTERFACE ${TINYGLTF_LIBRARY})
endif()
