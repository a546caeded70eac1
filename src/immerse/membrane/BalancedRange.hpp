#pragma once
// Work-balanced static partition of a node loop among the threads of the enclosing OpenMP parallel region.
// Node i's work is proportional to prefix[i + 1] - prefix[i] (its element-node slots or neighbours), which
// varies by 3x between vertices and mid-side nodes, and the mesh generators number vertices first: an even
// split of the node indices would leave one thread with twice the work. Each node is still computed by exactly
// one thread with a fixed summation order, so results do not depend on the thread count.
#include <algorithm>
#include <utility>
#include <vector>

#include <omp.h>

namespace immerse {

/// [begin, end) of the calling thread's nodes; prefix has one entry per node plus one, non-decreasing.
inline std::pair<int, int> balanced_node_range(const std::vector<int>& prefix) {
  const int threads = omp_get_num_threads(), t = omp_get_thread_num();
  const long long total = prefix.back();
  auto bound = [&](int k) {
    const long long target = total * k / threads;
    return static_cast<int>(std::lower_bound(prefix.begin(), prefix.end(), target) - prefix.begin());
  };
  const int n = static_cast<int>(prefix.size()) - 1;
  return {std::min(bound(t), n), t + 1 == threads ? n : std::min(bound(t + 1), n)};
}

}  // namespace immerse
