"""The ``time_to_result`` block of ``python -m ignjax.bench``: what a
researcher waits for a result, the first time (an empty cache folder) and
the second (the same folder, a new process).

Each task runs in a fresh ``python -m ignjax.bench.time_to_result COMMAND
OUT ARGS...`` process with ``IGNJAX_CACHE_DIR`` set to a new temporary
folder (cold), then in another on that folder (warm):

* ``evaluate`` - ``python -m ignjax.evaluate --agent eig`` on the shipped
  500 episodes (or ``--episodes``);
* ``sweep_eval_quick`` - ``python -m ignjax.sweep --study eval --quick``;
* ``in_loop`` - the EIG agent's in-the-loop sweep of 16 cost vectors x 500
  episodes (:func:`ignjax.bench.rollouts.in_loop_sweep`), after loading the
  benchmark and building its world.

Each child asks for one CPU device per core before JAX starts, as the
commands' own entry points do (``python -m ignjax.evaluate``), so a task runs
on the devices the command would.

Each run is split into ``load_s`` (reading the episode file, building the
scenes' tables, goal fields and the world, outside compiling), ``compile_s``
(tracing, lowering and compiling programs, or loading them from the
persistent cache: JAX's compile events, :mod:`ignjax.cache.clock`) and
``run_s`` (the rest of the process's wall time ``total_s``: simulating,
writing outputs, and Python's start and imports), with ``programs`` (programs
obtained), ``cache_hits`` (of them loaded from a cache), ``whole`` (of the
hits, loaded whole from the program store, :mod:`ignjax.cache.programs`:
no tracing or lowering) and ``compiled``. ``same_outputs`` says whether the cold and warm runs wrote the
same bytes (every output file but the checkpoints' metadata, which orbax
stamps with the time).
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

IN_LOOP_VECTORS = 16
IN_LOOP_EPISODES = 500
COMMANDS = {"evaluate": "ignjax.evaluate.cli", "sweep": "ignjax.sweep.cli"}
"""Commands a task may run (their ``main(argv)``, with ``--out`` added), besides ``in_loop``."""


def default_tasks(episodes: str) -> dict:
    """The block's tasks: name -> (command, arguments) (module docstring)."""
    return {"evaluate": ("evaluate", ["--episodes", episodes, "--agent", "eig", "--quiet"]),
            "sweep_eval_quick": ("sweep", ["--study", "eval", "--quick", "--quiet"]),
            "in_loop": ("in_loop", [episodes, str(IN_LOOP_VECTORS), str(IN_LOOP_EPISODES)])}


def _child(command: str, argv: list[str], out: Path) -> dict:
    """Run one task in this process (a fresh one) and return its load and compile split."""
    import importlib

    from ignjax.cache.clock import CompileClock, phase_spans, split

    clock = CompileClock().start()
    if command in COMMANDS:
        rc = importlib.import_module(COMMANDS[command]).main([*argv, "--out", str(out)])
        if rc:
            raise SystemExit(rc)
    elif command == "in_loop":
        from ignjax.cache.compile import use_compile_cache
        from ignjax.cache.programs import prefetch_programs

        use_compile_cache()
        prefetch_programs(("in_loop", argv))
        from ignjax.bench.rollouts import in_loop_sweep
        from ignjax.episodes.dataset import load_benchmark
        from ignjax.evaluate.runner import make_world

        episodes, K, E = argv
        es = load_benchmark(episodes)
        in_loop_sweep(es, make_world(es), int(K), int(E))()
    else:
        raise SystemExit(f"unknown command {command!r}: one of {', '.join([*COMMANDS, 'in_loop'])}")
    clock.stop()
    return {**split(phase_spans("load"), clock.spans), "programs": clock.programs, "cache_hits": clock.cache_hits,
            "whole": clock.whole, "compiled": clock.programs - clock.cache_hits}


def _digests(folder: Path) -> dict:
    """Digest of every file under ``folder`` but orbax's time-stamped checkpoint files."""
    out = {}
    for f in sorted(folder.rglob("*")) if folder.is_dir() else ():
        if f.is_file() and "checkpoints" not in f.relative_to(folder).parts:
            out[str(f.relative_to(folder))] = hashlib.blake2b(f.read_bytes(), digest_size=16).hexdigest()
    return out


def run_fresh(command: str, argv: list[str], cache: Path, out: Path, env: dict | None = None) -> dict:
    """One fresh process running a task on cache folder ``cache``, outputs in ``out``: its split (module docstring)."""
    env = {k: v for k, v in (os.environ if env is None else env).items()
           if k not in ("JAX_COMPILATION_CACHE_DIR", "IGNJAX_NO_CACHE")}
    env["IGNJAX_CACHE_DIR"] = str(cache)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "ignjax.bench.time_to_result", command, str(out), *argv], env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    total = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"time_to_result: {command} {' '.join(argv)} failed (exit {p.returncode}):\n"
                           f"{p.stderr[-3000:]}")
    res = json.loads(p.stdout.strip().splitlines()[-1])
    res["total_s"] = total
    res["run_s"] = total - res["load_s"] - res["compile_s"]
    return res


def cold_and_warm(command: str, argv: list[str], folder: Path, env: dict | None = None, log=None,
                  name: str = "") -> dict:
    """A task run cold (cache folder ``folder/cache`` empty) and then warm, and whether both wrote the same bytes."""
    runs: dict = {}
    for state in ("cold", "warm"):
        runs[state] = r = run_fresh(command, argv, folder / "cache", folder / state, env)
        if log:
            log(f"  {name or command:17s} {state}: {r['total_s']:6.1f} s = load {r['load_s']:5.1f} + compile "
                f"{r['compile_s']:5.1f} + run {r['run_s']:5.1f}; {r['programs']} programs, {r['compiled']} compiled, "
                f"{r['whole']} loaded whole")
    if command in COMMANDS:
        cold, warm = _digests(folder / "cold"), _digests(folder / "warm")
        runs["same_outputs"] = bool(cold) and cold == warm
    return runs


def bench_time_to_result(episodes: str, log=None) -> dict:
    """Cold and warm figures of each of :func:`default_tasks` (module docstring)."""
    out: dict = {}
    for name, (command, argv) in default_tasks(episodes).items():
        with tempfile.TemporaryDirectory(prefix="ignjax-ttr-") as tmp:
            out[name] = cold_and_warm(command, argv, Path(tmp), log=log, name=name)
    return out


def main(argv=None) -> int:
    from ignjax.devices import configure_cpu_devices

    configure_cpu_devices()  # as the commands' own entry points do, before JAX starts: one CPU device per core
    command, out, *rest = sys.argv[1:] if argv is None else argv
    print(json.dumps(_child(command, rest, Path(out))))
    return 0


if __name__ == "__main__":
    from ignjax.devices.quickexit import exit_now

    exit_now(main())  # as the commands' entry points end (ignjax.devices.quickexit)
