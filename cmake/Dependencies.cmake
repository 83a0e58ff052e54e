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

# FLANN (exact k-d tree search, an index backend) and tinygltf (the hand mesh).
include(nphandThirdParty)

if(NPHAND_BUILD_TESTS)
  find_package(GTest 1.12 REQUIRED)
endif()
if(NPHAND_BUILD_BENCH)
  find_package(benchmark 1.7 REQUIRED)
endif()
