#pragma once
// How a decomposed run ends when something throws on some of its ranks (issue 34, docs/robustness.md):
// an error thrown on every rank alike (a rank file's write failure, which DecomposedOutput agrees on; a
// checkpoint's; a thermal solver's) ends the run as a breakdown, published with status `failed`; an
// error on one rank alone, while the others wait in a collective call of the step, can only end every
// rank (MPI_Abort) — after rank 0, if it is the one, has published what it holds.
#include <mpi.h>

#include <optional>
#include <string>

namespace frictherm::coupling::detail {

/// Called by each rank that caught an exception, with its message, on a communicator used for nothing
/// else (`comm`: a duplicate of the run's). When every rank of `comm` calls it within
/// `timeout_seconds` (the error was thrown on every rank alike), returns the lowest rank's message on
/// every rank. Otherwise (this rank failed alone: the others wait in some collective call of the run)
/// returns nothing after the timeout; the agreement stays posted, and the caller ends the processes.
/// Non-blocking (MPI_Iallreduce, tested every millisecond) so that a rank failing alone never waits
/// in a collective call the others do not make.
std::optional<std::string> agree_on_failure(MPI_Comm comm, const std::string& message, double timeout_seconds);

}  // namespace frictherm::coupling::detail
