"""Several processes on one run: on one machine or one per host of a cluster.

A run with N processes splits its rollout work: every process loads the
same episodes and runs its own share of the batches on its own devices
(the local devices of :func:`jax.local_devices`; no program spans two
processes), writes each finished batch to the run folder as a part file
(:mod:`ignjax.devices.parts`), and process 0 merges the parts in episode
order and writes the outputs once, the same bytes as a one-process run.

The processes find each other through JAX's distributed runtime
(:func:`jax.distributed.initialize`): process 0 runs the coordinator at
``--coordinator HOST:PORT``, the others connect to it. The runtime gives
each process its index, the barriers between the steps of a run
(:meth:`ProcessGroup.barrier`) and the failure detection: a process whose
peer dies is stopped by the runtime once the peer misses its heartbeats
(:data:`HEARTBEAT_TIMEOUT_S`), so no process waits for a dead one for ever.

Where the settings come from, first found wins:

1. the flags ``--coordinator HOST:PORT --num-processes N --process-id I``;
2. the environment ``JAX_COORDINATOR_ADDRESS``, ``JAX_NUM_PROCESSES`` and
   ``JAX_PROCESS_ID`` (the first is also JAX's own name);
3. with ``--cluster``, JAX's own detection of the cluster's environment
   (Slurm, Open MPI, Kubernetes, Cloud TPU: e.g. ``SLURM_NTASKS``,
   ``SLURM_PROCID`` and the job's first host as coordinator).

None of them: one process, and JAX's distributed runtime is not started.
``--processes N`` starts N local processes on 127.0.0.1
(:mod:`ignjax.devices.launch`).
"""

from __future__ import annotations

import dataclasses
import os
import socket
import sys
import time

from ignjax.errors import ConfigError

ENV_COORDINATOR = "JAX_COORDINATOR_ADDRESS"
ENV_NUM_PROCESSES = "JAX_NUM_PROCESSES"
ENV_PROCESS_ID = "JAX_PROCESS_ID"

COORDINATOR_TIMEOUT_S = 60.0
"""Default of ``--coordinator-timeout``: how long a process waits for the
coordinator to answer and for every process to connect."""

HEARTBEAT_TIMEOUT_S = 60
"""Seconds after which JAX's distributed runtime declares a silent process
dead and stops the others (the runtime's own error: exit by SIGABRT)."""

SHUTDOWN_TIMEOUT_S = 30
"""Seconds a finishing process waits for the others at JAX's shutdown."""

WORK_TIMEOUT_S = 7 * 24 * 3600.0
"""Default wait at a barrier that follows work (a process's share of the
rollouts): long, since a dead peer is detected by the runtime's heartbeats,
not by this timeout."""


@dataclasses.dataclass(frozen=True)
class ProcessOptions:
    """The process settings of a command line, checked (:func:`process_options`)."""

    launch: int = 0
    """``--processes N`` (N > 1): start N local processes; 0: this is one of them."""
    coordinator: str | None = None
    num_processes: int | None = None
    process_id: int | None = None
    cluster: bool = False
    timeout_s: float = COORDINATOR_TIMEOUT_S

    @property
    def distributed(self) -> bool:
        return self.cluster or self.num_processes is not None and self.num_processes > 1


@dataclasses.dataclass(frozen=True)
class ProcessGroup:
    """This process's place among the processes of a run.

    ``index`` in ``0..count-1``; process 0 is the main one (it writes the
    outputs). With one process every method is trivial.
    """

    index: int = 0
    count: int = 1
    client: object = None
    """JAX's distributed-runtime client (None for one process)."""

    @property
    def main(self) -> bool:
        return self.index == 0

    def share(self, n: int) -> range:
        """This process's items of ``n`` (batches, in file order): a
        contiguous block, the blocks in process order, the first ``n % count``
        processes one item more (:func:`numpy.array_split`'s split)."""
        return share(n, self.count, self.index)

    def barrier(self, name: str, timeout_s: float = WORK_TIMEOUT_S) -> None:
        """Wait until every process has reached the barrier ``name``.

        Raises:
            RuntimeError: the barrier timed out or the runtime failed.
        """
        if self.client is None:
            return
        try:
            self.client.wait_at_barrier(f"ignjax:{name}", int(timeout_s * 1000))
        except Exception as e:  # the runtime's own error type
            raise RuntimeError(f"process {self.index} of {self.count}: barrier {name!r} failed: {e}") from e

    def agree(self, value: str, where: str, timeout_s: float = WORK_TIMEOUT_S) -> None:
        """The barrier after which the processes start work: process 0 comes to
        it when the run folder is ready, and publishes ``value`` (the run's
        settings, hashed); every other process checks that it runs with the
        same. The wait is long (process 0 may build a benchmark first); a dead
        process 0 is detected by the runtime's heartbeats.

        Raises:
            ConfigError: this process's value differs from process 0's (naming ``where``).
        """
        if self.client is None:
            return
        key = "ignjax:settings"
        if self.main:
            self.client.key_value_set(key, value)
        self.barrier("start", timeout_s)
        if not self.main and self.client.blocking_key_value_get(key, 60_000) != value:
            raise ConfigError(None, where, f"process {self.index} was started with other settings than process 0 "
                                           f"(every process of a run needs the same arguments)")


