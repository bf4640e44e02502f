"""The workflow's Slurm and generic cluster profiles, run through a real one-node Slurm cluster.

A small probe workflow checks that the profiles' resource requests reach sbatch and that failed
jobs are detected and retried; the DEM stage of the tiny study run through the ``slurm`` profile
must give the same results as a local run, with every non-local job executed by Slurm.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pandas as pd
import pytest
import yaml

from .conftest import PROFILES, ROOT, local_cluster, snakemake

pytestmark = [pytest.mark.workflow, pytest.mark.slow]

# The test cluster has no accounting database, so sacct cannot report states; squeue can, for
# MinJobAge seconds after a job ends. Short status intervals keep the test quick.
SLURM_TEST_ARGS = (
    "--slurm-status-command",
    "squeue",
    "--slurm-init-seconds-before-status-checks",
    "2",
    "--seconds-between-status-checks",
    "2",
    "--slurm-keep-successful-logs",
)

PROBE_SNAKEFILE = """
rule all:
    input:
        "probe/declared.txt",
        "probe/defaults.txt",


rule declared:
    output:
        "probe/declared.txt",
    threads: 2
    resources:
        runtime=7,
        mem_mb=300,
    shell:
        "echo job=$SLURM_JOB_ID cpus=$SLURM_CPUS_PER_TASK > {output}"


rule defaults:
    output:
        "probe/defaults.txt",
    shell:
        "echo job=$SLURM_JOB_ID cpus=$SLURM_CPUS_PER_TASK > {output}"


rule fails:
    output:
        "probe/never.txt",
    shell:
        "exit 3"
