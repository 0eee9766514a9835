# Every dependency is a Debian 12 package (see README, "Dependencies").
find_package(Threads REQUIRED)
find_package(TBB 2021 REQUIRED)
find_package(zstd 1.5 REQUIRED)
find_package(glm REQUIRED)
find_package(CLI11 2.1 REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(PNG REQUIRED)
find_package(ZLIB REQUIRED)
find_package(OpenEXR 3.1 REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash>=0.8)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy>=1.5)
# The viewer's window and panel: GLFW 3.3 and Dear ImGui 1.86 (its GLFW and OpenGL 3 backends
# are in Debian's libimgui.a).
find_package(glfw3 3.3 REQUIRED)
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui>=1.86)
# Blosc 1.21 (an OpenVDB dependency): our VDB reader decompresses with it (blosc_cbuffer_validate).
pkg_check_modules(BLOSC REQUIRED IMPORTED_TARGET blosc>=1.21)

# OpenVDB 10 ships a Find module, not a config package.
find_path(_flipscope_openvdb_cmake FindOpenVDB.cmake
  PATHS /usr/lib/x86_64-linux-gnu/cmake/OpenVDB /usr/lib/cmake/OpenVDB /usr/local/lib/cmake/OpenVDB
  REQUIRED)
list(APPEND CMAKE_MODULE_PATH "${_flipscope_openvdb_cmake}")
find_package(OpenVDB 10 REQUIRED COMPONENTS openvdb)

if(TARGET zstd::libzstd_shared)
  set(FLIPSCOPE_ZSTD zstd::libzstd_shared)
else()
  set(FLIPSCOPE_ZSTD zstd::libzstd_static)
endif()

# Optional: Embree 3, the peer of `bench render --peer embree` (Debian: libembree-dev). Only the
# flipscope command links it; without it the bench says so.
find_package(embree 3 QUIET)
if(embree_FOUND)
  message(STATUS "Embree ${embree_VERSION}: bench render --peer embree is built in")
else()
  message(STATUS "Embree 3 not found: bench render --peer embree will say so (Debian: libembree-dev)")
endif()
