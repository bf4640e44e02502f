"""A one-node Slurm cluster on localhost, for running the workflow's scheduler profiles for real.

Writes ``/etc/slurm/slurm.conf`` (the Slurm job-step executor drops ``SLURM_CONF``, so the file
must be at the default path), makes sure a MUNGE key exists, starts ``munged`` (unless one
already answers), ``slurmctld`` and ``slurmd`` in the foreground as child processes, waits until
the node is idle, and stops exactly the processes it started, by their PIDs, removing the
configuration again. One cluster at a time: the process that started one holds a lock on
``/var/lib/demcal-slurm/cluster.lock`` until it stops it (or exits), and a second start while
it is held fails at once, instead of stopping the first one's daemons under its jobs.

Finished jobs are appended to a job-completion log (``jobcomp/filetxt``) that
:func:`parse_jobcomp` reads, because a cluster without ``slurmdbd`` has no ``sacct``.

Command line (as root)::

    python scripts/slurm/local_cluster.py start   # returns once the node is idle
    python scripts/slurm/local_cluster.py status
    python scripts/slurm/local_cluster.py stop    # stops the recorded daemons by PID
"""

from __future__ import annotations

import argparse
import fcntl
import json
import os
import pwd
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

CONF_PATH = Path("/etc/slurm/slurm.conf")
MARKER = "# demcal one-node Slurm cluster on localhost (scripts/slurm/local_cluster.py)"
STATE_DIR = Path("/var/lib/demcal-slurm")
LOG_DIR = Path("/var/log/demcal-slurm")
RECORD = STATE_DIR / "daemons.json"
LOCK = STATE_DIR / "cluster.lock"
MUNGE_KEY = Path("/etc/munge/munge.key")
MUNGE_RUN_DIR = Path("/run/munge")
INSTALL_SCRIPT = Path(__file__).resolve().with_name("install_slurm.sh")
PARTITION = "local"
REQUIRED_BINARIES = (
    "munged",
    "munge",
    "unmunge",
    "slurmctld",
    "slurmd",
    "sbatch",
    "squeue",
    "sinfo",
    "scontrol",
)


class ClusterError(RuntimeError):
    """The local Slurm cluster could not be set up, started or stopped."""


@dataclass(frozen=True)
class NodeHardware:
    """The node line of ``slurm.conf``, as ``slurmd -C`` reports it.

    Attributes
    ----------
    name : str
        Node name (the short host name).
    cpus, boards, sockets_per_board, cores_per_socket, threads_per_core : int
        CPU topology.
    real_memory_mb : int
        Memory of the node, MB.
    """

    name: str
    cpus: int
    boards: int
    sockets_per_board: int
    cores_per_socket: int
    threads_per_core: int
    real_memory_mb: int


@dataclass
class LocalCluster:
    """A running one-node cluster and the daemons this module started for it.

    Attributes
    ----------
    node : NodeHardware
        The single compute node.
    partition : str
        Name of the only (default) partition.
    jobcomp_log : Path
        Job-completion log, one line per finished job.
    pids : dict of str to int
        Daemon name to PID, only for the daemons started here.
    """

    node: NodeHardware
    partition: str
    jobcomp_log: Path
    pids: dict[str, int] = field(default_factory=dict)
    _procs: dict[str, subprocess.Popen] = field(default_factory=dict, repr=False)
    _lock_fd: int | None = field(default=None, repr=False)


