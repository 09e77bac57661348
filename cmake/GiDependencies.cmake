# Every dependency is a Debian package (tools/install-deps.sh installs them).
find_package(PkgConfig REQUIRED)
find_package(glm REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(draco REQUIRED)
find_package(tinyexr REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
find_package(glfw3 REQUIRED)
find_package(Eigen3 REQUIRED NO_MODULE)
find_package(embree 3 REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
find_package(TBB REQUIRED)
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)

# tinygltf is compiled by us (engine/src/gltf/tinygltf_impl.cpp) with Draco enabled; the
# Debian shared library is built without Draco, so it is not linked. Its header includes
# <stb_image.h> from libstb-dev.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
find_path(STB_INCLUDE_DIR stb_image.h PATH_SUFFIXES stb REQUIRED)

# Draco's CMake package names its target `draco::draco` on Debian 12; fall back to the
# plain variables when it does not.
if(TARGET draco::draco)
  set(GI_DRACO_TARGET draco::draco)
else()
  add_library(gi_draco INTERFACE)
  target_include_directories(gi_draco SYSTEM INTERFACE ${draco_INCLUDE_DIRS})
  target_link_libraries(gi_draco INTERFACE ${draco_LIBRARIES})
  set(GI_DRACO_TARGET gi_draco)
endif()

if(GI_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
