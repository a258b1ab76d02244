"""The run folder of a sweep: which run it holds (``run.json``: the
fingerprint, the configuration, and ``loaded_agents``, the checkpoint path
and weights' SHA-256 of each agent whose parameters are files) and the
rollout stages already finished (``checkpoints/``, orbax), so that
``--resume`` continues exactly where a killed run stopped."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import orbax.checkpoint as ocp

from ignjax import __version__
from ignjax.config import SweepConfig, fingerprint, loaded_agents
from ignjax.errors import InputError
from ignjax.fileio import atomic_write, remove_leftover_temporaries


def prepare_folder(out: Path, cfg: SweepConfig, studies: list[str], resume: bool, force: bool) -> None:
    """Create or reuse the run folder; refuse one that holds another run."""
    meta = out / "run.json"
    fp = fingerprint(cfg, studies)
    if out.exists() and any(out.iterdir()):
        if force:
            shutil.rmtree(out)
        elif not meta.is_file():
            raise InputError(str(out), "--out", "folder is not empty and holds no ignjax run; use --force to replace it")
        else:
            old = json.loads(meta.read_text())
            if old.get("fingerprint") != fp:
                raise InputError(str(meta), "fingerprint",
                                 "the folder holds a different run (other configuration or studies); "
                                 "use another --out, or --force to replace it")
            if not resume:
                raise InputError(str(out), "--out", "the folder already holds this run; use --resume to continue "
                                                    "it or --force to start over")
            remove_leftover_temporaries(out)  # a file being written when the killed run stopped
    out.mkdir(parents=True, exist_ok=True)
    if not meta.is_file():
        record = {"fingerprint": fp, "ignjax_version": __version__, "studies": studies, "config": cfg.to_dict(),
                  "loaded_agents": loaded_agents(cfg, studies)}
        atomic_write(meta, json.dumps(record, indent=2, sort_keys=True) + "\n")


class Checkpoints:
    """Finished rollout stages of a run, saved with orbax (one folder per stage).

    A stage is either absent or complete: orbax writes a save into
    ``<stage>.orbax-checkpoint-tmp`` and renames it to ``<stage>`` only once
    every file is written (its atomic-rename commit on local file systems),
    and a later save of the same stage first deletes such an unfinished
    folder. So a run killed mid-save (even by SIGKILL) has no ``<stage>``
    folder, and ``--resume`` recomputes that stage from the same inputs.
    """

    def __init__(self, root: Path):
        self.root = root

    def _path(self, name: str) -> Path:
        return self.root / name.replace("/", "__")

    def has(self, name: str) -> bool:
        return self._path(name).is_dir()

    def load(self, name: str) -> dict:
        with _checkpointer() as ck:
            return ck.restore(self._path(name).resolve())

    def save(self, name: str, tree: dict) -> None:
        self.root.mkdir(parents=True, exist_ok=True)
        with _checkpointer() as ck:
            ck.save(self._path(name).resolve(), tree)


def _checkpointer():
    """Orbax's checkpointer for this process alone: in a run of several
    processes only process 0 saves and loads stages, so orbax must not wait
    for the others at its barriers."""
    import jax

    if jax.process_count() == 1:
        return ocp.PyTreeCheckpointer()
    me = jax.process_index()
    mp = ocp.options.MultiprocessingOptions(primary_host=me, active_processes={me})
    return ocp.Checkpointer(ocp.PyTreeCheckpointHandler(multiprocessing_options=mp), multiprocessing_options=mp)


__all__ = ["Checkpoints", "prepare_folder"]