def parse_node_hardware(text: str) -> NodeHardware:
    """Read the ``NodeName=...`` line that ``slurmd -C`` prints.

    Parameters
    ----------
    text : str
        Output of ``slurmd -C``.

    Raises
    ------
    ValueError
        If the output has no node line or a field is missing.
    """
    line = next((ln for ln in text.splitlines() if ln.startswith("NodeName=")), None)
    if line is None:
        raise ValueError(f"slurmd -C: no 'NodeName=' line in output {text!r}")
    fields = dict(item.split("=", 1) for item in line.split() if "=" in item)
    keys = {
        "cpus": "CPUs",
        "boards": "Boards",
        "sockets_per_board": "SocketsPerBoard",
        "cores_per_socket": "CoresPerSocket",
        "threads_per_core": "ThreadsPerCore",
        "real_memory_mb": "RealMemory",
    }
    missing = [k for k in ("NodeName", *keys.values()) if k not in fields]
    if missing:
        raise ValueError(f"slurmd -C: field(s) {', '.join(missing)} missing in {line!r}")
    return NodeHardware(name=fields["NodeName"], **{a: int(fields[k]) for a, k in keys.items()})


def render_slurm_conf(
    node: NodeHardware,
    state_dir: Path = STATE_DIR,
    log_dir: Path = LOG_DIR,
    partition: str = PARTITION,
    min_job_age_s: int = 3600,
) -> str:
    """The ``slurm.conf`` of a one-node cluster whose controller and node are this machine.

    Parameters
    ----------
    node : NodeHardware
        The compute node.
    state_dir, log_dir : Path
        Directories for daemon state and logs.
    partition : str
        Name of the single, default partition.
    min_job_age_s : int
        Seconds a finished job stays visible to ``squeue``/``scontrol``, s. Without an
        accounting database this is the only way to see a finished job's state, so it must
        exceed the executor's status-check interval.
    """
    cores = node.cpus
    return "\n".join(
        [
            MARKER,
            "ClusterName=demcal",
            f"SlurmctldHost={node.name}(127.0.0.1)",
            "SlurmUser=root",
            "SlurmdUser=root",
            "AuthType=auth/munge",
            "CredType=cred/munge",
            f"StateSaveLocation={state_dir / 'slurmctld'}",
            f"SlurmdSpoolDir={state_dir / 'slurmd'}",
            f"SlurmctldPidFile={state_dir / 'slurmctld.pid'}",
            f"SlurmdPidFile={state_dir / 'slurmd.pid'}",
            f"SlurmctldLogFile={log_dir / 'slurmctld.log'}",
            f"SlurmdLogFile={log_dir / 'slurmd.log'}",
            # No cgroups in containers: plain process tracking, no task binding.
            "ProctrackType=proctrack/linuxproc",
            "TaskPlugin=task/none",
            "MpiDefault=none",
            "ReturnToService=2",
            "SchedulerType=sched/backfill",
            "SelectType=select/cons_tres",
            "SelectTypeParameters=CR_Core_Memory",
            "AccountingStorageType=accounting_storage/none",
            "JobAcctGatherType=jobacct_gather/none",
            "JobCompType=jobcomp/filetxt",
            f"JobCompLoc={log_dir / 'jobcomp.log'}",
            f"MinJobAge={min_job_age_s}",
            "InactiveLimit=0",
            "KillWait=5",
            "SlurmctldTimeout=30",
            "SlurmdTimeout=30",
            f"NodeName={node.name} NodeAddr=127.0.0.1 CPUs={cores} Boards={node.boards} "
            f"SocketsPerBoard={node.sockets_per_board} CoresPerSocket={node.cores_per_socket} "
            f"ThreadsPerCore={node.threads_per_core} RealMemory={node.real_memory_mb} "
            "State=UNKNOWN",
            f"PartitionName={partition} Nodes={node.name} Default=YES MaxTime=INFINITE State=UP",
            "",
        ]
    )


def parse_jobcomp(text: str) -> list[dict[str, str]]:
    """Parse a ``jobcomp/filetxt`` log: one dict of ``Key=Value`` fields per finished job.

    Parameters
    ----------
    text : str
        Content of the job-completion log.
    """
    return [dict(re.findall(r"(\w+)=(\S*)", line)) for line in text.splitlines() if line.strip()]


def missing_binaries() -> list[str]:
    """Slurm and MUNGE programs that are not on ``PATH`` (sbin included)."""
    path = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/sbin"])
    return [b for b in REQUIRED_BINARIES if shutil.which(b, path=path) is None]


