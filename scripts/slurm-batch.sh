#!/bin/bash
#SBATCH --job-name=evcorner-batch
#SBATCH --nodes=4
#SBATCH --ntasks-per-node=16
#SBATCH --cpus-per-task=1
#SBATCH --time=02:00:00
# `python -m evcorner batch` on a Slurm allocation: one task runs the Dask scheduler, every
# other task a single-threaded Dask worker, and this script the batch driver. The
# arguments are the batch's (inputs, -d, -p, -o, --to ...):
#
#   sbatch scripts/slurm-batch.sh /scratch/recordings/*.raw -d efast,harris,arcstar -o /scratch/out
#
# Every Dask process is the venv's interpreter (`$PY -m dask scheduler|worker`), the one
# evcorner is installed in: the `dask` command on PATH may be another Python's, whose
# workers cannot import evcorner. Environment:
#   EVCORNER_VENV  the venv (default ~/evcorner/.venv, made as README.md says)
#   DASK_HOST      the address the scheduler and the workers listen on (default: Dask's choice)
# Submitting the job again resumes the batch (finished tasks are skipped).
set -u
PY=${EVCORNER_VENV:-$HOME/evcorner/.venv}/bin/python
SCHED=$HOME/evcorner-sched-$SLURM_JOB_ID.json
host=()
if [ -n "${DASK_HOST:-}" ]; then host=(--host "$DASK_HOST"); fi
rm -f "$SCHED"
srun --nodes=1 --ntasks=1 --exclusive "$PY" -m dask scheduler --scheduler-file "$SCHED" "${host[@]}" &
scheduler=$!
while [ ! -f "$SCHED" ]; do
    if ! kill -0 "$scheduler" 2>/dev/null; then echo "slurm-batch.sh: the scheduler did not start" >&2; exit 1; fi
    sleep 1
done
srun --ntasks=$((SLURM_NTASKS - 1)) "$PY" -m dask worker --scheduler-file "$SCHED" --nthreads 1 \
     --memory-limit 0 --local-directory /tmp "${host[@]}" &
workers=$!
"$PY" -m evcorner batch "$@" --scheduler-file "$SCHED"
status=$?
kill "$workers" "$scheduler" 2>/dev/null
wait
rm -f "$SCHED"
exit $status
