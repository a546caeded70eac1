#!/bin/sh
# Runs a test program with an Open MPI session directory of its own (OMPI_MCA_orte_tmpdir_base), removed after it.
# Open MPI 4 creates and removes its per-user session directory under /tmp for every program that starts MPI, and
# two programs doing so at the same moment can collide ("A call to mkdir was unable to create the desired directory
# ... File exists", open-mpi/ompi#8510); ctest runs several test programs at once, each starting MPI and `immerse`.
dir=$(mktemp -d /tmp/immerse-mpi.XXXXXX) || exit 1
OMPI_MCA_orte_tmpdir_base=$dir "$@"
status=$?
rm -rf "$dir"
exit $status
