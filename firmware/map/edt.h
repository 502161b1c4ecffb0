// Exact squared Euclidean distance transform (Felzenszwalb & Huttenlocher 2012), separable, so the
// same code serves 2D grids (MCL distance image, pRANSAM contact grid) and 3D voxel fields (pRANSAM
// 3D). Input: f[i] = 0 at feature cells, kEdtInf elsewhere. Output: squared distance in cells² to
// the nearest feature. Scratch buffers are caller-provided (no allocation): see EdtScratch.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fw {

constexpr float kEdtInf = 1e20f;

// Scratch for a 1D pass over n samples: v (int, n), z (float, n+1), f copy (float, n), d (float, n).
struct EdtScratch {
  int* v = nullptr;
  float* z = nullptr;
  float* f = nullptr;
  float* d = nullptr;
  std::size_t capacity = 0;  // n the buffers hold (z holds capacity + 1)
};

// 1D squared distance transform of f (stride `stride`) of length n, in place.
void squared_edt_1d(float* data, std::size_t n, std::size_t stride, const EdtScratch& scratch);

// N-D transform of a dense row-major array with dims[0] the slowest axis; in place.
// scratch.capacity must be ≥ the largest dimension.
template <int kDim>
void squared_edt(float* data, const std::size_t (&dims)[kDim], const EdtScratch& scratch) {
  std::size_t total = 1;
  for (int a = 0; a < kDim; ++a) total *= dims[a];
  for (int axis = 0; axis < kDim; ++axis) {
    std::size_t stride = 1;
    for (int a = axis + 1; a < kDim; ++a) stride *= dims[a];
    const std::size_t n = dims[axis];
    const std::size_t block = stride * n;
    for (std::size_t outer = 0; outer < total; outer += block) {
      for (std::size_t inner = 0; inner < stride; ++inner) {
        squared_edt_1d(data + outer + inner, n, stride, scratch);
      }
    }
  }
}

}  // namespace fw
