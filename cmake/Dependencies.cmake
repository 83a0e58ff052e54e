# Every third-party package nphand uses, found once, with the versions Debian 12 ships.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(OpenCV 4.6 REQUIRED COMPONENTS core imgproc imgcodecs videoio objdetect)
find_package(OpenSSL 3 REQUIRED)        # SHA-256 of the hand asset
find_package(nlohmann_json 3.11 REQUIRED)
find_package(CLI11 2.1 REQUIRED)
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)          # CRC-32 of the database file
find_package(OpenMP REQUIRED)        # FAISS's config names OpenMP::OpenMP_CXX
find_package(faiss REQUIRED)         # exact search for the feature study; index backends

# FLANN: exact k-d tree search (view-sphere coverage) and an index backend. Its pkg-config
# file drags in HDF5; flann_cpp and lz4 are all it needs.
find_path(FLANN_INCLUDE_DIR flann/flann.hpp REQUIRED)
find_library(FLANN_CPP_LIBRARY flann_cpp REQUIRED)
find_library(LZ4_LIBRARY lz4 REQUIRED)
add_library(nphand_flann INTERFACE)
target_include_directories(nphand_flann SYSTEM INTERFACE ${FLANN_INCLUDE_DIR})
target_link_libraries(nphand_flann INTERFACE ${FLANN_CPP_LIBRARY} ${LZ4_LIBRARY})

# tinygltf: Debian ships the compiled library; its header includes <stb_image.h> unqualified.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
find_library(TINYGLTF_LIBRARY tinygltf REQUIRED)
find_path(STB_INCLUDE_DIR stb_image.h PATHS /usr/include/stb REQUIRED)
add_library(nphand_tinygltf INTERFACE)
target_include_directories(nphand_tinygltf SYSTEM INTERFACE ${TINYGLTF_INCLUDE_DIR} ${STB_INCLUDE_DIR})
target_link_libraries(nphand_tinygltf INTERFACE ${TINYGLTF_LIBRARY})

if(NPHAND_BUILD_TESTS)
  find_package(GTest 1.12 REQUIRED)
endif()
if(NPHAND_BUILD_BENCH)
  find_package(benchmark 1.7 REQUIRED)
endif()
