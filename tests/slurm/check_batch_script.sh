#!/bin/bash
# The example batch script scripts/slurm/immerse.sbatch as Slurm would run it, with srun standing for mpiexec:
# a new run of the quick channel on 2 tasks, then its continuation from the checkpoint (RESTART) on 3.
# Usage: check_batch_script.sh SOURCE_DIR IMMERSE MPIEXEC WORK_DIR
set -euo pipefail
src=$1 immerse=$2 mpiexec=$3 work=$4
rm -rf "$work" && mkdir -p "$work/bin"
# srun: the tasks of the job, each a process of mpiexec (the --cpu-bind option is Slurm's own).
cat > "$work/bin/srun" <<SRUN
#!/bin/bash
[[ "\$1" == --cpu-bind=* ]] && shift
exec "$mpiexec" -q -n "\$SLURM_NTASKS" --oversubscribe "\$@"
SRUN
chmod +x "$work/bin/srun"
export PATH="$work/bin:$PATH" OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm=isolated
export ASAN_OPTIONS=detect_leaks=0 SLURM_CPUS_PER_TASK=1 IMMERSE="$immerse"
export CONFIG="$src/scenarios/rbc_channel_quick.toml" OUT="$work/out/channel"
cd "$work"

SLURM_NTASKS=2 SETS="--set time.end=9e-4 --set output.fields_every=0" bash "$src/scripts/slurm/immerse.sbatch" \
  > first.log 2>&1 || { cat first.log; echo "FAIL: the first job exited with $?"; exit 1; }
grep -q "distributed over 2 MPI processes" first.log || { cat first.log; echo "FAIL: not run on 2 processes"; exit 1; }
[[ -f out/channel/checkpoint.h5 ]] || { echo "FAIL: no checkpoint"; exit 1; }

SLURM_NTASKS=3 RESTART=out/channel/checkpoint.h5 SETS="--set time.end=1.8e-3 --set output.fields_every=0" \
  bash "$src/scripts/slurm/immerse.sbatch" > second.log 2>&1 || { cat second.log; echo "FAIL: the restart job exited with $?"; exit 1; }
grep -q "distributed over 3 MPI processes" second.log || { cat second.log; echo "FAIL: not run on 3 processes"; exit 1; }
# The continued folder holds the rows of steps 0 to 4, one each.
steps=$(tail -n +2 out/channel/diagnostics.csv | cut -d, -f1 | tr '\n' ' ')
[[ "$steps" == "0 1 2 3 4 " ]] || { echo "FAIL: diagnostics.csv has the steps '$steps', not 0 to 4"; exit 1; }
echo "batch script: 2 steps on 2 tasks, continued to step 4 on 3 tasks from the checkpoint"