SINGLE = ProcessGroup()
"""The group of a one-process run."""


def share(n: int, count: int, index: int) -> range:
    """Items of ``range(n)`` for process ``index`` of ``count`` (:meth:`ProcessGroup.share`)."""
    base, extra = divmod(int(n), int(count))
    start = index * base + min(index, extra)
    return range(start, start + base + (index < extra))


def add_arguments(parser) -> None:
    """The process flags of ``python -m ignjax.evaluate`` and ``python -m ignjax.sweep``."""
    g = parser.add_argument_group(
        "processes (several processes or hosts split the episodes; process 0 writes the outputs)")
    g.add_argument("--processes", type=int, default=None, metavar="N",
                   help="start N local processes on this machine (coordinator on 127.0.0.1, on a port the launcher holds for the run); "
                        "each gets IGNJAX_CPU_DEVICES = cores / N unless set")
    g.add_argument("--coordinator", default=None, metavar="HOST:PORT",
                   help=f"process 0's address, where it runs the coordinator (or ${ENV_COORDINATOR})")
    g.add_argument("--num-processes", type=int, default=None, metavar="N",
                   help=f"processes in the run (or ${ENV_NUM_PROCESSES})")
    g.add_argument("--process-id", type=int, default=None, metavar="I",
                   help=f"this process's index, 0..N-1 (or ${ENV_PROCESS_ID})")
    g.add_argument("--cluster", action="store_true",
                   help="take coordinator, process count and index from the cluster's environment "
                        "(JAX's detection: Slurm, Open MPI, Kubernetes, Cloud TPU)")
    g.add_argument("--coordinator-timeout", type=float, default=COORDINATOR_TIMEOUT_S, metavar="S",
                   help="seconds to wait for the coordinator to answer and every process to connect "
                        "(default %(default)g)")


def _env_int(name: str) -> int | None:
    v = os.environ.get(name, "").strip()
    if not v:
        return None
    try:
        return int(v)
    except ValueError:
        raise ConfigError(None, name, f"expected an integer, got {v!r}") from None


def _check_address(addr: str, where: str) -> str:
    host, sep, port = addr.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ConfigError(None, where, f"expected HOST:PORT with a port in 1..65535, got {addr!r}")
    return addr


def process_options(args) -> ProcessOptions:
    """Check the process flags of ``args`` (:func:`add_arguments`) and the environment.

    Raises:
        ConfigError: naming the flag (or variable) and the reason: a count
            below 1, an index outside ``0..N-1``, an address that is not
            ``HOST:PORT``, a timeout that is not positive, ``--processes``
            together with the flags it sets itself, an index without a count.
    """
    timeout = float(args.coordinator_timeout)
    if not timeout > 0:
        raise ConfigError(None, "--coordinator-timeout", f"must be > 0 seconds, got {args.coordinator_timeout}")
    if args.processes is not None:
        if args.processes < 1:
            raise ConfigError(None, "--processes", f"must be >= 1, got {args.processes}")
        given = [f for f, v in (("--coordinator", args.coordinator), ("--num-processes", args.num_processes),
                                ("--process-id", args.process_id), ("--cluster", args.cluster or None)) if v is not None]
        if given:
            raise ConfigError(None, "--processes", f"starts its processes itself and sets their addresses: drop "
                                                   f"{', '.join(given)}")
        return ProcessOptions(launch=args.processes if args.processes > 1 else 0, timeout_s=timeout)
    coord = args.coordinator or os.environ.get(ENV_COORDINATOR) or None
    where_c = "--coordinator" if args.coordinator else ENV_COORDINATOR
    num = args.num_processes if args.num_processes is not None else _env_int(ENV_NUM_PROCESSES)
    where_n = "--num-processes" if args.num_processes is not None else ENV_NUM_PROCESSES
    pid = args.process_id if args.process_id is not None else _env_int(ENV_PROCESS_ID)
    where_p = "--process-id" if args.process_id is not None else ENV_PROCESS_ID
    if num is not None and num < 1:
        raise ConfigError(None, where_n, f"must be >= 1, got {num}")
    if pid is not None and pid < 0:
        raise ConfigError(None, where_p, f"must be >= 0, got {pid}")
    if pid is not None and num is not None and pid >= num:
        raise ConfigError(None, where_p, f"must be in 0..{num - 1} ({where_n} is {num}), got {pid}")
    if coord is not None:
        _check_address(coord, where_c)
    if args.cluster:
        return ProcessOptions(coordinator=coord, num_processes=num, process_id=pid, cluster=True, timeout_s=timeout)
    if num is None or num == 1:
        if pid not in (None, 0):
            raise ConfigError(None, where_p, f"process {pid} needs {where_n} > {pid}")
        return ProcessOptions(timeout_s=timeout)
    if pid is None:
        raise ConfigError(None, "--process-id", f"{where_n} is {num}: each process needs its index 0..{num - 1} "
                                                f"(--process-id or ${ENV_PROCESS_ID})")
    if coord is None:
        raise ConfigError(None, "--coordinator", f"{where_n} is {num}: the processes need process 0's HOST:PORT "
                                                 f"(--coordinator or ${ENV_COORDINATOR})")
    return ProcessOptions(coordinator=coord, num_processes=num, process_id=pid, timeout_s=timeout)


