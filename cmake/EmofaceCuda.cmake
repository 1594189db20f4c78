# CUDA is optional: enabled when nvcc is found and EMOFACE_CUDA is ON.
# Architectures come from a cache variable with a fallback (tiny-cuda-nn style):
# 90, Hopper's code and its PTX, which the driver compiles for newer chips.
# Each further architecture is another pass of nvcc over every kernel (a
# minute of CI's build on 2 cores for 75-real); pass
# -DCMAKE_CUDA_ARCHITECTURES=75-real;90 for a Turing card.
set(EMOFACE_HAVE_CUDA OFF)
if(EMOFACE_CUDA)
  if(NOT CMAKE_CUDA_COMPILER AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(CMAKE_CUDA_ARCHITECTURES "90" CACHE STRING "CUDA architectures")
    endif()
    enable_language(CUDA)
    find_package(CUDAToolkit REQUIRED)
    set(CMAKE_CUDA_STANDARD 17)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    set(EMOFACE_HAVE_CUDA ON)
    message(STATUS "emoface: CUDA backends ON (${CMAKE_CUDA_COMPILER}, archs ${CMAKE_CUDA_ARCHITECTURES})")
  else()
    message(STATUS "emoface: no nvcc found, CUDA backends OFF (CPU paths only)")
  endif()
else()
  message(STATUS "emoface: CUDA backends OFF (-DEMOFACE_CUDA=OFF)")
endif()
