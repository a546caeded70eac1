#pragma once
// Work sizes below which a loop runs on one thread: starting a parallel region and waking its threads costs from
// a few microseconds (threads spinning) to tens of microseconds (threads asleep, or inter-processor interrupts in a
// virtual machine), more than such a loop's whole work. bench/threads.py times the runs that depend on them
// (docs/performance.md, "Threads").

namespace immerse {

/// Loops over the cells or faces of the grid (stencils, transforms, field updates).
inline constexpr long kMinCellsForThreads = 65536;
/// Element-wise loops over doubles (copies, axpy-like updates of the implicit unknowns).
inline constexpr long kMinValuesForThreads = 1L << 15;
/// Per-node kernels of the coupling (delta-function stencils: spreading, interpolation, node checks).
inline constexpr long kMinNodesForThreads = 2048;
/// Per-element and per-node kernels of one membrane (forces, curvature fit, geometry).
inline constexpr long kMinElementsForThreads = 1024;

}  // namespace immerse