def _wait_for_coordinator(addr: str, timeout_s: float, where: str) -> None:
    """Until the coordinator accepts a TCP connection (JAX's runtime would
    abort the process after its timeout, with no word about the flag)."""
    host, _, port = addr.rpartition(":")
    host = host.strip("[]")
    deadline = time.monotonic() + timeout_s
    last = None
    while True:
        try:
            with socket.create_connection((host, int(port)), timeout=min(2.0, timeout_s)):
                return
        except OSError as e:
            last = e
        if time.monotonic() >= deadline:
            raise ConfigError(None, where, f"the coordinator {addr} did not answer within {timeout_s:g} s "
                                           f"({last}); is process 0 running there? (--coordinator-timeout)")
        time.sleep(0.2)


def _check_port_free(addr: str, where: str) -> None:
    port = int(addr.rpartition(":")[2])
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("", port))
        except OSError as e:
            raise ConfigError(None, where, f"process 0 cannot run the coordinator on port {port}: {e}") from None


def start(opts: ProcessOptions) -> ProcessGroup:
    """Join the run's processes (:func:`jax.distributed.initialize`); call it
    before JAX starts its backends. One process: :data:`SINGLE`, nothing started.

    A process other than 0 first waits for the coordinator to accept a
    connection, up to ``opts.timeout_s``; then JAX connects every process
    within what is left of it (at least 5 s).

    Raises:
        ConfigError: the coordinator did not answer in time (``--coordinator``),
            or process 0 cannot listen on its port, or the cluster's
            environment gave no settings (``--cluster``).
    """
    if not opts.distributed:
        return SINGLE
    import jax
    from jax._src import distributed

    t0 = time.monotonic()
    coord, num, pid = opts.coordinator, opts.num_processes, opts.process_id
    if opts.cluster:
        from jax._src.clusters import ClusterEnv

        coord, num, pid, _ = ClusterEnv.auto_detect_unset_distributed_params(coord, num, pid, [], None,
                                                                             int(opts.timeout_s))
        if coord is None or num is None or pid is None:
            raise ConfigError(None, "--cluster", "JAX found no cluster environment (Slurm, Open MPI, Kubernetes, "
                                                 "Cloud TPU) to take the coordinator, process count and index from")
        _check_address(coord, "--cluster")
        if num == 1:
            return SINGLE
    where = "--coordinator"
    if pid == 0:
        _check_port_free(coord, where)
    else:
        _wait_for_coordinator(coord, opts.timeout_s, where)
    left = max(5, int(round(opts.timeout_s - (time.monotonic() - t0))))
    print(f"process {pid} of {num}: joining the coordinator at {coord} (up to {left} s)", file=sys.stderr, flush=True)
    # every device of this host, unless JAX_LOCAL_DEVICE_IDS names some: the cluster's detection above is asked for
    # no device list, since JAX's Slurm detection would give each task the one accelerator of its SLURM_LOCALID, and
    # a task per host wants all of them
    local = os.environ.get("JAX_LOCAL_DEVICE_IDS")
    jax.distributed.initialize(coord, num, pid, local_device_ids=[int(x) for x in local.split(",")] if local else None,
                               cluster_detection_method="deactivate", initialization_timeout=left,
                               heartbeat_timeout_seconds=HEARTBEAT_TIMEOUT_S,
                               shutdown_timeout_seconds=SHUTDOWN_TIMEOUT_S)
    return ProcessGroup(index=pid, count=num, client=distributed.global_state.client)


def local_cpu_devices(n_processes: int, cores: int) -> int:
    """CPU devices each of ``n_processes`` local processes gets (the cores split evenly, at least one)."""
    return max(1, cores // max(1, n_processes))


__all__ = ["COORDINATOR_TIMEOUT_S", "ENV_COORDINATOR", "ENV_NUM_PROCESSES", "ENV_PROCESS_ID", "HEARTBEAT_TIMEOUT_S",
           "ProcessGroup", "ProcessOptions", "SINGLE", "WORK_TIMEOUT_S", "add_arguments", "local_cpu_devices",
           "process_options", "share", "start"]
