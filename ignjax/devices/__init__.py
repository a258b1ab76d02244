"""The devices a program shards its batches over.

On accelerators the devices are the GPUs or TPU chips JAX finds. On CPU, JAX
makes one device unless told otherwise, and XLA:CPU runs the body of a
rollout's ``lax.scan`` on one core, so a sharded rollout
(:func:`ignjax.sim.rollout.rollout`) uses every core only when the process
has one CPU device per core. :func:`configure_cpu_devices` asks for them; it
must run before JAX initialises its backends (before the first array is
made or the first computation runs), so the command lines and the test
suite call it first thing.
"""

from __future__ import annotations

import os
import warnings

import jax

ENV_VAR = "IGNJAX_CPU_DEVICES"
"""Environment variable that sets the CPU device count (see :func:`configure_cpu_devices`)."""


def available_cores() -> int:
    """CPU cores this process may run on (its affinity mask where the system
    has one, else the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not every system has affinity masks
        return os.cpu_count() or 1


def configure_cpu_devices(n: int | None = None) -> int | None:
    """Ask JAX for ``n`` CPU devices (``jax_num_cpu_devices``).

    The count comes from, in order: the environment variable
    ``IGNJAX_CPU_DEVICES`` when set (a positive integer), ``n``, and the
    number of CPU cores this process may use (:func:`available_cores`).
    It only matters when the CPU is the backend the rollouts run on; on
    GPUs and TPUs the CPU devices are unused.

    JAX reads the setting when it initialises its backends. Once they are
    initialised nothing is changed: a warning says so and the function
    returns None (unless the process already has that many CPU devices).

    Args:
        n: CPU devices wanted (None: one per available core).

    Returns:
        The CPU device count set, or None when the backends were already
        initialised with another count.

    Raises:
        ValueError: ``IGNJAX_CPU_DEVICES`` or ``n`` is not a positive integer.
    """
    env = os.environ.get(ENV_VAR, "").strip()
    if env:
        try:
            count = int(env)
        except ValueError:
            raise ValueError(f"{ENV_VAR}: expected a positive integer, got {env!r}") from None
        where = ENV_VAR
    else:
        count = available_cores() if n is None else int(n)
        where = "n"
    if count < 1:
        raise ValueError(f"{where}: expected a positive integer, got {count}")
    try:
        jax.config.update("jax_num_cpu_devices", count)
    except RuntimeError:
        warnings.warn(f"JAX backends are already initialised; keeping their CPU devices (asked for {count})",
                      RuntimeWarning, stacklevel=2)
        return None
    return count


__all__ = ["ENV_VAR", "available_cores", "configure_cpu_devices"]
