# Every dependency comes from a Debian 12 package; tools/install_deps.sh installs them.
find_package(Threads REQUIRED)
find_package(Torch REQUIRED)          # libtorch-dev
find_package(mujoco REQUIRED)         # libmujoco-dev (its config needs libqhull-dev)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(yaml-cpp REQUIRED)
find_package(spdlog REQUIRED)
find_package(GTest)
# The BLAS LibTorch links (libblas3 or OpenBLAS, a dependency of libtorch-dev): the hand-written
# backward passes (algorithms/mlp_backprop.cpp) call its sgemm.
find_library(SEGUE_BLAS NAMES libblas.so.3 blas REQUIRED)
# That BLAS (OpenBLAS's OpenMP build) takes its thread count from each calling thread's
# OpenMP setting: the thread pool's workers set theirs (core/thread_pool.cpp), so they link
# the OpenMP runtime LibTorch itself uses.
find_package(OpenMP REQUIRED COMPONENTS CXX)
# Torch's config appends flags we do not want to force on every target.
set(CMAKE_CXX_FLAGS "${CMAKE_CXX_FLAGS} ${TORCH_CXX_FLAGS}")