"""


def profile(name: str) -> dict:
    """The YAML of ``workflow/profiles/<name>/config.yaml``."""
    return yaml.safe_load((PROFILES / name / "config.yaml").read_text())


def jobcomp_by_id(cluster: local_cluster.LocalCluster) -> dict[str, dict[str, str]]:
    """Finished jobs of the test cluster, by Slurm job id."""
    return {
        rec["JobId"]: rec for rec in local_cluster.parse_jobcomp(cluster.jobcomp_log.read_text())
    }


def probe_record(path: Path) -> dict[str, str]:
    """``key=value`` words a probe job wrote."""
    return dict(word.split("=", 1) for word in path.read_text().split())


def tres(rec: dict[str, str]) -> dict[str, str]:
    """The trackable resources (cpu, mem, node) a finished job was given."""
    return dict(item.split("=", 1) for item in rec["Tres"].split(",") if "=" in item)


@pytest.fixture
def probe_dir(tmp_path: Path) -> Path:
    """A run directory holding the probe workflow."""
    (tmp_path / "Snakefile").write_text(PROBE_SNAKEFILE)
    return tmp_path


# ---- without daemons: the helpers and the profiles themselves -------------------------------


def test_node_line_and_config_follow_slurmd_report():
    node = local_cluster.parse_node_hardware(
        "NodeName=n1 CPUs=8 Boards=1 SocketsPerBoard=2 CoresPerSocket=4 ThreadsPerCore=1 "
        "RealMemory=31000\nUpTime=1-02:03:04\n"
    )
    assert (node.name, node.cpus, node.sockets_per_board, node.real_memory_mb) == (
        "n1",
        8,
        2,
        31000,
    )
    conf = local_cluster.render_slurm_conf(node, Path("/s"), Path("/l"), partition="p")
    lines = conf.splitlines()
    assert lines[0] == local_cluster.MARKER
    node_line = next(ln for ln in lines if ln.startswith("NodeName="))
    assert "CPUs=8" in node_line and "RealMemory=31000" in node_line
    assert "PartitionName=p Nodes=n1 Default=YES MaxTime=INFINITE State=UP" in lines
    assert "JobCompLoc=/l/jobcomp.log" in lines
    with pytest.raises(ValueError, match="RealMemory"):
        local_cluster.parse_node_hardware("NodeName=n1 CPUs=8 Boards=1 SocketsPerBoard=2")


def test_jobcomp_lines_parse_into_fields():
    text = (
        "JobId=12 UserId=root(0) Name=abc JobState=COMPLETED TimeLimit=7 "
        "Tres=cpu=2,mem=300M,node=1 ExitCode=0:0\n\n"
        "JobId=13 Name=abc JobState=FAILED ReservationName= ExitCode=3:0\n"
    )
    recs = local_cluster.parse_jobcomp(text)
    assert [r["JobId"] for r in recs] == ["12", "13"]
    assert recs[0]["Tres"] == "cpu=2,mem=300M,node=1" and recs[1]["ReservationName"] == ""
    assert tres(recs[0]) == {"cpu": "2", "mem": "300M", "node": "1"}


def test_site_settings_are_left_to_the_user():
    slurm = profile("slurm")["default-resources"]
    assert slurm["slurm_partition"] == "" and slurm["slurm_account"] == ""
    assert profile("cluster-generic")["default-resources"]["cluster_args"] == ""
    assert profile("local")["cores"] == "all"


# ---- with a running cluster -----------------------------------------------------------------


def test_second_start_is_refused_and_leaves_the_running_cluster_alone(slurm_cluster):
    # Two test sessions on one machine share /etc/slurm/slurm.conf: a second start used to stop
    # the first one's daemons and hang its jobs. It must fail at once, naming the holder.
    res = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "slurm" / "local_cluster.py"), "start"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 1, res.stdout + res.stderr
    assert f"already in use by process {os.getpid()}" in res.stderr
    assert slurm_cluster.pids and all(local_cluster._alive(p) for p in slurm_cluster.pids.values())
    assert local_cluster.MARKER in local_cluster.CONF_PATH.read_text()
    idle = subprocess.run(
        ["sinfo", "-h", "-n", slurm_cluster.node.name, "-o", "%T"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert idle.stdout.strip() == "idle"


def test_slurm_profile_requests_reach_sbatch(slurm_cluster, probe_dir):
    res = snakemake(
        probe_dir,
        "--profile",
        str(PROFILES / "slurm"),
        *SLURM_TEST_ARGS,
        snakefile=probe_dir / "Snakefile",
        timeout=300,
    )
    assert res.returncode == 0, res.stderr[-4000:]
    log = res.stdout + res.stderr
    run_id = re.search(r"SLURM run ID: (\S+)", log).group(1)
    declared = probe_record(probe_dir / "probe" / "declared.txt")
    defaults = probe_record(probe_dir / "probe" / "defaults.txt")
    assert declared["job"] and defaults["job"] and declared["job"] != defaults["job"]
    assert declared["cpus"] == "2"

    finished = jobcomp_by_id(slurm_cluster)
    rec = finished[declared["job"]]
    assert rec["Name"] == run_id and rec["JobState"] == "COMPLETED"
    assert rec["Partition"] == slurm_cluster.partition
    assert rec["TimeLimit"] == "7"
    assert tres(rec)["cpu"] == "2" and tres(rec)["mem"] == "300M"
    # A rule without declared needs gets the profile's default resources.
    default_res = profile("slurm")["default-resources"]
    rec = finished[defaults["job"]]
    assert rec["JobState"] == "COMPLETED"
    assert rec["TimeLimit"] == str(default_res["runtime"])
    assert tres(rec)["mem"] == f"{default_res['mem_mb']}M" and tres(rec)["cpu"] == "1"
    # The sbatch logs land where the profile puts them.
    logdir = probe_dir / profile("slurm")["slurm-logdir"]
    assert sorted(p.name for p in logdir.rglob("*.log")) == sorted(
        f"{rec_id}.log" for rec_id in (declared["job"], defaults["job"])
    )


def test_generic_profile_submits_with_sbatch(slurm_cluster, probe_dir):
    res = snakemake(
        probe_dir,
        "--profile",
        str(PROFILES / "cluster-generic"),
        "--seconds-between-status-checks",
        "2",
        "all",
        "probe/never.txt",
        snakefile=probe_dir / "Snakefile",
        timeout=300,
    )
    log = res.stdout + res.stderr
    # The failing rule makes the run fail, after the profile's retries, and nothing else.
    assert res.returncode != 0
    declared = probe_record(probe_dir / "probe" / "declared.txt")
    defaults = probe_record(probe_dir / "probe" / "defaults.txt")
    assert declared["cpus"] == "2"

    finished = jobcomp_by_id(slurm_cluster)
    rec = finished[declared["job"]]
    assert rec["Name"] == "demcal.declared" and rec["JobState"] == "COMPLETED"
    assert rec["TimeLimit"] == "7" and tres(rec)["cpu"] == "2" and tres(rec)["mem"] == "300M"
    default_res = profile("cluster-generic")["default-resources"]
    rec = finished[defaults["job"]]
    assert rec["Name"] == "demcal.defaults" and rec["JobState"] == "COMPLETED"
    assert rec["TimeLimit"] == str(default_res["runtime"])
    assert tres(rec)["mem"] == f"{default_res['mem_mb']}M"

    submitted = re.findall(r"Submitted job \d+ with external jobid '(\d+)'", log)
    failed = [finished[j] for j in submitted if finished[j]["Name"] == "demcal.fails"]
    assert len(failed) == 1 + profile("cluster-generic")["retries"]
    assert all(r["JobState"] == "FAILED" and r["ExitCode"] != "0:0" for r in failed)
    assert (probe_dir / "logs" / "cluster" / f"declared.{declared['job']}.log").is_file()


# ---- the tiny study: Slurm against a local run ---------------------------------------------

# The DEM stage of the tiny study (design, decks, engine runs, bulk values, dataset) with one
# parameter set: its four shear decks and one heap make five DEM cases in three Slurm bundles,
# the last one short - what a cluster runs, in a minute or two on the 2-core test machine.
TINY_TARGET = "results/bulk/dataset.csv"
TINY_DESIGN_N = 1
# The bundling the profiles describe for small studies: two DEM cases per allocation (side by
# side on the 2-core node). One machine has no file-system latency to wait for.
BUNDLE = 2
TINY_SLURM_ARGS = (
    "--groups",
    "run_case=dem_cases",
    "--group-components",
    f"dem_cases={BUNDLE}",
    "--latency-wait",
    "5",
)
# Run logs whose content includes wall-clock and CPU times.
TIMED_FILES = {"engine.out", "log.liggghts"}
#: Snakemake's benchmark records and the run-time table and figure drawn from them: times,
#: memory and load of each run only.
TIMED_FOLDERS = ("benchmarks",)
TIMED_FIGURES = {"run_times.png", "run_times.csv"}


def tiny_workdir(path: Path) -> Path:
    """A scratch run directory with the repository's configs and the reduced tiny config."""
    path.mkdir(parents=True)
    shutil.copytree(ROOT / "config", path / "config")
    config = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())
    config["design"]["n"] = TINY_DESIGN_N
    (path / "tiny.yaml").write_text(yaml.safe_dump(config))
    return path


