# `cmake --install build --prefix P`: the stage libraries and their public headers, the
# nphand binary, the hand mesh with its licence, and a CMake package:
#   find_package(nphand) ... target_link_libraries(app PRIVATE nphand::nphand)
include(CMakePackageConfigHelpers)

# Public headers. The glTF accessor reader, the index file's format and body reader, and the
# adapters of the third-party index libraries are internal: nothing public includes them.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/nphand DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h"
        PATTERN "model/gltf_accessor.h" EXCLUDE
        PATTERN "index/body.h" EXCLUDE
        PATTERN "index/index_file.h" EXCLUDE
        PATTERN "index/faiss_index.h" EXCLUDE
        PATTERN "index/flann_index.h" EXCLUDE
        PATTERN "index/hnswlib_index.h" EXCLUDE)

install(TARGETS nphand RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The mesh (MIT, @webxr-input-profiles/assets 1.0.20) travels with its licence.
install(FILES ${NPHAND_ASSET_CACHE}/right.glb ${NPHAND_ASSET_CACHE}/left.glb ${NPHAND_ASSET_CACHE}/LICENSE.md
        DESTINATION ${CMAKE_INSTALL_DATADIR}/nphand/hand)

set(config_dir ${CMAKE_INSTALL_LIBDIR}/cmake/nphand)
install(EXPORT nphandTargets NAMESPACE nphand:: DESTINATION ${config_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/nphandConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/nphandConfig.cmake INSTALL_DESTINATION ${config_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/nphandConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/nphandConfig.cmake ${PROJECT_BINARY_DIR}/nphandConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/nphandThirdParty.cmake
        DESTINATION ${config_dir})
