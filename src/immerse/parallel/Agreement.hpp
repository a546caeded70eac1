#pragma once
// How the processes of a run agree: a text sent from one process to all, the first error any process met (so that
// every process takes the same way out of a collective phase), the largest or smallest of a number. Collective.
#include <string>

#include "immerse/parallel/Communicator.hpp"

namespace immerse {

/// `text` of process `root`, on every process.
std::string broadcast_text(const Communicator& comm, std::string text, int root = 0);
/// The nonempty `error` of the lowest-ranked process that has one, on every process; empty if none has.
std::string first_error(const Communicator& comm, const std::string& error);
/// The largest `value` over the processes, on every process.
int max_over_processes(const Communicator& comm, int value);
/// The smallest `value` over the processes, on every process (exact: the same bits as the smallest one's).
double min_over_processes(const Communicator& comm, double value);

}  // namespace immerse
