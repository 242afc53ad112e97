#pragma once
// The sliding maximum or minimum of van Herk and Gil-Werman: three comparisons a position
// whatever the window. Cut the input into blocks of the window's length; the extremum of
// a window is that of the part of it in one block, running to the block's end, and the
// part in the next, running from the block's start. Used by the column sweeps of
// morphology (geometry/morphology_columns.cpp) and the planner's reach of a head over
// material (planner/atoms/deposit_reach.cpp).

namespace hybridctl::geometry {

// from_start[i]: the extremum of in[] from the start of i's block of `block` to i;
// to_end[i]: from i to the end of its block (or of the input). `pick` returns the better
// of two values (std::max or std::min's shape).
template <typename T, typename Pick>
void block_extrema(const T* in, int len, int block, T* from_start, T* to_end, Pick pick) {
  for (int i = 0; i < len; ++i) from_start[i] = i % block == 0 ? in[i] : pick(from_start[i - 1], in[i]);
  for (int i = len - 1; i >= 0; --i) to_end[i] = (i % block == block - 1 || i == len - 1) ? in[i] : pick(to_end[i + 1], in[i]);
}

// The extremum of in[first .. first + block) from block_extrema's two arrays.
template <typename T, typename Pick>
T window_extremum(const T* from_start, const T* to_end, int first, int block, Pick pick) {
  return pick(to_end[first], from_start[first + block - 1]);
}

}  // namespace hybridctl::geometry