def unavailable_reason(install: bool = True) -> str | None:
    """Why a local cluster cannot run here, or ``None`` if it can.

    Parameters
    ----------
    install : bool
        Install missing Debian packages (``scripts/slurm/install_slurm.sh``) first.
    """
    if os.geteuid() != 0:
        return f"the Slurm and MUNGE daemons need root (running as uid {os.geteuid()})"
    if CONF_PATH.exists() and MARKER not in CONF_PATH.read_text():
        return f"{CONF_PATH} belongs to another Slurm installation; it is left untouched"
    if missing_binaries() and install:
        if shutil.which("apt-get") is None:
            return f"Slurm/MUNGE programs {missing_binaries()} missing and no apt-get"
        res = subprocess.run(
            ["bash", str(INSTALL_SCRIPT)], capture_output=True, text=True, timeout=900
        )
        if res.returncode != 0:
            tail = (res.stdout + res.stderr).strip().splitlines()[-5:]
            return "installing slurm-wlm/munge failed: " + " | ".join(tail)
    missing = missing_binaries()
    if missing:
        return f"Slurm/MUNGE programs missing: {', '.join(missing)}"
    return None


def _sbin_env() -> dict[str, str]:
    """This environment with the daemons' sbin directories on PATH and no SLURM_CONF."""
    env = {k: v for k, v in os.environ.items() if k != "SLURM_CONF"}
    env["PATH"] = os.pathsep.join([env.get("PATH", ""), "/usr/sbin", "/sbin"])
    return env


