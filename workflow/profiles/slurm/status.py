#!/usr/bin/python3
"""Snakemake cluster-status command: prints running, success or failed for a Slurm job id.

Asks `scontrol show job` (knows jobs until MinJobAge after they end) and falls back to
`sacct` (needs accounting); a job that slurmctld no longer knows and accounting does not
either is reported failed, and one whose state cannot be asked (slurmctld busy) running. Always exits 0:
Snakemake aborts the whole run when the status command fails.
"""
import re
import subprocess
import sys
import time

# Every state from which the job may still run: a "failed" for one of these would let Snakemake
# resubmit the job while it still writes its outputs.
RUNNING = {"PENDING", "RUNNING", "CONFIGURING", "COMPLETING", "SUSPENDED", "REQUEUED", "REQUEUE_FED",
           "REQUEUE_HOLD", "RESIZING", "SIGNALING", "STAGE_OUT", "STOPPED", "RESV_DEL_HOLD", "SPECIAL_EXIT"}
UNKNOWN = "UNKNOWN"  # slurmctld did not answer: not a verdict


def run(*cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError):
        return None


def scontrol_state(jobid):
    # Retry when slurmctld is busy or briefly unreachable: a wrong "failed" loses a good job.
    for attempt in range(3):
        result = run("scontrol", "show", "job", jobid)
        if result and result.returncode == 0:
            match = re.search(r"JobState=(\w+)", result.stdout)
            return match.group(1) if match else None
        if result and "Invalid job id" in result.stderr:
            return None  # slurmctld has forgotten the job (MinJobAge)
        time.sleep(5)
    return UNKNOWN


def sacct_state(jobid):
    result = run("sacct", "-n", "-X", "-P", "-o", "State", "-j", jobid)
    words = result.stdout.split() if result and result.returncode == 0 else []
    return words[0] if words else None  # "CANCELLED by 0": the first word is the state


def main():
    jobid = sys.argv[1].split(";")[0]  # sbatch --parsable prints "id" or "id;cluster"
    state = scontrol_state(jobid)
    if state == UNKNOWN:  # ask again at the next check rather than fail a job that may be running
        state = sacct_state(jobid) or "RUNNING"
    elif state is None:  # forgotten by slurmctld: accounting may still know
        state = sacct_state(jobid)
    if state in RUNNING:
        print("running")
    elif state == "COMPLETED":
        print("success")
    else:
        print("failed")


if __name__ == "__main__":
    main()
