#!/usr/bin/env bash
# Status of one Slurm job for Snakemake's cluster-generic executor: prints running, success or
# failed. The argument is what `sbatch --parsable` printed ("jobid" or "jobid;cluster").
set -uo pipefail
jobid="${1%%;*}"

# The controller knows queued, running and recently finished jobs.
if out=$(scontrol show job "$jobid" --oneliner 2>&1); then
    state=$(grep -o 'JobState=[A-Z_]*' <<<"$out" | head -n1 | cut -d= -f2)
else
    state=""
    # Any controller error other than an unknown job id: ask again at the next check.
    grep -qi "invalid job id" <<<"$out" || { echo running; exit 0; }
fi
# Jobs the controller has already forgotten: the accounting database, where there is one.
if [ -z "$state" ] && command -v sacct >/dev/null 2>&1; then
    state=$(sacct -j "$jobid" -X -n -P -o State 2>/dev/null | head -n1 | cut -d' ' -f1)
fi

case "$state" in
    COMPLETED) echo success ;;
    BOOT_FAIL | CANCELLED | DEADLINE | FAILED | NODE_FAIL | OUT_OF_MEMORY | PREEMPTED | TIMEOUT)
        echo failed ;;
    "") echo failed ;;  # neither the controller nor accounting knows the job
    *) echo running ;;
esac
