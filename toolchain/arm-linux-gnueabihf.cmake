# Cross build for 32-bit ARM (armhf) onboard computers (Debian g++-arm-linux-gnueabihf); unit tests run
# under qemu-user through CMAKE_CROSSCOMPILING_EMULATOR.
set(MMLFW_CROSS_TRIPLET arm-linux-gnueabihf)
set(MMLFW_CROSS_PROCESSOR armv7l)
set(MMLFW_CROSS_QEMU qemu-arm)
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
