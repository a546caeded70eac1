#pragma once
// `immerse run` over several MPI processes (`mpirun -np N immerse run ...`; run_command comes here when
// MPI_COMM_WORLD has more than one process), with DistributedSimulation: the explicit and implicit schemes but the dense
// BFGS, contact, the viscosity contrast and the volume correction.
//
// Every process reads and checks the whole input (configuration, scenario kind, process count against the grid's z
// planes, the checkpoint of a restart) and builds the run; bad input ends every process with status 2, one line on
// rank 0 and nothing written. Rank 0 then takes the output folder with the rules of the one-process run (RunOutput:
// lock, refusal of another run's folder without --overwrite, rows kept when continuing in place) and tells the others;
// it writes diagnostics.csv, its table of columns, config.resolved.toml (with the provenance), the copies of mesh
// files, the XDMF series and the log. Frames (fields_NNNNNN.h5) and checkpoints are written by all processes together
// (parallel HDF5, ParallelCheckpoint), each its own z planes and membranes; the file layouts are those of the
// one-process run, so its readers (Checkpoint::read, the XDMF series, the Python package) read them, and a checkpoint
// restarts on any number of processes or in one.
//
// The time loop steps, writes on the schedules of RunOutput and stops, on every process together, when the run ends,
// becomes unstable (status 3: the message on rank 0, the last state saved as in one process), a write fails (5) or
// a process received SIGINT, SIGTERM, SIGHUP or SIGQUIT (4: agreed by a reduction after each step, then a checkpoint).
// Verified by: the tests RunMpi.* (tests/test_run_mpi.cpp: `mpiexec -n N immerse run` on 1 to 3 processes) and
// Python.OutputFiles (a 2-process run's files read by meshio and h5py, its frames against one process's).
#include <iosfwd>

#include "immerse/app/RunOptions.hpp"

namespace immerse {

/// Runs `options` over the processes of MPI_COMM_WORLD; returns the exit status of run_command on every process.
/// `out` and `err` are written by rank 0 only. Collective.
int run_distributed(const RunOptions& options, std::ostream& out, std::ostream& err);

}  // namespace immerse
