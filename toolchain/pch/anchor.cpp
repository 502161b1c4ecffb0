// The one source of the precompiled-header donors (toolchain/pch.cmake): a donor target compiles
// its header set once; every target of the same compile flags reuses that header file.
namespace mmlfw_pch {
int anchor() { return 0; }
}  // namespace mmlfw_pch