def without_timings(value):
    """JSON content without wall-clock entries (keys ending in 'seconds')."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if not k.endswith("seconds")}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def result_differences(local: Path, remote: Path) -> list[str]:
    """Files of two ``results/`` trees that differ, apart from timings.

    CSV tables are compared value by value without columns ending in 'seconds', JSON without
    such keys, the engine's run logs, benchmark records and the run-time table and figure only for
    presence, everything else byte by byte.
    """
    files_a = {p.relative_to(local) for p in local.rglob("*") if p.is_file()}
    files_b = {p.relative_to(remote) for p in remote.rglob("*") if p.is_file()}
    diffs = [f"only in one run: {p}" for p in sorted(files_a ^ files_b)]
    for rel in sorted(files_a & files_b):
        a, b = local / rel, remote / rel
        if rel.name in TIMED_FILES | TIMED_FIGURES or rel.parts[0] in TIMED_FOLDERS:
            continue
        if rel.suffix == ".csv":
            fa, fb = pd.read_csv(a), pd.read_csv(b)
            keep = [c for c in fa.columns if not str(c).endswith("seconds")]
            if list(fa.columns) != list(fb.columns) or not fa[keep].equals(fb[keep]):
                diffs.append(f"table differs: {rel}")
        elif rel.suffix == ".json":
            if without_timings(json.loads(a.read_text())) != without_timings(
                json.loads(b.read_text())
            ):
                diffs.append(f"JSON differs: {rel}")
        elif a.read_bytes() != b.read_bytes():
            diffs.append(f"bytes differ: {rel}")
    return diffs


def scheduled_jobs(log: str) -> tuple[set[str], set[str]]:
    """Jobs in a Snakemake log as ``rule:wildcards``: (non-local, local)."""
    remote: set[str] = set()
    local: set[str] = set()
    lines = log.splitlines()
    for i, line in enumerate(lines):
        head = re.match(r"^\s*(local)?rule (\w+):$", line)
        if not head:
            continue
        wildcards = ""
        for follow in lines[i + 1 : i + 12]:
            if re.match(r"^\s*(local)?rule \w+:$", follow) or not follow.startswith(" "):
                break
            found = re.match(r"^\s*wildcards: (.*)$", follow)
            if found:
                wildcards = found.group(1).replace(", ", ",")
        (local if head.group(1) else remote).add(f"{head.group(2)}:{wildcards}")
    return remote, local


def slurm_job_targets(slurm_log: Path) -> set[str]:
    """The jobs one Slurm job ran: the ``--target-jobs`` of its Snakemake command line."""
    for line in slurm_log.read_text(errors="replace").splitlines():
        if "--target-jobs" in line:
            words = line.split("--target-jobs", 1)[1].split()
            targets = []
            for word in words:
                if word.startswith("--"):
                    break
                targets.append(word)
            return set(targets)
    raise AssertionError(f"{slurm_log}: no --target-jobs in the job's log")


@pytest.fixture(scope="module")
def tiny_runs(slurm_cluster, tmp_path_factory) -> dict:
    """The DEM stage of the tiny study, run locally and through the ``slurm`` profile."""
    base = tmp_path_factory.mktemp("tiny_cluster")
    local_dir = tiny_workdir(base / "local")
    # Both runs read one snapshot of the configuration.
    slurm_dir = Path(shutil.copytree(local_dir, base / "slurm"))
    # Side by side: the Slurm run mostly waits for job starts and status checks, and the
    # single-threaded engine runs give the same results however the cores are shared.
    with ThreadPoolExecutor(max_workers=2) as pool:
        local = pool.submit(
            snakemake,
            local_dir,
            TINY_TARGET,
            "--profile",
            str(PROFILES / "local"),
            "--configfile",
            str(local_dir / "tiny.yaml"),
        )
        slurm = pool.submit(
            snakemake,
            slurm_dir,
            TINY_TARGET,
            "--profile",
            str(PROFILES / "slurm"),
            *SLURM_TEST_ARGS,
            *TINY_SLURM_ARGS,
            "--configfile",
            str(slurm_dir / "tiny.yaml"),
        )
        local_res, res = local.result(), slurm.result()
    assert local_res.returncode == 0, "local run failed:\n" + local_res.stderr[-4000:]
    assert res.returncode == 0, "Slurm run failed:\n" + res.stderr[-4000:]
    return {"local": local_dir, "slurm": slurm_dir, "log": res.stdout + res.stderr}


def test_tiny_study_through_slurm_equals_local_run(tiny_runs):
    local, remote = tiny_runs["local"] / "results", tiny_runs["slurm"] / "results"
    cases = sorted(p.parent.name for p in remote.glob("cases/*/*/status.json"))
    tiny = yaml.safe_load((ROOT / "config" / "tiny.yaml").read_text())["shear_cell"]
    per_set = len(tiny["normal_stresses"]) * len(tiny["P"]) + 1  # separate shear decks + a heap
    assert tiny["separate_runs"] and len(cases) == per_set * TINY_DESIGN_N, cases
    statuses = [json.loads(p.read_text())["status"] for p in remote.glob("cases/*/*/status.json")]
    assert statuses.count("ok") == len(statuses), statuses
    assert result_differences(local, remote) == []


def test_every_remote_job_of_the_tiny_study_ran_in_slurm(tiny_runs, slurm_cluster):
    log = tiny_runs["log"]
    run_id = re.search(r"SLURM run ID: (\S+)", log).group(1)
    remote, _ = scheduled_jobs(log)
    assert remote

    logdir = tiny_runs["slurm"] / profile("slurm")["slurm-logdir"]
    targets = {p.stem: slurm_job_targets(p) for p in logdir.rglob("*.log")}
    finished = {
        job_id: rec for job_id, rec in jobcomp_by_id(slurm_cluster).items() if rec["Name"] == run_id
    }
    # One Slurm job per submission, each completed, and together they ran every non-local job.
    assert set(targets) == set(finished)
    assert all(rec["JobState"] == "COMPLETED" for rec in finished.values())
    assert set().union(*targets.values()) == remote

    # Each DEM case ran in exactly one Slurm job, BUNDLE cases per job.
    case_dirs = {
        f"run_case:stage=cases,test={p.parent.parent.name},case={p.parent.name}"
        for p in (tiny_runs["slurm"] / "results").glob("cases/*/*/status.json")
    }
    bundles = [t for t in targets.values() if any(j.startswith("run_case:") for j in t)]
    assert sorted(j for t in bundles for j in t) == sorted(case_dirs)
    assert len(bundles) == math.ceil(len(case_dirs) / BUNDLE)
    assert all(len(t) <= BUNDLE for t in bundles)
