# Cross build for 64-bit ARM onboard computers (Debian g++-aarch64-linux-gnu); unit tests run
# under qemu-user through CMAKE_CROSSCOMPILING_EMULATOR.
set(MMLFW_CROSS_TRIPLET aarch64-linux-gnu)
set(MMLFW_CROSS_PROCESSOR aarch64)
set(MMLFW_CROSS_QEMU qemu-aarch64)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