def _proc_start_ticks(pid: int) -> int | None:
    """Start time of a process in clock ticks since boot (guards against PID reuse)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    # The command name may contain spaces: fields after the closing parenthesis.
    return int(stat.rsplit(")", 1)[1].split()[19])


def _alive(pid: int) -> bool:
    """True while ``pid`` exists and is not a zombie."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _wait_until(
    check: Callable[[], bool], timeout: float, what: str, log: Path | None = None
) -> None:
    """Poll ``check`` until it holds; on timeout raise with the end of ``log``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if check():
            return
        time.sleep(0.5)
    tail = ""
    if log is not None and log.exists():
        tail = "\n" + "\n".join(log.read_text(errors="replace").splitlines()[-15:])
    raise ClusterError(f"timed out after {timeout:.0f} s waiting for {what}{tail}")


def _run_ok(cmd: list[str], check_stdout: Callable[[str], bool] | None = None) -> bool:
    """True if ``cmd`` succeeds (and its output passes ``check_stdout``)."""
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=10, env=_sbin_env())
    except (OSError, subprocess.TimeoutExpired):
        return False
    return res.returncode == 0 and (check_stdout is None or check_stdout(res.stdout))


def _munge_works() -> bool:
    """True if a running munged encodes and decodes a credential."""
    try:
        cred = subprocess.run(["munge", "-n"], capture_output=True, timeout=10, check=True).stdout
        subprocess.run(["unmunge"], input=cred, capture_output=True, timeout=10, check=True)
    except (OSError, subprocess.SubprocessError):
        return False
    return True


def _ensure_munge_key() -> tuple[int, int]:
    """Make sure the MUNGE key exists; return the uid and gid munged should run as."""
    try:
        user = pwd.getpwnam("munge")
        uid, gid = user.pw_uid, user.pw_gid
    except KeyError:
        uid, gid = 0, 0
    MUNGE_KEY.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    if not MUNGE_KEY.exists():
        MUNGE_KEY.write_bytes(os.urandom(1024))
    os.chown(MUNGE_KEY.parent, uid, gid)
    os.chown(MUNGE_KEY, uid, gid)
    MUNGE_KEY.chmod(0o400)
    for d in (MUNGE_RUN_DIR, Path("/var/lib/munge"), Path("/var/log/munge")):
        d.mkdir(mode=0o755 if d == MUNGE_RUN_DIR else 0o700, parents=True, exist_ok=True)
        os.chown(d, uid, gid)
    return uid, gid


def _launch(cluster: LocalCluster, name: str, cmd: list[str], **kwargs: Any) -> None:
    """Start one daemon in the foreground as a child process and record its PID."""
    out = (LOG_DIR / f"{name}.out").open("ab")
    proc = subprocess.Popen(
        cmd,
        stdout=out,
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
        env=_sbin_env(),
        start_new_session=True,
        **kwargs,
    )
    out.close()
    cluster._procs[name] = proc
    cluster.pids[name] = proc.pid
    _write_record(cluster)


def _acquire_lock() -> int:
    """Take the one-cluster lock without waiting; return its file descriptor.

    The lock is the kernel's (``flock``), so it is released when its holder exits, however it
    ends. The file names the holder's PID for the error message.

    Raises
    ------
    ClusterError
        If another process holds the lock, naming that process.
    """
    STATE_DIR.mkdir(parents=True, exist_ok=True)
    fd = os.open(LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
        os.close(fd)
        raise ClusterError(
            f"a local Slurm cluster is already in use by process {holder} ({LOCK} is locked); "
            "two test clusters would share /etc/slurm/slurm.conf and stop each other's daemons: "
            "wait for that process to finish"
        ) from None
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
    return fd


def _release_lock(cluster: LocalCluster) -> None:
    """Release the one-cluster lock if ``cluster`` holds it."""
    if cluster._lock_fd is not None:
        os.close(cluster._lock_fd)
        cluster._lock_fd = None


def _write_record(cluster: LocalCluster) -> None:
    """Record the started daemons (PID and start time), so ``stop`` works from another process."""
    record = {
        name: {"pid": pid, "start": _proc_start_ticks(pid)} for name, pid in cluster.pids.items()
    }
    RECORD.write_text(json.dumps(record, indent=1))


def _read_record() -> dict[str, dict[str, Any]]:
    """The daemons recorded by :func:`_write_record`, oldest first."""
    if not RECORD.exists():
        return {}
    try:
        return json.loads(RECORD.read_text())
    except json.JSONDecodeError:
        return {}


def _terminate(pid: int, start: int | None, timeout: float = 20.0) -> None:
    """SIGTERM one recorded process (if it is still the same process), SIGKILL after timeout."""
    if not _alive(pid) or (start is not None and _proc_start_ticks(pid) != start):
        return
    os.kill(pid, signal.SIGTERM)
    deadline = time.monotonic() + timeout
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    if _alive(pid):
        os.kill(pid, signal.SIGKILL)


def _remove_conf() -> None:
    """Remove the configuration written by :func:`start` (and only that one).

    Slurm client commands given a configuration whose controller is down retry for seconds;
    Snakemake's Slurm plugin calls one on every start, so the file must not outlive the cluster.
    """
    if CONF_PATH.exists() and MARKER in CONF_PATH.read_text():
        CONF_PATH.unlink()


def stop_recorded() -> list[str]:
    """Stop the daemons recorded by an earlier :func:`start`, by PID; return their names."""
    stopped = []
    # Node daemon first, then the controller, then authentication.
    for name, entry in reversed(list(_read_record().items())):
        if _alive(entry["pid"]):
            _terminate(entry["pid"], entry.get("start"))
            stopped.append(name)
    RECORD.unlink(missing_ok=True)
    _remove_conf()
    return stopped


def start(timeout: float = 90.0) -> LocalCluster:
    """Configure and start a one-node cluster; return once its node is idle.

    Parameters
    ----------
    timeout : float
        Seconds to wait for each daemon, s.

    Raises
    ------
    ClusterError
        If another process's cluster is in use, the configuration belongs to another
        installation or a daemon does not come up (the message carries the end of its log).
    """
    reason = unavailable_reason(install=False)
    if reason:
        raise ClusterError(reason)
    lock_fd = _acquire_lock()
    try:
        for d in (STATE_DIR, STATE_DIR / "slurmctld", STATE_DIR / "slurmd", LOG_DIR):
            d.mkdir(parents=True, exist_ok=True)
        # Daemons left by an earlier start whose stop never ran (its holder is gone, or the
        # lock would not be ours): they are ours, stop them.
        stop_recorded()
        node = parse_node_hardware(
            subprocess.run(
                ["slurmd", "-C"], capture_output=True, text=True, check=True, env=_sbin_env()
            ).stdout
        )
    except BaseException:
        os.close(lock_fd)
        raise
    CONF_PATH.parent.mkdir(parents=True, exist_ok=True)
    CONF_PATH.write_text(render_slurm_conf(node))
    jobcomp = LOG_DIR / "jobcomp.log"
    jobcomp.write_text("")
    cluster = LocalCluster(node=node, partition=PARTITION, jobcomp_log=jobcomp, _lock_fd=lock_fd)
    try:
        if not _munge_works():
            uid, gid = _ensure_munge_key()
            _launch(cluster, "munged", ["munged", "--foreground", "--force"], user=uid, group=gid)
            _wait_until(_munge_works, timeout, "munged", LOG_DIR / "munged.out")
        # -c: start from empty state, so no job of an earlier session comes back.
        _launch(cluster, "slurmctld", ["slurmctld", "-D", "-c"])
        _wait_until(
            lambda: _run_ok(["scontrol", "ping"], check_stdout=lambda s: "UP" in s),
            timeout,
            "slurmctld",
            LOG_DIR / "slurmctld.log",
        )
        _launch(cluster, "slurmd", ["slurmd", "-D", "-N", node.name])
        _wait_until(
            lambda: _run_ok(
                ["sinfo", "-h", "-n", node.name, "-o", "%T"],
                check_stdout=lambda s: s.strip() == "idle",
            ),
            timeout,
            f"node {node.name} to become idle",
            LOG_DIR / "slurmd.log",
        )
    except BaseException:
        stop(cluster)
        raise
    return cluster


def stop(cluster: LocalCluster) -> None:
    """Stop the daemons :func:`start` launched for ``cluster``, by PID, newest first.

    Also removes the ``slurm.conf`` that :func:`start` wrote and releases the one-cluster lock.
    """
    for name in reversed(list(cluster.pids)):
        proc = cluster._procs.get(name)
        if proc is not None and proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=10)
    cluster.pids.clear()
    cluster._procs.clear()
    RECORD.unlink(missing_ok=True)
    _remove_conf()
    _release_lock(cluster)


def main(argv: list[str] | None = None) -> int:
    """Command line: ``start``, ``stop`` or ``status``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("action", choices=["start", "stop", "status"])
    args = parser.parse_args(argv)
    if args.action == "start":
        reason = unavailable_reason(install=True)
        if reason:
            print(f"cannot start a local Slurm cluster: {reason}", file=sys.stderr)
            return 1
        try:
            cluster = start()
        except ClusterError as err:
            print(f"cannot start a local Slurm cluster: {err}", file=sys.stderr)
            return 1
        # The daemons must outlive this command: forget the child handles, keep the record.
        # Its lock goes with this process, so a later start stops them.
        print(
            f"node {cluster.node.name} idle in partition {cluster.partition}; daemons "
            + ", ".join(f"{n}={p}" for n, p in cluster.pids.items())
        )
        return 0
    if args.action == "stop":
        stopped = stop_recorded()
        print("stopped: " + (", ".join(stopped) or "nothing recorded"))
        return 0
    record = _read_record()
    for name, entry in record.items():
        state = "running" if _alive(entry["pid"]) else "gone"
        print(f"{name} pid {entry['pid']}: {state}")
    host = socket.gethostname()
    print(f"{CONF_PATH}: {'present' if CONF_PATH.exists() else 'missing'} (host {host})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
